"""``clearbench regress``: the quick suite against its committed baseline."""

from __future__ import annotations

import argparse
import dataclasses
import time

from clearbench.harness.cli.commands import command_help
from clearbench.harness.cli.common import (
    UserError,
    add_engine_module_option,
    add_engine_option,
    engine_modules,
)
from clearbench.harness.run.engine_choice import RunInputError
from clearbench.harness.run.runner import MANY_RUNS_PER_WORKER
from clearbench.harness.studies.regress import (
    DEFAULT_BASELINE,
    compare,
    load_baseline,
    measure_baseline,
    run_suite,
    suite_entries,
    suite_specs,
    updated_baseline,
    write_baseline,
)
from clearbench.harness.studies.regress.suite import (
    EngineSelection,
    engines_without_runs,
    restricted,
    warm_up,
    with_declared_runs,
)


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "regress", help=command_help("regress"),
        description="Run the quick suite of the baseline file (every available engine on a "
        "few smoke scenes with short horizons, and a short c60-on each) in a fresh temporary "
        "store and compare status, expectations and every figure with the baseline, each "
        "against the tolerance measured for it (exact within its round-off spread, bounded, "
        "or within the range of an ensemble: docs/harness.md#regression). Exit status 1 "
        "naming each regression (engine, scene, figure, criterion, and whether the engine's "
        "version changed); an engine not available here is skipped with a note. --update "
        "re-measures the baseline: every run as given and under each perturbation the file "
        "lists (round-off of the initial state, numba and OpenBLAS code paths, an engine's "
        "own arithmetic settings), about five times the time of a check.",
    )
    parser.add_argument("--baseline", default=str(DEFAULT_BASELINE), metavar="FILE",
                        help=f"baseline file (default {DEFAULT_BASELINE})")
    parser.add_argument("--update", action="store_true",
                        help="re-measure the baseline's results and tolerances")
    parser.add_argument("--jobs", "-j", type=int, default=None,
                        help="parallel workers (default: usable cores)")
    parser.add_argument("--runs-per-worker", type=int, default=MANY_RUNS_PER_WORKER,
                        metavar="N", help="runs a worker serves before it is replaced (default "
                        f"{MANY_RUNS_PER_WORKER}; a crashed or timed-out one always is)")
    parser.add_argument("--timeout", type=float, default=None, metavar="SECONDS",
                        help="wall-clock limit of every run (default: each entry's own, 300 s "
                        "unless it says; numba cannot cache kernels compiled with NUMBA_OPT=0, "
                        "so each worker then compiles them first: docs/harness.md#regression)")
    add_engine_option(parser, many=True,
                      help="only the suite's entries of these engines (ENGINE: all of its "
                      "entries, ENGINE[PRESET]: that label's); with --update, an engine with no "
                      "entry yet gets the quick runs it declares (its HARNESS_DEFAULTS) and the "
                      "other engines' results are kept")
    add_engine_module_option(parser)
    parser.set_defaults(handler=run_regress)


def run_regress(args: argparse.Namespace) -> int:
    start = time.monotonic()
    modules = engine_modules(args)
    try:
        chosen = EngineSelection.parse(args.engines, modules) if args.engines else None
        baseline = load_baseline(args.baseline, chosen.names if chosen else None, modules)
        if chosen and args.update:
            baseline, added = with_declared_runs(baseline, chosen.names, modules)
            for name in added:
                print(f"{name}: the quick runs it declares added to the suite")
        part, others = restricted(baseline, chosen)
        skipped: dict[str, str] = {}
        specs = suite_specs(part, modules, skipped)
        entries = {ident: entry for ident, entry in suite_entries(part, modules).items()
                   if ident in specs}
        missing = engines_without_runs(part, chosen.names if chosen else None, modules)
    except RunInputError as error:
        raise UserError(f"{args.baseline}: {error}") from None
    except ValueError as error:
        raise UserError(f"{args.baseline}: not a baseline file: {error}") from None
    if args.runs_per_worker < 1 or (args.jobs is not None and args.jobs < 1):
        raise UserError("--jobs and --runs-per-worker must be >= 1")
    if args.timeout is not None:
        if not args.timeout > 0:
            raise UserError(f"--timeout {args.timeout:g}: expected a positive number of seconds")
        specs = {ident: dataclasses.replace(spec, timeout=args.timeout)
                 for ident, spec in specs.items()}
    if args.update:
        return _update(args, baseline, entries, specs, skipped, others, modules, start)
    for name in missing:
        print(f"note: {name}: no run in the suite (`clearbench regress --update -e {name}` "
              "adds the quick runs it declares)")
    warm_up(entries, modules)
    results = run_suite(specs, jobs=args.jobs, runs_per_worker=args.runs_per_worker)
    elapsed = time.monotonic() - start
    outcome = compare(part, results, skipped)
    for note in outcome.notes:
        print(f"note: {note}")
    if outcome.regressions:
        print(f"REGRESSIONS against {args.baseline} ({len(outcome.regressions)}):")
        for line in outcome.regressions:
            print(f"  {line}")
        return 1
    print(f"no regression: {outcome.runs} runs, {outcome.compared_figures} figures within "
          f"their measured tolerances of {args.baseline} ({elapsed:.1f} s)")
    return 0


def _update(args, baseline, entries, specs, skipped, others, modules, start) -> int:
    """Measure ``entries`` and write the baseline; the results of the ``skipped`` runs (engine
    not available) and of the ``others`` (engines not chosen) kept as they were."""
    def announce(label: str, runs: int) -> None:
        print(f"measuring: {runs} runs ({label}), {time.monotonic() - start:.0f} s so far",
              flush=True)

    measured = measure_baseline(entries, specs, baseline["perturbations"], modules,
                                jobs=args.jobs, runs_per_worker=args.runs_per_worker,
                                on_group=announce)
    results = measured["results"]
    cost = {"runs": measured["runs"], "worker_seconds": measured["worker_seconds"],
            "seconds": measured["seconds"]}
    kept = {**skipped, **dict.fromkeys(others, "engine not chosen")}
    write_baseline(args.baseline, updated_baseline(baseline, results, kept, cost, modules))
    statuses = ", ".join(f"{i} {r['status']}" for i, r in results.items())
    kinds: dict[str, int] = {}
    for result in results.values():
        for check in result["checks"].values():
            kinds[check["kind"]] = kinds.get(check["kind"], 0) + 1
    print(f"baseline {args.baseline} re-measured from {measured['runs']} runs in "
          f"{time.monotonic() - start:.1f} s ({statuses})")
    print("figures: " + ", ".join(f"{n} {k}" for k, n in sorted(kinds.items())))
    for ident, why in skipped.items():
        print(f"note: {ident}: not run, its baseline result kept ({why})")
    if others:
        print(f"note: {len(others)} runs of the engines not chosen not run, their baseline "
              "results kept")
    return 0
