"""The sub-commands of ``clearbench``: each one's module and one-line help, in help order.

This table is all the top-level parser needs to list the commands, so ``clearbench --help``
imports no command module (and so no engine, numba kernel or plotting library); the module of a
command is imported only when that command is given (:func:`clearbench.harness.cli.main.main`).
Each module registers its commands with ``register(subparsers)`` and takes their help from here
(:func:`command_help`).
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Command:
    """One sub-command: the module of :mod:`clearbench.harness.cli` that registers it, and
    its one-line help."""

    module: str
    help: str


#: Sub-command -> its module and help, in help order (a module's commands next to each other,
#: in the order its ``register`` adds them).
COMMANDS: dict[str, Command] = {
    "list": Command("scenes", "list the registered scenes (tags, features) and the engines"),
    "show": Command("scenes", "print a scene in TOML or JSON"),
    "validate": Command("scenes", "validate a scene file (TOML or JSON)"),
    "demo": Command("compare", "the README's main job: validate the scenes, run the "
                    "comparison, report"),
    "compare": Command("compare", "the default comparison of the available engines, and its "
                       "report"),
    "run": Command("run", "run one scene in one engine and print its metrics"),
    "sweep": Command("sweep", "work–precision sweep: error against stepping time over a "
                     "ladder of steps"),
    "stability": Command("stability", "the stiff and extreme suite: verdict and metrics per "
                         "engine"),
    "report": Command("report", "write the HTML report and Markdown summary from a results "
                      "store"),
    "regress": Command("regress", "compare a quick suite with the committed baseline"),
    "fclib": Command("fclib", "validate the contact solvers on FCLIB problems (side by side "
                     "with Siconos)"),
    "check-geometry": Command("check_geometry", "recorded runs' penetration read a second way "
                              "by the independent geometry instrument, beside the kernel's"),
    "bench": Command("bench", "run a benchmark (prints figures, asserts nothing)"),
    "c60": Command("c60", "C-60 circuit breaker: validation against the published figures"),
    "compile": Command("compile_kernels", "compile the numba kernels into this checkout's "
                       "cache, in parallel"),
    "campaign": Command("campaign", "tolerance studies: Monte Carlo / quasi-Monte Carlo over "
                        "scene parameters, resumable, on Dask"),
}


def command_help(name: str) -> str:
    """The one-line help of sub-command ``name`` (KeyError for a name not in :data:`COMMANDS`)."""
    return COMMANDS[name].help


def command_modules() -> list[str]:
    """The modules of :data:`COMMANDS`, each once, in help order."""
    return list(dict.fromkeys(command.module for command in COMMANDS.values()))
