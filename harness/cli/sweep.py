"""``clearbench sweep``: work–precision points per scene and engine over a ladder of steps."""

from __future__ import annotations

import argparse

from clearbench.harness.cli.commands import command_help
from clearbench.harness.cli.common import (
    UserError,
    add_engine_option,
    add_runner_options,
    assignments,
    engine_modules,
    make_runner,
    open_store,
)
from clearbench.harness.measure.headline import format_value
from clearbench.harness.run.engine_choice import RunInputError, resolve_engine
from clearbench.harness.studies.sweep import (
    DEFAULT_LADDER,
    FINE_FACTOR,
    REFERENCE_ENGINE,
    execute_plan,
    parse_ladder,
    plan_sweep,
    resolve_engines,
    work_precision_points,
)
from clearbench.scenarios.library import scene_names


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "sweep", help=command_help("sweep"),
        description="Run every SCENE in every engine at every time step of the ladder (each run "
        "isolated, in parallel, stored; runs already in the store are not run again, so an "
        "interrupted sweep resumes), then print per scene the work–precision points (error "
        "against stepping time per simulated time unit) and the Pareto front. Error is "
        "analytic where the scene has an analytic reference, else against the reference "
        "solver at a fine step on the scene's named outputs.",
    )
    parser.add_argument("scenes", nargs="*", metavar="SCENE",
                        help="registered scene names or scene files")
    parser.add_argument("--tag", help="add every registered scene with this tag")
    add_engine_option(parser, many=True, default=["reference"],
                      help="engines (default: reference)")
    parser.add_argument("--dt", default=DEFAULT_LADDER, metavar="LADDER",
                        help="comma-separated time steps; a trailing x means times the scene's "
                        f"comfortable step (default {DEFAULT_LADDER})")
    parser.add_argument("--horizon", type=float, default=None,
                        help="simulated duration (default: each scene's)")
    parser.add_argument("--record-every", type=int, default=1, metavar="N")
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                        help="a scene factory parameter applied to every scene")
    parser.add_argument("--reference-engine", default=REFERENCE_ENGINE,
                        metavar="ENGINE[PRESET]",
                        help="engine of the fine reference runs (default reference); 'none' "
                        "to measure no error where there is no analytic reference")
    parser.add_argument("--fine-factor", type=float, default=FINE_FACTOR,
                        help=f"fine reference step over the smallest step (default "
                        f"{FINE_FACTOR})")
    add_runner_options(parser)
    parser.set_defaults(handler=run_sweep)


def selected_scenes(names: list[str], tag: str | None) -> list[str]:
    chosen = list(names)
    if tag:
        tagged = scene_names(tag)
        if not tagged:
            raise UserError(f"--tag {tag!r}: no scene has this tag")
        chosen += [n for n in tagged if n not in chosen]
    if not chosen:
        raise UserError("no scene given (name scenes or use --tag)")
    return chosen


def run_sweep(args: argparse.Namespace) -> int:
    scenes = selected_scenes(args.scenes, args.tag)
    modules = engine_modules(args)
    ladder = parse_ladder(args.dt)
    engines = resolve_engines(args.engines, modules)
    reference = None
    if args.reference_engine.lower() != "none":
        try:
            reference = resolve_engine(args.reference_engine, modules,
                                       field="--reference-engine")
        except RunInputError as error:
            print(f"note: no fine reference runs ({error}); error is measured only "
                  "where the scene has an analytic reference")
    if not args.fine_factor > 0:
        raise RunInputError("--fine-factor", args.fine_factor, "must be > 0")
    plan = plan_sweep(scenes, engines, ladder,
                      scene_parameters=assignments(args.set, "--set"),
                      horizon=args.horizon, record_every=args.record_every,
                      timeout=args.timeout, reference=reference,
                      fine_factor=args.fine_factor)
    store = open_store(args)
    runner = make_runner(args, store, len(plan.all_specs))
    outcome = execute_plan(plan, runner, rerun=args.rerun)
    print(f"{outcome.summary()} ({store.directory})")
    print_work_precision(store, [spec.scene.name for spec in plan.all_specs],
                         {spec.key for spec in plan.all_specs})
    return 0


def print_work_precision(store, scene_list: list[str], keys: set[str]) -> None:
    frame = store.dataframe()
    frame = frame[frame["key"].isin(keys)]
    for scene in dict.fromkeys(scene_list):
        rows = frame[frame["scene_name"] == scene]
        print(f"\n{scene}")
        points = work_precision_points(rows, scene)
        print(f"  {'engine':<26} {'dt':>10} {'status':<11} {'error':>10} {'s/sim-unit':>11}  "
              "pareto")
        for _, row in rows.sort_values(["label", "time_step"]).iterrows():
            on_front = points.loc[points["key"] == row["key"], "pareto"]
            mark = "*" if len(on_front) and bool(on_front.iloc[0]) else ""
            role = " (fine ref)" if str(row["campaign"]).endswith(":fine-reference") else ""
            print(f"  {row['label'] + role:<26} {row['time_step']:>10.3g} {row['status']:<11} "
                  f"{format_value(row['error']):>10} "
                  f"{format_value(row['stepping_seconds_per_simulated_second']):>11}  {mark}")
        if not len(points):
            print("  (no work–precision point: no run finished with an error measure)")
