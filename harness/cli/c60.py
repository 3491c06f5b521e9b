"""``clearbench c60``: the C-60 circuit-breaker tools.

- ``clearbench c60 validate``: the validation table against the published figures. Runs the
  C-60 scenes it needs with the reference engine (isolated workers, a wall-clock limit, runs
  kept in the results store ``--store``), prints the table and writes it as Markdown with
  force-displacement figures.
- ``clearbench c60 compare [--plan demo|full]``: c60-on and c60-trip in every available engine
  and preset over a ladder of steps (the plans of :mod:`clearbench.harness.studies.c60_comparison`),
  the cross-engine table and the work-precision summary printed, then the report written.
- ``clearbench c60 identify``: the identification study (which of the source's documented
  alternatives reproduces which section of the paper), one table in
  ``reports/c60_identification.md``; its runs go through the store like the validation's.
- ``clearbench c60 angles TRAJECTORY.npz``: each body's angle about z and the largest body
  speed along a run (a diagnostic, for example of a stored run).
"""

from __future__ import annotations

import argparse
import math
from dataclasses import replace
from pathlib import Path

from clearbench.adapters.trajectory import Trajectory
from clearbench.harness.c60 import identification
from clearbench.harness.c60.angles import body_angles
from clearbench.harness.c60.cross_engine import collect
from clearbench.harness.c60.runs import DEFAULT_TIMEOUT as STUDY_TIMEOUT
from clearbench.harness.c60.runs import StudyRuns
from clearbench.harness.c60.validation import validate, write_figures, write_json, write_markdown
from clearbench.harness.c60.work_precision import BUDGETS, error_budget, work_precision
from clearbench.harness.cli.commands import command_help
from clearbench.harness.cli.common import (
    UserError,
    add_engine_option,
    add_engine_options_option,
    add_runner_options,
    engine_modules,
    engine_options,
    make_runner,
    open_store,
)
from clearbench.harness.measure.headline import format_value
from clearbench.harness.report.page import write_report
from clearbench.harness.run.engine_choice import RunInputError, check_options, resolve_engine
from clearbench.harness.studies.c60_comparison import PLAN_NAMES, c60_plan, plan_engines, plan_runs

DEFAULT_REPORT = Path("reports/c60_validation.md")
DEFAULT_FIGURES = Path("reports/figures")
DEFAULT_IDENTIFICATION = Path("reports/c60_identification.md")


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "c60", help=command_help("c60"),
        description="C-60 circuit-breaker tools. `clearbench c60 validate` runs the C-60 "
        "scenes with the reference engine and compares FC-1, the functional conditions, the "
        "trip and the bench tests of Section 5 with the paper's figures; `clearbench c60 "
        "angles` prints each body's angle along a trajectory.",
    )
    commands = parser.add_subparsers(dest="c60_command", metavar="C60_COMMAND")
    commands.required = True
    validate = commands.add_parser(
        "validate", help="run the C-60 scenes and write the validation table",
        description="Run (or read from the results store) the C-60 scenes, print the "
        "validation table, write it as Markdown and the force-displacement figures as PNG. "
        "Each run executes in its own worker process with a wall-clock limit and is kept in "
        "the store under its run key (scene, preset, settings, code), so a repeated command "
        "reuses it; a run that crashed, timed out or diverged is reported as such. The first "
        "time tens of minutes of stepping on one core.",
    )
    _add_run_options(validate, DEFAULT_REPORT, "Markdown report")
    validate.add_argument("--figures", type=Path, default=DEFAULT_FIGURES,
                          help=f"directory of the PNG figures (default {DEFAULT_FIGURES})")
    validate.add_argument("--no-speed-check", action="store_true",
                          help="skip the half-speed reruns of the bench tests")
    validate.add_argument("--no-sensitivity", action="store_true",
                          help="skip the variants' runs (preload 0.9599 rad, the paper's Table 4 "
                          "friction, mu_C4 0.1; shared with `clearbench c60 identify`)")
    validate.set_defaults(handler=run_validate)
    compare = commands.add_parser(
        "compare", help="c60-on and c60-trip across engines, work-precision, report",
        description="Run c60-on and c60-trip in every available engine and preset of the "
        "plan over its ladder of steps (runs already in the store are reused), print the "
        "cross-engine figures (FC-1, latch creep, trip times, penetration, wall time) and each "
        "engine's cheapest step within an error budget of 1 % and 5 % (its error and every "
        "finer step's), and write the report. Plan `demo` (what "
        "`clearbench demo` runs: shortened horizons, a few minutes of CPU) or `full` (the "
        "scenes' horizons and longer ladders: hours).",
    )
    compare.add_argument("--plan", choices=sorted(PLAN_NAMES), default="demo",
                         help="which runs (default demo)")
    add_engine_option(compare, many=True,
                      help="only these labels of the plan (default: every label whose engine "
                      "is available)")
    compare.add_argument("--out", default="reports/out", metavar="DIR",
                         help="report directory (default reports/out)")
    add_runner_options(compare, timeout=7200.0)
    compare.set_defaults(handler=run_c60_compare)
    identify = commands.add_parser(
        "identify", help="which documented variant of the model reproduces which paper figure",
        description="Run (or read from the results store) c60-on at the paper's mean "
        "clearances and at the prototype's, and the bench tests, for the source's documented "
        "alternatives and their combinations; write one table of every published figure per "
        "variant with the sections each matches. About 30 c60-on runs of 4 ms and 8 bench "
        "tests: tens of minutes on one core the first time, seconds from the store.",
    )
    _add_run_options(identify, DEFAULT_IDENTIFICATION, "Markdown table (JSON beside it)")
    identify.add_argument("--variants", metavar="NAME,...",
                          help="only these variants of the study (default: all of them)")
    identify.add_argument("--runs", choices=("all", "on", "bench"), default="all",
                          help="all (default), only the c60-on runs, or only the bench tests")
    identify.add_argument("--no-calibration", action="store_true",
                          help="skip the labelled calibration (the preload fitted to the "
                          "prototype's FC-1, judged on the other figures)")
    identify.add_argument("--stored-only", action="store_true",
                          help="write the table from the runs in the store only, running "
                          "nothing")
    identify.set_defaults(handler=run_identify)
    angles = commands.add_parser(
        "angles", help="each body's angle about z and the largest speed along a trajectory",
        description="For a trajectory written by the reference engine (for example a run of "
        "`clearbench c60 validate` in the store: reports/store/trajectories/KEY.npz, KEY the "
        "run's store_key in reports/c60_validation.json), print every EVERY "
        "ms the absolute angle of each body about z (the angle the source's angle laws use, "
        "in (-pi, pi]) and the largest body speed. A diagnostic; asserts nothing.",
    )
    angles.add_argument("trajectory", type=Path, metavar="TRAJECTORY.npz")
    angles.add_argument("--every", type=float, default=1.0, metavar="MS",
                        help="time between printed samples [ms] (default 1)")
    angles.set_defaults(handler=run_angles)


