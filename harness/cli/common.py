"""What the sub-commands share: :class:`UserError` and the options of the commands that run
engines (store, parallelism, limits, plugins).

Bad input is reported by :func:`clearbench.harness.cli.main.main` as one line on stderr with
exit status 2: a command raises :class:`UserError` for a bad option of its own, and lets the
input errors of the layers below (:class:`~clearbench.harness.run.engine_choice.RunInputError`,
:class:`~clearbench.scenarios.validation.SceneError`) propagate unchanged.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from clearbench.harness.run.runner import Runner, default_jobs
from clearbench.harness.run.spec import DEFAULT_TIMEOUT, parse_assignment
from clearbench.harness.run.store import ResultsStore


class UserError(Exception):
    """Bad input from the user: printed as one line on stderr, exit status 2."""


#: Store used when --store is not given (overridden by the CLEARBENCH_STORE variable).
DEFAULT_STORE = "reports/store"


def default_store() -> str:
    return os.environ.get("CLEARBENCH_STORE", DEFAULT_STORE)


def add_store_option(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--store", default=None, metavar="DIR",
                        help=f"results store directory (default: $CLEARBENCH_STORE or "
                        f"{DEFAULT_STORE})")


def add_runner_options(parser: argparse.ArgumentParser, timeout: float = DEFAULT_TIMEOUT) -> None:
    """--store, --jobs, --timeout, --runs-per-worker, --rerun, --engine-module, --no-progress."""
    add_store_option(parser)
    parser.add_argument("--jobs", "-j", type=int, default=None,
                        help=f"parallel worker processes (default: usable cores, here "
                        f"{default_jobs()})")
    parser.add_argument("--timeout", type=float, default=timeout, metavar="SECONDS",
                        help=f"wall-clock limit of each run (default {timeout:g} s)")
    parser.add_argument("--runs-per-worker", type=int, default=1, metavar="N",
                        help="runs a worker process serves before it is replaced (default 1: a "
                        "fresh process per run; a crashed or timed-out worker is always replaced)")
    parser.add_argument("--rerun", action="store_true",
                        help="run again even when the run is already in the store")
    parser.add_argument("--engine-module", action="append", default=[], metavar="NAME=MODULE",
                        help="an extra engine adapter module (same contract as "
                        "clearbench.adapters), e.g. mine=my_package.my_adapter")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")


def open_store(args: argparse.Namespace, create: bool = True) -> ResultsStore:
    path = Path(args.store or default_store())
    if not create and not (path / "runs.sqlite").exists():
        raise UserError(f"--store {path}: no results store there (run a sweep first)")
    try:
        return ResultsStore(path)
    except (OSError, ValueError) as error:
        raise UserError(f"--store {path}: {error}") from None


def engine_modules(args: argparse.Namespace) -> dict[str, str]:
    modules = {}
    for text in args.engine_module:
        name, sep, module = text.partition("=")
        if not sep or not name or not module:
            raise UserError(f"--engine-module {text!r}: expected NAME=MODULE")
        modules[name.strip()] = module.strip()
    return modules


def assignments(items: list[str], option: str) -> dict:
    """``['a=1', 'b=x']`` -> ``{'a': 1, 'b': 'x'}`` (values read as TOML literals)."""
    return dict(parse_assignment(text, option) for text in items or [])


def make_runner(args: argparse.Namespace, store: ResultsStore, total: int) -> Runner:
    if args.jobs is not None and args.jobs < 1:
        raise UserError(f"--jobs {args.jobs}: must be >= 1")
    if args.runs_per_worker < 1:
        raise UserError(f"--runs-per-worker {args.runs_per_worker}: must be >= 1")
    progress = not args.no_progress and total > 1 and sys.stderr.isatty()
    return Runner(store, jobs=args.jobs, runs_per_worker=args.runs_per_worker,
                  progress=progress)

