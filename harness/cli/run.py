"""``clearbench run``: one scene in one engine, isolated in a worker, stored, summarised."""

from __future__ import annotations

import argparse
import json
import shutil

from clearbench.harness.cli.commands import command_help
from clearbench.harness.cli.common import (
    UserError,
    add_engine_option,
    add_engine_options_option,
    add_runner_options,
    assignments,
    engine_modules,
    engine_options,
    make_runner,
    open_store,
)
from clearbench.harness.measure.geometry_check import UNSEEN_PENETRATION
from clearbench.harness.measure.headline import format_value
from clearbench.harness.measure.units import unit_text
from clearbench.harness.measure.verdicts import run_verdict, verdict_text
from clearbench.harness.run.spec import make_run_spec
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.units import UnitSystem


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "run", help=command_help("run"),
        description="Run SCENE (a registered name or a .toml/.json scene file) in one engine, in "
        "an isolated worker process with a wall-clock limit, record it in the results store "
        "and print its metrics, expectations and verdict. A run already in the store is shown "
        "from the store (--rerun to run it again).",
    )
    parser.add_argument("scene", help="registered scene name or scene file")
    add_engine_option(parser, many=False, default="reference", flags=("--engine", "-e"),
                      help="engine and preset, e.g. reference, mujoco[tuned] (default: "
                      "reference)")
    parser.add_argument("--dt", type=float, default=None,
                        help="time step in the scene's time unit (default: the scene's)")
    parser.add_argument("--horizon", type=float, default=None,
                        help="simulated duration in the scene's time unit (default: the scene's)")
    parser.add_argument("--record-every", type=int, default=1, metavar="N",
                        help="keep one sample every N steps (default 1)")
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                        help="a parameter of the scene's factory, e.g. radial_clearance=1e-5")
    add_engine_options_option(parser, "an engine option overriding the preset, e.g. "
                              "tolerance=1e-10")
    parser.add_argument("--out", metavar="FILE.npz", help="also write the trajectory here")
    parser.add_argument("--json", action="store_true", help="print the stored row as JSON")
    add_runner_options(parser)
    parser.set_defaults(handler=run_one)


def run_one(args: argparse.Namespace) -> int:
    spec = make_run_spec(args.scene, args.engine,
                         scene_parameters=assignments(args.set, "--set"),
                         time_step=args.dt, horizon=args.horizon,
                         record_every=args.record_every,
                         options=engine_options(args),
                         timeout=args.timeout, extra_engine_modules=engine_modules(args),
                         campaign="run")
    store = open_store(args)
    runner = make_runner(args, store, 1)
    outcome = runner.run_all([spec], rerun=args.rerun)
    row = store.get(spec.key)
    if row is None:  # pragma: no cover - the runner always records
        raise UserError(f"run {spec.key} was not recorded")
    if args.out:
        trajectory = store.trajectory_path(spec.key)
        if not trajectory.exists():
            raise UserError(f"--out {args.out}: run ended {row['status']} with no trajectory")
        shutil.copyfile(trajectory, args.out)
    if args.json:
        print(json.dumps(row, indent=2, sort_keys=True))
    else:
        print_summary(row, from_store=spec.key in outcome.skipped, store_path=store.directory,
                      scene=spec.scene)
    return 0 if row["status"] in ("ok", "unsupported") else 1


def _figure_text(name: str, value, row: dict, scene: Scene | None) -> str:
    """A figure with its unit (:mod:`clearbench.harness.measure.units`), or saying that it
    has none stated there."""
    kinds = {r.get("name"): r.get("kind") for r in json.loads(row["expectations"] or "[]")}
    return format_value(value, unit_text(name, scene, kinds) or "(unit not stated)")


def print_summary(row: dict, from_store: bool = False, store_path=None,
                  scene: Scene | None = None) -> None:
    """Human-readable summary of one stored run (``scene``: the run's scene, for the units of
    its figures; SI when not given)."""
    units = scene.units if scene is not None else UnitSystem()
    origin = " (from the store; --rerun to run again)" if from_store else ""
    print(f"{row['scene_name']}  {row['engine']}[{row['preset']}]  dt = {row['time_step']:g}  "
          f"horizon = {row['horizon']:g}{origin}")
    figures = json.loads(row["metrics"] or "{}")
    verdict = run_verdict(row["status"], row["expectations_passed"], figures)
    reason = (row["verdict_reason"].removeprefix(f"{UNSEEN_PENETRATION}: ")
              if verdict == UNSEEN_PENETRATION else row["message"])
    print(f"  verdict: {verdict_text(verdict)}" + (f" — {reason}" if reason else ""))
    if row["engine_status"] != row["status"]:
        print(f"  engine reported: {row['engine_status']} {row['engine_message']}".rstrip())
    print(f"  engine: {row['engine_version']}")
    print(f"  wall: worker {format_value(row['worker_seconds'], 's')}, build "
          f"{format_value(row['build_seconds'], 's')}, stepping "
          f"{format_value(row['stepping_seconds'], 's')} for {row['steps']} steps "
          f"({format_value(row['stepping_seconds_per_step'], 's')}/step, "
          f"{format_value(row['stepping_seconds_per_simulated_second'], 's')} per simulated "
          "time unit)")
    if figures:
        print(f"  metrics (units {units.length}-{units.mass}-{units.time}, force "
              f"{units.force_unit()}; a ratio says what it is of):")
        for name in sorted(figures):
            print(f"    {name:<36} {_figure_text(name, figures[name], row, scene)}")
    if row["error_source"]:
        print(f"  error measured against: {row['error_source']}")
    expectations = json.loads(row["expectations"] or "[]")
    if expectations:
        print("  expectations:")
        for result in expectations:
            passed = result.get("passed")
            mark = {True: "PASS", False: "FAIL", None: "n/a"}.get(passed, str(passed))
            detail = result.get("detail") or result.get("criterion") or result.get("note", "")
            print(f"    {mark:<5} {result.get('name', result.get('kind', '?'))}: {detail}")
    if row["metrics_error"]:
        print(f"  metrics not computed: {row['metrics_error']}")
    if row["trajectory"] and store_path is not None:
        print(f"  trajectory: {store_path / row['trajectory']}")
    print(f"  run key: {row['key']}")