def _add_run_options(parser, report: Path, what: str) -> None:
    """--out, --preset and the runner's options of the commands that run the C-60 studies."""
    parser.add_argument("--out", type=Path, default=report, help=f"{what} (default {report})")
    parser.add_argument("--preset", default="default", help="reference engine preset")
    add_engine_options_option(parser, "a reference engine option of every run (as "
                              "`clearbench run --option`; repeatable), for instance a scheme "
                              "variant")
    add_runner_options(parser, timeout=STUDY_TIMEOUT, engine_module=False)


def _study_runs(args: argparse.Namespace, campaign: str, run_missing: bool = True) -> StudyRuns:
    """The runs of a study in the command's store, made by the command's runner with the
    reference engine's ``--preset`` (checked before any run: exit 2)."""
    engine = resolve_engine(f"reference[{args.preset}]")
    options = engine_options(args)
    check_options(engine, options)
    store = open_store(args)
    runner = make_runner(args, store, total=2)   # a study makes several runs
    return StudyRuns(store, runner, engine, timeout=args.timeout, run_missing=run_missing,
                     rerun=args.rerun, campaign=campaign, options=options)


def _print_made(runs: StudyRuns) -> None:
    print(f"C-60 runs: {len(runs.made)} made, {len(runs.reused)} reused from the store "
          f"({runs.store.directory})")


def run_validate(args: argparse.Namespace) -> int:
    runs = _study_runs(args, "c60-validate")
    report = validate(runs, speed_check=not args.no_speed_check,
                      sensitivity=not args.no_sensitivity)
    _print_made(runs)
    print(f"{'quantity':<78} {'ours':>9} {'sim.':>7} {'meas.':>7} {'diff':>8}")
    for row in report.rows:
        difference = row.difference()
        text = "" if math.isnan(difference) else f"{100 * difference:+.1f}%"
        print(f"{row.quantity[:78]:<78} {row.ours:>9.4f} {row.paper_simulated:>7.3f} "
              f"{row.paper_measured:>7.3f} {text:>8}")
    for finding in report.findings:
        print(f"- {finding}")
    figures = write_figures(report, args.figures)
    write_markdown(report, args.out, figures, runs.settings_label)
    write_json(report, args.out.with_suffix(".json"), figures, runs.settings_label)
    print(f"report: {args.out} (and {args.out.with_suffix('.json')} for `clearbench report`)")
    for path in figures.values():
        print(f"figure: {path}")
    return 0


