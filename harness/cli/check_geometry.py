"""``clearbench check-geometry``: the kernel's penetration of recorded runs beside the
independent instrument's (:mod:`clearbench.harness.measure.geometry_check`), state by state.

Every run's measurement already does this at a stride (the figures ``instrument_*`` and the
verdict "unseen penetration"); this command reads every recorded state (``--stride 1`` by
default) of runs given as trajectory files or as runs of a results store, prints per pair the
two figures, the largest difference and the allowance, and exits 1 when a run has an unseen
penetration (0 when the two agree at every state read).
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from clearbench.adapters.trajectory import Trajectory
from clearbench.harness.cli.commands import command_help
from clearbench.harness.cli.common import assignments, open_store
from clearbench.harness.cli.errors import UserError
from clearbench.harness.measure import geometry_check
from clearbench.harness.measure.headline import format_value
from clearbench.harness.run.engine_choice import RunInputError
from clearbench.harness.run.spec import resolve_scene


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "check-geometry", help=command_help("check-geometry"),
        description="Read every recorded state of runs a second way with the independent "
        "geometry instrument and compare its penetration with the kernel's figure, pair by "
        "pair (docs/harness.md, 'The independent instrument'). Exit 1 when a run has an "
        "unseen penetration.")
    parser.add_argument("runs", nargs="*", metavar="RUN",
                        help="a trajectory file (.npz, e.g. from clearbench run --out) or the "
                        "key of a run in the results store")
    parser.add_argument("--scene", default=None,
                        help="the runs' scene: a registered name or a scene file (default: "
                        "the store's copy of the run's scene, else the registered scene the "
                        "trajectory names)")
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                        help="a parameter of the registered scene's factory")
    parser.add_argument("--scene-runs", default="", metavar="NAME[,NAME]",
                        help="also every stored run of these scenes (e.g. c60-on,c60-trip)")
    parser.add_argument("--stride", type=int, default=1, metavar="N",
                        help="read every N-th recorded state first (then every state near an "
                        "unseen penetration); default 1: all")
    parser.add_argument("--stored-kernel", default=None, metavar="ARRAY",
                        help="compare with this (T, pairs) penetration array stored in the "
                        "trajectory file (the kernel figure of the revision that made it) "
                        "instead of this revision's kernel")
    parser.add_argument("--store", default=None, metavar="DIR",
                        help="results store for run keys and --scene-runs (default: "
                        "$CLEARBENCH_STORE or reports/store)")
    parser.set_defaults(handler=check_runs)


def _scene_for(args, trajectory: Trajectory, stored=None):
    if args.scene is not None or args.set:
        try:
            scene, _ = resolve_scene(args.scene or trajectory.scene_name,
                                     assignments(args.set, "--set"))
        except RunInputError as error:
            raise UserError(str(error)) from None
    elif stored is not None:
        scene = stored
    else:
        try:
            scene, _ = resolve_scene(trajectory.scene_name)
        except RunInputError as error:
            raise UserError(f"{error}; give the run's scene with --scene") from None
    if scene.content_hash != trajectory.scene_hash:
        raise UserError(f"scene {scene.name!r} has content hash {scene.content_hash[:12]}, the "
                        f"run was made with {trajectory.scene_hash[:12]}: give the run's own "
                        "scene with --scene FILE (or its parameters with --set)")
    return scene


def _runs(args):
    """(label, scene, trajectory, stored kernel figure or None) of every run asked for."""
    store = None
    if any(not Path(run).is_file() for run in args.runs) or args.scene_runs:
        store = open_store(args, create=False)
    keys = []
    for run in args.runs:
        path = Path(run)
        if path.is_file():
            trajectory = Trajectory.load(path)
            kernel = None
            if args.stored_kernel:
                with np.load(path) as data:
                    if args.stored_kernel not in data:
                        raise UserError(f"--stored-kernel {args.stored_kernel}: {path} has no "
                                        f"such array (it has {', '.join(data.files)})")
                    kernel = np.asarray(data[args.stored_kernel], dtype=float)
            yield str(path), _scene_for(args, trajectory), trajectory, kernel
        else:
            keys.append(run)
    if args.scene_runs:
        frame = store.dataframe(expand_metrics=False)
        names = [n.strip() for n in args.scene_runs.split(",") if n.strip()]
        chosen = frame[frame["scene_name"].isin(names) & (frame["trajectory"] != "")]
        keys += list(chosen.sort_values(["scene_name", "label", "time_step"])["key"])
    for key in keys:
        row = store.get(key)
        if row is None:
            raise UserError(f"{key}: neither a trajectory file nor a run of the store "
                            f"{store.directory}")
        trajectory = store.load_trajectory(key)
        if trajectory is None or not len(trajectory.times):
            print(f"{key}: no recorded state stored (status {row['status']}), skipped")
            continue
        label = (f"{row['scene_name']} {row['engine']}[{row['preset']}] "
                 f"dt={row['time_step']:g} ({key})")
        yield label, _scene_for(args, trajectory, store.scene(row["scene_hash"])), \
            trajectory, None


def check_runs(args: argparse.Namespace) -> int:
    if args.stride < 1:
        raise UserError(f"--stride {args.stride}: must be at least 1")
    if not args.runs and not args.scene_runs:
        raise UserError("give a trajectory file, a run key or --scene-runs")
    unseen_runs = 0
    for label, scene, trajectory, kernel in _runs(args):
        result = geometry_check.check(scene, trajectory, kernel, stride=args.stride)
        print_check(label, scene, result)
        unseen_runs += result.unseen_max > 0.0
    return 1 if unseen_runs else 0


def print_check(label: str, scene, result: geometry_check.GeometryCheck) -> None:
    """Per pair: the two penetrations' maxima, the largest difference and allowance."""
    length, time = scene.units.length, scene.units.time
    read = result.instrument.read
    print(f"{label}: {int(read[:, 0].sum())} of {len(result.times)} states read per pair "
          f"(stride {result.stride}), {len(result.names)} pairs, instrument "
          f"{format_value(result.instrument.seconds, 's')}")
    print(f"  {'pair':<32} {'kernel max':>12} {'instrument max':>15} {'|difference|':>13} "
          f"{'allowance':>11}  unseen")
    intervals = result.unseen_intervals()
    difference = np.abs(result.difference)
    for k, name in enumerate(result.names):
        instrument = np.nanmax(result.instrument.penetration[:, k])
        note = ""
        if name in intervals:
            first, last, count = intervals[name]
            note = f"{count} states, t = {first:.6g} .. {last:.6g} {time}"
        elif result.instrument.left_ring[:, k].any():
            note = f"(journal out of its ring at {int(result.instrument.left_ring[:, k].sum())}" \
                   " states, not compared)"
        print(f"  {name:<32} {format_value(result.kernel[:, k].max() + 0.0, length):>12} "
              f"{format_value(instrument + 0.0, length):>15} "
              f"{format_value(difference[:, k].max(), length):>13} "
              f"{format_value(np.nanmax(result.allowance[:, k]), length):>11}  {note}")
    if result.unseen_max > 0.0:
        print(f"  {result.message(length, time)}")
    else:
        state = "agree within the allowance" if result.agrees else \
            "no unseen penetration (the kernel's figure deeper somewhere)"
        print(f"  {state} at every state read (largest difference "
              f"{format_value(result.agreement_max, length)})")

