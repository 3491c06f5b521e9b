"""What the sub-commands share: :class:`~clearbench.harness.cli.errors.UserError` (imported
here for them), the ``-e`` engine option of every command (:func:`add_engine_option`), the
options of the commands that run engines (store, parallelism, limits, plugins) and their
progress line (:func:`progress_line`).

Bad input is reported by :func:`clearbench.harness.cli.main.main` as one line on stderr with
exit status 2: a command raises :class:`UserError` for a bad option of its own, and lets the
input errors of the layers below (:class:`~clearbench.harness.run.engine_choice.RunInputError`,
:class:`~clearbench.scenarios.validation.SceneError`) propagate unchanged.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from pathlib import Path

from clearbench.harness.cli.errors import UserError
from clearbench.harness.measure.headline import format_value
from clearbench.harness.measure.verdicts import run_verdict, verdict_text
from clearbench.harness.run.runner import Runner, default_jobs
from clearbench.harness.run.spec import DEFAULT_TIMEOUT, RunSpec, parse_assignment
from clearbench.harness.run.store import ResultsStore, RunRecord
from clearbench.scenarios.units import TIME_UNITS

#: Store used when --store is not given (overridden by the CLEARBENCH_STORE variable).
DEFAULT_STORE = "reports/store"


def default_store() -> str:
    return os.environ.get("CLEARBENCH_STORE", DEFAULT_STORE)


def add_engine_options_option(parser: argparse.ArgumentParser, help: str) -> None:
    """``--option KEY=VALUE`` (repeatable): engine options, read by :func:`engine_options`."""
    parser.add_argument("--option", action="append", default=[], metavar="KEY=VALUE", help=help)


def engine_options(args: argparse.Namespace) -> dict:
    """The engine options of ``--option`` (:func:`add_engine_options_option`), parsed."""
    return assignments(args.option, "--option")


def add_store_option(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--store", default=None, metavar="DIR",
                        help=f"results store directory (default: $CLEARBENCH_STORE or "
                        f"{DEFAULT_STORE})")


def add_runner_options(parser: argparse.ArgumentParser, timeout: float = DEFAULT_TIMEOUT,
                       engine_module: bool = True, runs_per_worker: int = 1) -> None:
    """--store, --jobs, --timeout, --runs-per-worker (default ``runs_per_worker``), --rerun,
    --engine-module (unless not ``engine_module``: a command that runs only the reference
    engine), --no-progress."""
    add_store_option(parser)
    parser.add_argument("--jobs", "-j", type=int, default=None,
                        help=f"parallel worker processes (default: usable cores, here "
                        f"{default_jobs()})")
    parser.add_argument("--timeout", type=float, default=timeout, metavar="SECONDS",
                        help=f"wall-clock limit of each run (default {timeout:g} s)")
    fresh = ": a fresh process per run" if runs_per_worker == 1 else ""
    parser.add_argument("--runs-per-worker", type=int, default=runs_per_worker, metavar="N",
                        help="runs a worker process serves before it is replaced (default "
                        f"{runs_per_worker}{fresh}; a crashed or timed-out worker is always "
                        "replaced)")
    parser.add_argument("--rerun", action="store_true",
                        help="run again even when the run is already in the store")
    if engine_module:
        add_engine_module_option(parser)
    parser.add_argument("--no-progress", action="store_true",
                        help="no progress bar (terminal) nor progress lines (log or pipe)")


def add_engine_module_option(parser: argparse.ArgumentParser) -> None:
    """--engine-module NAME=MODULE (repeatable): an engine plugged in (:func:`engine_modules`)."""
    parser.add_argument("--engine-module", action="append", default=[], metavar="NAME=MODULE",
                        help="an extra engine adapter module (same contract as "
                        "clearbench.adapters, its harness defaults included), e.g. "
                        "mine=my_package.my_adapter")


class _AccumulateEngines(argparse.Action):
    """Every ``-e`` adds its labels (one or several after each flag); the default is replaced
    by the first, not extended."""

    def __call__(self, parser, namespace, values, option_string=None):
        current = getattr(namespace, self.dest, None)
        given = [] if current is None or current is self.default else list(current)
        setattr(namespace, self.dest, [*given, *values])


class _OneEngine(argparse.Action):
    """A command that runs one engine: a second ``-e`` is an error (exit 2), not ignored."""

    def __call__(self, parser, namespace, values, option_string=None):
        seen = f"_{self.dest}_given"
        if getattr(namespace, seen, False):
            parser.error(f"argument {'/'.join(self.option_strings)}: given twice "
                         f"({getattr(namespace, self.dest)!r}, then {values!r}); this command "
                         "runs one engine")
        setattr(namespace, seen, True)
        setattr(namespace, self.dest, values)


def add_engine_option(parser: argparse.ArgumentParser, *, many: bool, default=None,
                      help: str, flags: tuple[str, ...] = ("--engines", "-e"),
                      dest: str | None = None) -> None:
    """The ``-e ENGINE[PRESET]`` option of every command, one implementation.

    ``many``: repeated flags accumulate (``-e a -e b`` and ``-e a b`` both give ``[a, b]``;
    ``default`` when none is given); otherwise the command takes exactly one engine and a
    repeated flag exits with status 2 naming both values.
    """
    dest = dest or ("engines" if many else "engine")
    if many:
        parser.add_argument(*flags, nargs="+", action=_AccumulateEngines, default=default,
                            dest=dest, metavar="ENGINE[PRESET]",
                            help=help + " (repeatable; each -e adds)")
    else:
        parser.add_argument(*flags, action=_OneEngine, default=default, dest=dest,
                            metavar="ENGINE[PRESET]", help=help)


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
    """The runner of a command: a progress bar on stderr when it is a terminal, and one
    :func:`progress_line` per finished run on stdout when stdout is not (a log, a pipe), for
    commands of more than one run, unless ``--no-progress``."""
    if args.jobs is not None and args.jobs < 1:
        raise UserError(f"--jobs {args.jobs}: must be >= 1")
    if args.runs_per_worker < 1:
        raise UserError(f"--runs-per-worker {args.runs_per_worker}: must be >= 1")
    wanted = not args.no_progress and total > 1
    lines = wanted and not sys.stdout.isatty()
    return Runner(store, jobs=args.jobs, runs_per_worker=args.runs_per_worker,
                  progress=wanted and sys.stderr.isatty(),
                  on_finished=print_progress_line if lines else None)


def progress_line(done: int, total: int, spec: RunSpec, record: RunRecord) -> str:
    """``[37/135] reference[default] pendulum dt=1 ms ✓ pass 1.2 s``: the run, its verdict
    and the wall time of its worker's run phase."""
    verdict = verdict_text(run_verdict(record.status, record.expectations_passed,
                                       json.loads(getattr(record, "metrics", "") or "{}")))
    step = format_quantity(spec.time_step * TIME_UNITS[spec.scene.units.time], "s")
    return (f"[{done}/{total}] {spec.engine.label} {spec.scene.name} dt={step} {verdict} "
            f"{format_value(record.worker_seconds, 's')}")


def print_progress_line(done: int, total: int, spec: RunSpec, record: RunRecord) -> None:
    print(progress_line(done, total, spec, record), flush=True)


#: SI prefixes for :func:`format_quantity`, largest first.
_PREFIXES = ((1.0, ""), (1e-3, "m"), (1e-6, "u"), (1e-9, "n"))


def format_quantity(value: float, unit: str) -> str:
    """``0.001, 's'`` -> ``'1 ms'``: 3 significant digits with the largest SI prefix (down
    to nano) that keeps the number at least 1."""
    for factor, prefix in _PREFIXES:
        if abs(value) >= factor:
            return f"{value / factor:.3g} {prefix}{unit}"
    return f"{value:.3g} {unit}"

