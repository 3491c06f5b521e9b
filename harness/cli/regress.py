"""``clearbench regress``: the quick suite against its committed baseline."""

from __future__ import annotations

import argparse
import time

from clearbench.harness.cli.common import UserError, engine_modules
from clearbench.harness.run.engine_choice import RunInputError
from clearbench.harness.studies.regress import (
    DEFAULT_BASELINE,
    compare,
    load_baseline,
    run_suite,
    suite_specs,
    updated_baseline,
    write_baseline,
)


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "regress", help="compare a quick suite with the committed baseline",
        description="Run the quick suite of the baseline file (every available engine on a "
        "few smoke scenes with short horizons, and a short c60-on each) in a fresh temporary "
        "store and compare status, expectations and every metric with the baseline, within the "
        "per-engine, per-metric tolerances stated in the file. Exit status 1 naming each "
        "regression (engine, scene, figure, and whether the engine's version changed); an "
        "engine not available here is skipped with a note; --update rewrites the baseline's "
        "results instead.",
    )
    parser.add_argument("--baseline", default=str(DEFAULT_BASELINE), metavar="FILE",
                        help=f"baseline file (default {DEFAULT_BASELINE})")
    parser.add_argument("--update", action="store_true",
                        help="rewrite the baseline's results from this run")
    parser.add_argument("--jobs", "-j", type=int, default=None,
                        help="parallel workers (default: usable cores)")
    parser.add_argument("--runs-per-worker", type=int, default=1, metavar="N",
                        help="runs a worker serves before it is replaced (default 1)")
    parser.add_argument("--engine-module", action="append", default=[], metavar="NAME=MODULE",
                        help="an extra engine adapter module, e.g. mine=my_package.adapter")
    parser.set_defaults(handler=run_regress)


def run_regress(args: argparse.Namespace) -> int:
    start = time.monotonic()
    try:
        baseline = load_baseline(args.baseline)
        skipped: dict[str, str] = {}
        specs = suite_specs(baseline, engine_modules(args), skipped)
    except RunInputError as error:
        raise UserError(f"{args.baseline}: {error}") from None
    except ValueError as error:
        raise UserError(f"{args.baseline}: not a baseline file: {error}") from None
    if args.runs_per_worker < 1 or (args.jobs is not None and args.jobs < 1):
        raise UserError("--jobs and --runs-per-worker must be >= 1")
    results = run_suite(specs, jobs=args.jobs, runs_per_worker=args.runs_per_worker)
    elapsed = time.monotonic() - start
    if args.update:
        write_baseline(args.baseline, updated_baseline(baseline, results, skipped))
        statuses = ", ".join(f"{i} {r['status']}" for i, r in results.items())
        print(f"baseline {args.baseline} updated from {len(results)} runs in {elapsed:.1f} s "
              f"({statuses})")
        for ident, why in skipped.items():
            print(f"note: {ident}: not run, its baseline result kept ({why})")
        return 0
    outcome = compare(baseline, results, skipped)
    for note in outcome.notes:
        print(f"note: {note}")
    if outcome.regressions:
        print(f"REGRESSIONS against {args.baseline} ({len(outcome.regressions)}):")
        for line in outcome.regressions:
            print(f"  {line}")
        return 1
    print(f"no regression: {outcome.runs} runs, {outcome.compared_figures} figures within "
          f"tolerance of {args.baseline} ({elapsed:.1f} s)")
    return 0
