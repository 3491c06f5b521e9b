"""One template for an engine that steps in this process, read from the sources (no engine is
imported or run, so the check holds whether an engine is installed here or not).

Every such engine of :data:`clearbench.adapters.ENGINES`, and the toy engine of the tests, is a
:class:`~clearbench.adapters.base.SteppingEngine` that leaves the run to the base class, whose
``run.py`` holds a :class:`~clearbench.adapters.stepping.StepRunner` and no loop of its own that
takes steps (the loop is :func:`clearbench.adapters.stepping.step_loop`), with the files and the
settings base of the template (docs/engines/adding.md). The engines that keep a driver of their
own are exactly the two the template names (the reference's compiled loop, Siconos's worker
process).
"""

from __future__ import annotations

import ast
import importlib.util
from pathlib import Path

import pytest

from clearbench.adapters import ENGINES

ROOT = Path(__file__).resolve().parents[1]
TOY = "tests.toy_engine"
#: The files of the template, the toy's exactly (docs/engines/adding.md's table).
TEMPLATE_FILES = {"__init__.py", "settings.py", "capabilities.py", "build.py", "run.py",
                  "engine.py"}
#: Engines with a driver of their own, as SteppingEngine's docstring and adding.md say.
OWN_DRIVERS = {"reference", "siconos"}
#: The calls that take an engine's step (or several): one inside a loop of a run.py is a time
#: loop of the engine's own. Each in-process engine's run.py must call one of them (so that a
#: renamed primitive fails here instead of passing unseen).
STEP_CALLS = {"mj_step", "mj_step1", "mj_step2", "stepSimulation", "AdvanceTo", "SolveSteps",
              "SolveDynamic", "step", "advance", "advance_python"}


def _package_dir(module: str) -> Path:
    spec = importlib.util.find_spec(module)
    assert spec is not None and spec.submodule_search_locations, module
    return Path(next(iter(spec.submodule_search_locations)))


def _tree(path: Path) -> ast.Module:
    return ast.parse(path.read_text(encoding="utf-8"), filename=str(path))


def _classes(tree: ast.Module) -> dict[str, ast.ClassDef]:
    return {node.name: node for node in tree.body if isinstance(node, ast.ClassDef)}


def _base_names(node: ast.ClassDef) -> set[str]:
    return {base.id if isinstance(base, ast.Name) else ast.unparse(base).split(".")[-1]
            for base in node.bases}


def _call_name(node: ast.Call) -> str:
    func = node.func
    return func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", "")


def _engine_class(package: Path) -> ast.ClassDef:
    engines = [c for c in _classes(_tree(package / "engine.py")).values()
               if _base_names(c) & {"SteppingEngine", "ModuleEngine", "Engine"}]
    assert len(engines) == 1, f"{package}/engine.py: {[c.name for c in engines]}"
    return engines[0]


def _in_process() -> dict[str, Path]:
    packages = {name: _package_dir(module) for name, module in ENGINES.items()
                if name not in OWN_DRIVERS}
    packages["toy"] = _package_dir(TOY)
    return packages


IN_PROCESS = sorted(_in_process())


def test_the_engines_with_their_own_driver_are_exactly_the_two_the_template_names():
    own = {name for name, module in ENGINES.items()
           if "SteppingEngine" not in _base_names(_engine_class(_package_dir(module)))}
    assert own == OWN_DRIVERS
    base = _tree(ROOT / "adapters" / "base.py")
    doc = " ".join(ast.get_docstring(_classes(base)["SteppingEngine"]).split())
    assert "the reference solver" in doc and "Siconos" in doc
    adding = (ROOT / "docs" / "engines" / "adding.md").read_text(encoding="utf-8")
    assert "Two engines keep a driver of their own" in adding


@pytest.mark.parametrize("name", IN_PROCESS)
def test_an_engine_is_a_stepping_engine_that_leaves_the_run_to_the_base(name):
    package = _in_process()[name]
    engine = _engine_class(package)
    assert "SteppingEngine" in _base_names(engine)
    methods = {node.name for node in engine.body if isinstance(node, ast.FunctionDef)}
    assert not methods & {"run", "_run"}, f"{name} overrides the run: {methods & {'run', '_run'}}"
    assert {"build", "runner", "metadata"} <= methods
    runners = [c for c in _classes(_tree(package / "run.py")).values()
               if "StepRunner" in _base_names(c)]
    assert len(runners) == 1, f"{name}/run.py: one StepRunner, found {len(runners)}"


def _assert_no_time_loop(name: str, path: Path) -> None:
    """``path`` has no while loop, calls a step primitive, and none inside a loop."""
    tree = _tree(path)
    assert not [n for n in ast.walk(tree) if isinstance(n, ast.While)], \
        f"{name}/run.py has a while loop"
    loops = [node for node in ast.walk(tree) if isinstance(node, ast.For | ast.AsyncFor)]
    in_loops = {id(call) for loop in loops for call in ast.walk(loop)
                if isinstance(call, ast.Call)}
    stepping = [call for call in ast.walk(tree)
                if isinstance(call, ast.Call) and _call_name(call) in STEP_CALLS]
    assert stepping, f"{name}/run.py calls none of {sorted(STEP_CALLS)}"
    looped = [f"{_call_name(c)} (line {c.lineno})" for c in stepping if id(c) in in_loops]
    assert not looped, f"{name}/run.py takes steps inside a loop: {looped}"


@pytest.mark.parametrize("name", IN_PROCESS)
def test_no_engine_run_module_holds_a_time_loop(name):
    _assert_no_time_loop(name, _in_process()[name] / "run.py")


def test_the_reference_run_module_leaves_both_its_loops_to_the_solver():
    """The reference's driver hands the run to one call of a loop in ref_solver/ (compiled, or
    its Python oracle); Siconos's loop runs in its worker process (adapters/siconos/worker),
    outside the run module by construction."""
    _assert_no_time_loop("reference", _package_dir(ENGINES["reference"]) / "run.py")


@pytest.mark.parametrize("name", IN_PROCESS)
def test_an_engine_has_the_template_files_and_settings_base(name):
    package = _in_process()[name]
    files = {path.name for path in package.glob("*.py")}
    if name == "toy":  # the template itself: nothing more
        assert files == TEMPLATE_FILES
    else:
        assert TEMPLATE_FILES <= files, f"{name} lacks {sorted(TEMPLATE_FILES - files)}"
    settings = [c for c in _classes(_tree(package / "settings.py")).values()
                if "EngineSettings" in _base_names(c)]
    assert len(settings) == 1, f"{name}/settings.py: one EngineSettings subclass"


def test_the_template_page_names_the_toy_file_for_file():
    adding = (ROOT / "docs" / "engines" / "adding.md").read_text(encoding="utf-8")
    assert "tests/toy_engine/" in adding
    rows = {line.split("|")[1].strip().strip("`") for line in adding.splitlines()
            if line.startswith("| `")}
    assert TEMPLATE_FILES <= rows, sorted(TEMPLATE_FILES - rows)
