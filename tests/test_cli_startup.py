"""Start-up of the command line: ``clearbench --help`` imports no command module, engine
package, numba kernel or plotting library, ``clearbench list`` imports no engine package (their
availability is found without importing them) and no numba, and the command table the
top-level help is drawn from agrees with what each command module registers. Behaviour, not
timing: what is imported is checked in a fresh interpreter's ``sys.modules``."""

from __future__ import annotations

import argparse
import importlib
import json
import subprocess
import sys

import pytest

from clearbench.harness.cli.commands import COMMANDS, command_modules
from clearbench.harness.cli.main import build_parser, given_command

#: Engine packages (and the engines' heavy dependencies) no start-up may import.
ENGINE_PACKAGES = ("mujoco", "pybullet", "exudyn")
#: What ``--help`` must not import besides: the kernels' compiler, plotting, data frames, the
#: scientific stack, and any command module or engine adapter of the project.
HELP_FORBIDDEN = (*ENGINE_PACKAGES, "numba", "matplotlib", "pandas", "scipy", "numpy",
                  "clearbench.adapters", "clearbench.harness.run", "clearbench.harness.measure",
                  "clearbench.scenarios", "clearbench.ref_solver")


def _modules_after(argv: list[str]) -> set[str]:
    """The modules ``sys.modules`` holds after ``clearbench ARGV`` in a fresh interpreter
    (its output is discarded)."""
    code = (
        "import contextlib, io, json, sys\n"
        "from clearbench.harness.cli.main import main\n"
        "with contextlib.redirect_stdout(io.StringIO()):\n"
        "    try:\n"
        f"        main({argv!r})\n"
        "    except SystemExit:\n"
        "        pass\n"
        "sys.__stdout__.write(json.dumps(sorted(sys.modules)))\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=300, check=True)
    return set(json.loads(done.stdout))


def _imported(modules: set[str], package: str) -> list[str]:
    return sorted(m for m in modules if m == package or m.startswith(package + "."))


def test_help_imports_no_command_module_and_no_engine():
    modules = _modules_after(["--help"])
    found = {name: _imported(modules, name) for name in HELP_FORBIDDEN}
    assert not any(found.values()), {k: v[:3] for k, v in found.items() if v}
    assert not [m for m in modules if m.startswith("clearbench.harness.cli.")
                and m.rsplit(".", 1)[1] in command_modules()]


def test_list_imports_no_engine_package_and_no_kernel_compiler():
    # The engines' availability is found without importing them (Siconos's probe answer is
    # kept per install state), the scenes' features come from the cache of this checkout,
    # and building a scene imports the numba kernels only when it is built.
    _modules_after(["list"])                        # fills the features cache
    modules = _modules_after(["list"])
    assert "clearbench.scenarios.library" in modules  # it did list the scenes
    found = {name: _imported(modules, name) for name in (*ENGINE_PACKAGES, "numba", "scipy")}
    assert not any(found.values()), {k: v[:3] for k, v in found.items() if v}


def _registered_help(module_name: str) -> dict[str, str]:
    """Command -> help of what ``module_name.register`` adds to an empty parser."""
    subparsers = argparse.ArgumentParser().add_subparsers()
    importlib.import_module(f"clearbench.harness.cli.{module_name}").register(subparsers)
    return {action.dest: action.help for action in subparsers._choices_actions}


@pytest.mark.parametrize("module_name", command_modules())
def test_the_command_table_agrees_with_each_module(module_name):
    expected = {name: command.help for name, command in COMMANDS.items()
                if command.module == module_name}
    assert _registered_help(module_name) == expected


def test_a_command_parses_the_same_with_only_its_module_loaded():
    argv = ["run", "pendulum", "-e", "mujoco[tuned]", "--dt", "1e-3"]
    only = build_parser([COMMANDS[given_command(argv)].module]).parse_args(argv)
    full = build_parser().parse_args(argv)
    assert vars(only).keys() == vars(full).keys()
    assert {k: v for k, v in vars(only).items() if k != "handler"} == \
        {k: v for k, v in vars(full).items() if k != "handler"}


def test_the_command_is_the_first_word_that_is_not_an_option():
    assert given_command(["-v", "list", "--tag", "smoke"]) == "list"
    assert given_command(["--help"]) is None
    assert given_command([]) is None
