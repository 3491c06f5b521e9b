"""``clearbench mujoco-table``: MuJoCo's error against the physics expectations of the
analytic scenes, per preset and time step (the figures of the README's MuJoCo section)."""

from __future__ import annotations

import sys

from clearbench.adapters import engine_availability
from clearbench.harness.cli.main import UserError
from clearbench.harness.studies.physics_table import (
    DEFAULT_SCENES,
    markdown,
    markdown_compact,
    measure,
)
from clearbench.scenarios.library import scene_names


def register(subparsers) -> None:
    """Add the ``mujoco-table`` sub-command."""
    parser = subparsers.add_parser(
        "mujoco-table",
        help="MuJoCo's error against physics on the analytic scenes (per preset and dt)",
        description="Run every analytic scene (and the clearance pendulum) in MuJoCo with each "
        "preset at each time step, and print, per scene, the figures of the shared expectation "
        "evaluator (apex ratios, creep, energy drift, clearance excess, ...) as Markdown "
        "tables. With --reference, the reference solver runs the same cells.",
    )
    parser.add_argument("--preset", action="append", dest="presets",
                        help="MuJoCo preset (repeatable; default: default and tuned)")
    parser.add_argument("--dt", action="append", type=float, dest="time_steps",
                        help="time step [s] (repeatable; default: 1e-3 and 1e-4)")
    parser.add_argument("--scene", action="append", dest="scenes",
                        help="scene name (repeatable; default: the analytic scenes and "
                        "clearance-pendulum)")
    parser.add_argument("--horizon", type=float,
                        help="simulated duration [scene time unit] (default: each scene's)")
    parser.add_argument("--reference", action="store_true",
                        help="add the reference solver (default preset) as a column")
    parser.add_argument("--compact", action="store_true",
                        help="one table for all scenes (a row per scene and figure)")
    parser.add_argument("--no-mujoco", action="store_true",
                        help="leave out the MuJoCo columns (with --reference: the reference "
                        "column alone)")
    parser.set_defaults(handler=run)


def run(args) -> int:
    from clearbench.adapters.mujoco import engine as mujoco_engine
    from clearbench.adapters.mujoco.settings import PRESETS

    available = engine_availability("mujoco")
    if not available.available:
        raise UserError(f"mujoco is not available: {available.detail}")
    presets = args.presets or ["default", "tuned"]
    unknown = sorted(set(presets) - set(PRESETS))
    if unknown:
        raise UserError(f"unknown preset(s) {unknown}; presets: {list(PRESETS)}")
    scenes = tuple(args.scenes or DEFAULT_SCENES)
    known = set(scene_names())
    missing = sorted(set(scenes) - known)
    if missing:
        raise UserError(f"unknown scene(s) {missing}; see `clearbench list`")
    time_steps = tuple(args.time_steps or (1e-3, 1e-4))
    if any(not dt > 0 for dt in time_steps):
        raise UserError(f"--dt must be > 0, got {time_steps}")
    engines = {} if args.no_mujoco else \
        {f"mujoco[{p}]": mujoco_engine.create(p) for p in presets}
    if not engines and not args.reference:
        raise UserError("nothing to run: --no-mujoco without --reference")
    if args.reference:
        from clearbench.adapters.reference import engine as reference

        engines["reference"] = reference.create()
    measured = measure(engines, time_steps, scenes, args.horizon,
                       progress=lambda text: print(f"running {text}", file=sys.stderr))
    print(markdown_compact(measured) if args.compact else markdown(measured))
    return 0
