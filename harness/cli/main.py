"""The ``clearbench`` command line.

Each sub-command lives in its own module that exposes ``register(subparsers)``; this module only
assembles them. Errors that come from bad user input are reported on stderr with a non-zero exit
status, never as a traceback.
"""

from __future__ import annotations

import argparse
import importlib
import logging
import sys

#: Modules that each add one or more sub-commands (``register(subparsers)``).
COMMAND_MODULES: tuple[str, ...] = (
    "clearbench.harness.cli.scenes",
    "clearbench.harness.cli.run",
    "clearbench.harness.cli.sweep",
    "clearbench.harness.cli.stability",
    "clearbench.harness.cli.compare",
    "clearbench.harness.cli.report",
    "clearbench.harness.cli.regress",
    "clearbench.harness.cli.bench_mujoco",
    "clearbench.harness.cli.fclib",
    "clearbench.harness.cli.bench",
    "clearbench.harness.cli.c60",
    "clearbench.harness.cli.campaign",
)


class UserError(Exception):
    """Bad input from the user: printed as one line on stderr, exit status 2."""


def build_parser() -> argparse.ArgumentParser:
    """Return the top-level argument parser with every registered sub-command."""
    parser = argparse.ArgumentParser(
        prog="clearbench",
        description="Cross-validation harness for rigid-body contact simulators.",
    )
    parser.add_argument("-v", "--verbose", action="store_true", help="log progress to stderr")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND")
    subparsers.required = True
    for module_name in COMMAND_MODULES:
        importlib.import_module(module_name).register(subparsers)
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
    except UserError as error:
        print(f"clearbench {args.command}: error: {error}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # output piped into `head` and the like
        sys.stderr.close()
        return 0


if __name__ == "__main__":
    sys.exit(main())
