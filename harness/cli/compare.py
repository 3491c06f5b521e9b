"""``clearbench compare``: the default comparison (the README's main job) and its report."""

from __future__ import annotations

import argparse
import time

from clearbench.harness.cli.c60 import c60_plan_specs, print_c60
from clearbench.harness.cli.commands import command_help
from clearbench.harness.cli.common import (
    UserError,
    add_engine_option,
    add_runner_options,
    engine_modules,
    make_runner,
    open_store,
)
from clearbench.harness.cli.scenes import check_round_trip, print_engines
from clearbench.harness.cli.sweep import print_work_precision
from clearbench.harness.report.page import write_report
from clearbench.harness.run.engine_choice import RunInputError, resolve_engine
from clearbench.harness.run.numba_cache import warm_up_jobs
from clearbench.harness.run.runner import MANY_RUNS_PER_WORKER
from clearbench.harness.studies.c60_comparison import PLAN_NAMES
from clearbench.harness.studies.stability import available_engines, plan_stability
from clearbench.harness.studies.sweep import (
    FINE_FACTOR,
    REFERENCE_ENGINE,
    execute_plan,
    parse_ladder,
    plan_sweep,
)
from clearbench.scenarios.library import get_entry, scene_names
from clearbench.scenarios.tags import DEFAULT_COMPARISON, STIFF

#: Default ladder of the comparison: the comfortable step and its half.
COMPARE_LADDER = "1x,0.5x"


def compare_scenes() -> list[str]:
    """Registered scenes with a tag of :data:`DEFAULT_COMPARISON`, not in the stiff suite."""
    chosen = []
    for tag in DEFAULT_COMPARISON:
        chosen += [n for n in scene_names(tag) if n not in chosen]
    stiff = set(scene_names(STIFF))
    return [n for n in chosen if n not in stiff]


def register(subparsers) -> None:
    """Add ``demo`` and ``compare`` to ``subparsers``."""
    demo = subparsers.add_parser(
        "demo", help=command_help("demo"),
        description="The main job: validate every registered scene, list the engines, then run "
        "the default comparison of the available engines (`clearbench compare`) and write the "
        "report. Takes the options of `compare`.",
    )
    add_compare_options(demo)
    demo.set_defaults(handler=run_demo)
    parser = subparsers.add_parser(
        "compare", help=command_help("compare"),
        description="Run the default comparison: every available engine (reference, and "
        "MuJoCo etc. where available) on the library scenes tagged "
        f"{' or '.join(DEFAULT_COMPARISON)} at their comfortable step and a short ladder "
        f"({COMPARE_LADDER}), optionally the stiff suite, then write the report. Runs already "
        "in the store are reused.",
    )
    add_compare_options(parser)
    parser.set_defaults(handler=run_compare)


def run_demo(args: argparse.Namespace) -> int:
    """Validate every registered scene, list the engines, then :func:`run_compare`."""
    print("Validating every registered scene (build, lossless round trip):")
    for name in scene_names():
        scene = get_entry(name).build()
        check_round_trip(scene, f"scene {name!r}")
        print(f"  ok  {name:<22} {len(scene.bodies)} bodies, {len(scene.all_contacts)} "
              f"contact pairs, horizon {scene.horizon} {scene.units.time}")
    print()
    print_engines()
    print()
    return run_compare(args)


def add_compare_options(parser: argparse.ArgumentParser) -> None:
    add_engine_option(parser, many=True,
                      help="engines (default: every available engine, default preset)")
    parser.add_argument("--scenes", nargs="+", default=None, metavar="SCENE",
                        help="scenes (default: the library scenes tagged "
                        f"{', '.join(DEFAULT_COMPARISON)})")
    parser.add_argument("--dt", default=COMPARE_LADDER, metavar="LADDER",
                        help=f"time-step ladder (default {COMPARE_LADDER})")
    parser.add_argument("--stability", action="store_true",
                        help="also run the stiff and extreme suite")
    parser.add_argument("--c60", choices=("none", *sorted(PLAN_NAMES)), default="demo",
                        help="C-60 runs across engines after the scenes: the `demo` plan "
                        "(default; shortened horizons, a few minutes), `full` (hours) or none")
    parser.add_argument("--out", default="reports/out", metavar="DIR",
                        help="report directory (default reports/out)")
    add_runner_options(parser, timeout=300.0, runs_per_worker=MANY_RUNS_PER_WORKER)


def run_compare(args: argparse.Namespace) -> int:
    start = time.monotonic()
    modules = engine_modules(args)
    engines = ([resolve_engine(e, modules, field="--engines") for e in args.engines]
               if args.engines else available_engines(modules))
    if not engines:
        raise UserError("no engine is available here (see `clearbench list`)")
    reference = None
    try:
        reference = resolve_engine(REFERENCE_ENGINE, modules)
    except RunInputError as error:
        print(f"note: no fine reference runs: {error}")
    scenes = args.scenes or compare_scenes()
    plan = plan_sweep(scenes, engines, parse_ladder(args.dt), timeout=args.timeout,
                      reference=reference, fine_factor=FINE_FACTOR, campaign="compare")
    stiff = plan_stability(engines, timeout=args.timeout) if args.stability else []
    c60 = (c60_plan_specs(args.c60, [e.label for e in engines] if args.engines else None,
                          modules) if args.c60 != "none" else [])
    store = open_store(args)
    labels = ", ".join(e.label for e in engines)
    print(f"Comparing {labels} on {len(scenes)} scenes (ladder {args.dt}"
          + (", and the stiff suite" if stiff else "") + (", and the C-60" if c60 else "")
          + f"), store {store.directory}")
    # One batch, the C-60's longest runs first: they run beside the scenes' short ones. Before
    # them, one worker compiles the reference's kernels (two-step runs of its pending scenes)
    # while the others run the other engines.
    runner = make_runner(args, store, len(c60) + len(plan.all_specs) + len(stiff))
    stored = store.reusable_keys()
    warm_up = warm_up_jobs([s for s in (*c60, *plan.all_specs, *stiff) if s.key not in stored],
                           extra_modules=modules)
    outcome = execute_plan(plan, runner, before=[*warm_up, *c60])
    if stiff:
        more = runner.run_all(stiff)
        outcome.ran += more.ran
        outcome.skipped += more.skipped
    print(f"{len(outcome.ran)} runs done, {len(outcome.skipped)} reused from the store, "
          f"{time.monotonic() - start:.0f} s")
    print_work_precision(store, [s.scene.name for s in plan.all_specs],
                         {s.key for s in plan.all_specs})
    if c60:
        print()
        print_c60(store, {s.key for s in c60})
    paths = write_report(store, args.out, engine_modules=modules)
    print(f"\nreport: {paths['html']}\nsummary: {paths['markdown']} "
          f"({time.monotonic() - start:.0f} s in all)")
    return 0
