"""The ``clearbench`` command line.

Each sub-command lives in its own module that exposes ``register(subparsers)``
(:data:`~clearbench.harness.cli.commands.COMMANDS` names it); this module only assembles them,
importing the module of the command given and no other (``clearbench --help`` imports none),
and is the one place where bad input becomes an error message: a
:class:`~clearbench.harness.cli.errors.UserError` (a bad option of a command), a
:class:`~clearbench.harness.run.engine_choice.RunInputError` (unknown scene, engine, preset,
bad setting) or a :class:`~clearbench.scenarios.validation.SceneError` (an invalid scene) is
printed as one line on stderr with exit status 2, never as a traceback.
"""

from __future__ import annotations

import argparse
import importlib
import logging
import sys
from collections.abc import Iterable

from clearbench.harness.cli.commands import COMMANDS, command_modules
from clearbench.harness.cli.errors import UserError


def input_errors() -> tuple[type[Exception], ...]:
    """Errors that mean bad input: reported in one line, exit status 2 (imported when a command
    runs: the layers that define them import numpy)."""
    from clearbench.harness.run.engine_choice import RunInputError
    from clearbench.scenarios.validation import SceneError

    return (UserError, RunInputError, SceneError)


def build_parser(modules: Iterable[str] | None = None) -> argparse.ArgumentParser:
    """Return the top-level argument parser.

    Parameters
    ----------
    modules : iterable of str, optional
        The command modules (``COMMANDS[...].module``) to import and register in full; every
        other command gets a placeholder parser with its help only. None (default): all of
        them.
    """
    loaded = set(command_modules() if modules is None else modules)
    parser = argparse.ArgumentParser(
        prog="clearbench",
        description="Cross-validation harness for rigid-body contact simulators.",
    )
    parser.add_argument("-v", "--verbose", action="store_true", help="log progress to stderr")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND")
    subparsers.required = True
    registered: set[str] = set()
    for name, command in COMMANDS.items():
        if command.module not in loaded:
            subparsers.add_parser(name, help=command.help, add_help=False)
        elif command.module not in registered:
            module = importlib.import_module(f"clearbench.harness.cli.{command.module}")
            module.register(subparsers)
            registered.add(command.module)
    return parser


def given_command(argv: list[str]) -> str | None:
    """The sub-command named in ``argv`` (the first word that is not an option; the top-level
    options take no value), or None."""
    return next((word for word in argv if not word.startswith("-")), None)


def main(argv: list[str] | None = None) -> int:
    """Entry point of the console script; returns the process exit status."""
    argv = sys.argv[1:] if argv is None else list(argv)
    command = COMMANDS.get(given_command(argv) or "")
    parser = build_parser([command.module] if command else [])
    args = parser.parse_args(argv)
    logging.basicConfig(
        level=logging.INFO if args.verbose else logging.WARNING,
        format="%(levelname)s %(name)s: %(message)s",
    )
    try:
        return int(args.handler(args) or 0)
    except input_errors() as error:
        print(f"clearbench {args.command}: error: {error}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # output piped into `head` and the like
        sys.stderr.close()
        return 0


if __name__ == "__main__":
    sys.exit(main())
