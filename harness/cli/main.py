"""The ``clearbench`` command line.

Each sub-command lives in its own module that exposes ``register(subparsers)``; this module only
assembles them, and is the one place where bad input becomes an error message: a
:class:`~clearbench.harness.cli.common.UserError` (a bad option of a command), a
:class:`~clearbench.harness.run.engine_choice.RunInputError` (unknown scene, engine, preset,
bad setting) or a :class:`~clearbench.scenarios.validation.SceneError` (an invalid scene) is
printed as one line on stderr with exit status 2, never as a traceback.
"""

from __future__ import annotations

import argparse
import logging
import sys

from clearbench.harness.cli import (
    bench,
    c60,
    campaign,
    compare,
    fclib,
    regress,
    report,
    run,
    scenes,
    stability,
    sweep,
)
from clearbench.harness.cli.common import UserError
from clearbench.harness.run.engine_choice import RunInputError
from clearbench.scenarios.validation import SceneError

#: Modules that each add one or more sub-commands (``register(subparsers)``), in help order.
COMMAND_MODULES = (scenes, run, sweep, stability, compare, report, regress, fclib, bench, c60,
                   campaign)

#: Errors that mean bad input: reported in one line, exit status 2.
INPUT_ERRORS = (UserError, RunInputError, SceneError)


def build_parser() -> argparse.ArgumentParser:
    """Return the top-level argument parser with every registered sub-command."""
    parser = argparse.ArgumentParser(
        prog="clearbench",
        description="Cross-validation harness for rigid-body contact simulators.",
    )
    parser.add_argument("-v", "--verbose", action="store_true", help="log progress to stderr")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND")
    subparsers.required = True
    for module in COMMAND_MODULES:
        module.register(subparsers)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Entry point of the console script; returns the process exit status."""
    parser = build_parser()
    args = parser.parse_args(argv)
    logging.basicConfig(
        level=logging.INFO if args.verbose else logging.WARNING,
        format="%(levelname)s %(name)s: %(message)s",
    )
    try:
        return int(args.handler(args) or 0)
    except INPUT_ERRORS as error:
        print(f"clearbench {args.command}: error: {error}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # output piped into `head` and the like
        sys.stderr.close()
        return 0


if __name__ == "__main__":
    sys.exit(main())