def run_identify(args: argparse.Namespace) -> int:
    candidates = identification.CANDIDATES
    if args.variants:
        wanted = [name.strip() for name in args.variants.split(",") if name.strip()]
        known = {c.name: c for c in candidates}
        unknown = [name for name in wanted if name not in known]
        if unknown or not wanted:
            raise UserError(f"--variants {args.variants}: unknown {unknown}; the study's "
                            f"variants: {', '.join(known)}")
        candidates = tuple(known[name] for name in wanted)
    if args.runs == "on":
        candidates = tuple(replace(c, trip_test=False, contact_test=False) for c in candidates)
    elif args.runs == "bench":
        candidates = tuple(replace(c, on=False) for c in candidates)
    runs = _study_runs(args, "c60-identify", run_missing=not args.stored_only)
    study = identification.identify(runs, candidates, calibrate=not args.no_calibration)
    _print_made(runs)
    lines = identification.table_lines(study)
    print("\n".join(lines))
    identification.write_markdown(study, args.out, runs.settings_label, identification.ON_HORIZON)
    identification.write_json(study, args.out.with_suffix(".json"))
    print(f"report: {args.out} (and {args.out.with_suffix('.json')})")
    return 0


def run_angles(args: argparse.Namespace) -> int:
    if not args.trajectory.is_file():
        raise UserError(f"{args.trajectory}: no such file")
    if not args.every > 0:
        raise UserError(f"--every {args.every}: must be > 0")
    trajectory = Trajectory.load(args.trajectory)
    print("t [ms]  " + "  ".join(f"{n[:12]:>12s}" for n in trajectory.body_names)
          + "  max speed")
    for sample in body_angles(trajectory, args.every):
        print(f"{sample.time:6.2f}  " + "  ".join(f"{a:12.3f}" for a in sample.angles)
              + f"  {sample.max_speed:9.3g}")
    return 0


def c60_plan_specs(plan_name: str, labels, modules) -> list:
    """The plan's C-60 runs (``labels``: only these engine labels), longest expected first;
    print the labels left out and why (UserError for a plan the engines declare wrongly)."""
    try:
        plan = c60_plan(plan_name, modules)
        engines, left_out = plan_engines(plan, labels, modules)
        specs = plan_runs(plan, engines)
    except RunInputError as error:
        raise UserError(str(error)) from None
    for label, reason in left_out.items():
        print(f"C-60 {plan.name}: {label} left out: {reason}")
    print(f"C-60 {plan.name} ({plan.description}): {len(specs)} runs")
    return specs


def run_c60_plan(plan_name: str, labels, modules, args, store) -> set[str]:
    """Validate and run the plan's C-60 runs (``labels``: only these engine labels); print
    the labels left out and why, then the cross-engine figures. Returns the run keys."""
    specs = c60_plan_specs(plan_name, labels, modules)
    runner = make_runner(args, store, len(specs))
    outcome = runner.run_all(specs)
    print(f"C-60: {outcome.summary()}")
    print_c60(store, {s.key for s in specs})
    return {s.key for s in specs}


def print_c60(store, keys: set[str]) -> None:
    """The cross-engine figures of the runs ``keys`` and each engine's cheapest step within
    each error budget (:data:`BUDGETS`)."""
    frame = store.dataframe(expand_metrics=False)
    runs = collect(store, frame[frame["key"].isin(keys)])
    print(f"\n  {'scene':<9} {'engine':<20} {'dt [ms]':>8} {'status':<10} {'FC-1 [N]':>9} "
          f"{'creep [mm]':>10} {'open [ms]':>9} {'pen. [mm]':>9} {'instr. [mm]':>11} "
          f"{'unseen [mm]':>11} {'beyond [mm]':>11} "
          f"{'wall [s]':>8} {'x ref':>6}")
    for run in runs:
        print(f"  {run.scene_name:<9} {run.label:<20} {run.time_step:>8.3g} {run.status:<10} "
              f"{format_value(run.fc1):>9} {format_value(run.latch_creep):>10} "
              f"{format_value(run.opening):>9} {format_value(run.penetration_max):>9} "
              f"{format_value(run.instrument_penetration):>11} "
              f"{format_value(run.unseen_penetration):>11} "
              f"{format_value(run.penetration_beyond_rebuild):>11} "
              f"{format_value(run.stepping_seconds):>8} "
              f"{format_value(run.ratio_to_reference):>6}")
    for study in work_precision(runs):
        print(f"\n  {study.quantity}: reference {study.reference_value:.5g} at dt = "
              f"{study.reference_step:g} ms (horizon {study.horizon:g} ms); the cheapest step "
              "whose error and every finer step's stay within the budget:")
        for budget in BUDGETS:
            for entry in error_budget(runs, study, budget):
                print(f"    {entry.label:<22} {entry.describe()}")


def run_c60_compare(args: argparse.Namespace) -> int:
    modules = engine_modules(args)
    store = open_store(args)
    run_c60_plan(args.plan, args.engines, modules, args, store)
    paths = write_report(store, args.out, engine_modules=modules)
    print(f"\nreport: {paths['html']}\nsummary: {paths['markdown']}")
    return 0
