"""The layering of the project's imports, read from the sources (nothing is imported).

Dependencies point one way: harness -> adapters -> (ref_solver, scenarios) -> the pure-math
floor ``clearbench.kernels``. Checked here: the floor imports nothing else of the project;
``ref_solver`` imports only the floor and the scene types (not the scene library, the analytic
references or the C-60 model); ``scenarios`` imports neither ``ref_solver``, the adapters nor
the harness; the adapters do not import the harness; no adapter subpackage imports another; the
Siconos worker imports nothing of the project but the floor; no import cycle among the
project's modules. Every import counts, at module level or inside a function (``if
TYPE_CHECKING:`` blocks too); imports made by name at run time (``importlib``) do not.
"""

from __future__ import annotations

import ast
import importlib.util
from functools import cache
from pathlib import Path

#: The project's subpackages (each a folder at the top of the repository).
SUBPACKAGES = ("clearbench.kernels", "clearbench.ref_solver", "clearbench.scenarios",
               "clearbench.adapters", "clearbench.harness")
#: Subpackages of scenarios that hold scene content, not scene types.
SCENE_CONTENT = ("clearbench.scenarios.library", "clearbench.scenarios.analytic",
                 "clearbench.scenarios.c60")
#: Shared modules of the adapters package; every other child of it is one engine's subpackage.
def _engine_subpackages() -> frozenset[str]:
    """The engines' subpackages of ``clearbench.adapters`` (its folders; its plain modules, base,
    stepping, trajectory and the like, are the shared layer every engine may import)."""
    folder = Path(importlib.util.find_spec("clearbench.adapters").origin).parent
    return frozenset(path.name for path in folder.iterdir()
                     if (path / "__init__.py").exists())


ENGINE_SUBPACKAGES = _engine_subpackages()


def _module_files() -> dict[str, Path]:
    """Module name -> source file of the top package and every module of the subpackages."""
    files = {"clearbench": Path(importlib.util.find_spec("clearbench").origin)}
    for package in SUBPACKAGES:
        for location in importlib.util.find_spec(package).submodule_search_locations:
            root = Path(location)
            for path in sorted(root.rglob("*.py")):
                parts = path.relative_to(root).with_suffix("").parts
                if parts[-1] == "__init__":
                    parts = parts[:-1]
                files[".".join((package, *parts))] = path
    return files


def _resolve(name: str, modules) -> str | None:
    """The project module that ``name`` (a module, or a name inside one) belongs to."""
    while name and name not in modules:
        name = name.rpartition(".")[0]
    return name or None


def _imports(module: str, path: Path, modules) -> list[tuple[str, int, bool]]:
    """(imported project module, line, inside a function) of every import in ``path``."""
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    found = []

    def visit(node, in_function: bool) -> None:
        for child in ast.iter_child_nodes(node):
            nested = in_function or isinstance(child, ast.FunctionDef | ast.AsyncFunctionDef
                                               | ast.Lambda)
            if isinstance(child, ast.Import):
                names = [alias.name for alias in child.names]
            elif isinstance(child, ast.ImportFrom):
                if child.level:
                    base = package.split(".")[: len(package.split(".")) - child.level + 1]
                    source = ".".join(base + ([child.module] if child.module else []))
                else:
                    source = child.module or ""
                # ``from package import module`` imports the module, else a name of the package.
                names = [f"{source}.{alias.name}" for alias in child.names]
            else:
                names = []
            for name in names:
                target = _resolve(name, modules)
                if target is not None and target != module:
                    found.append((target, child.lineno, nested))
            visit(child, nested)

    visit(ast.parse(path.read_text(), str(path)), False)
    return found


@cache
def import_graph() -> dict[str, list[tuple[str, int, bool]]]:
    """Module -> its imports of project modules (see :func:`_imports`)."""
    files = _module_files()
    return {module: _imports(module, path, files) for module, path in files.items()}


def _within(module: str, package: str) -> bool:
    return module == package or module.startswith(package + ".")


def _violations(source: str, allowed) -> list[str]:
    """Imports by modules of ``source`` of project modules that ``allowed(target)`` refuses."""
    return [f"{module}:{line} imports {target}"
            for module, imports in import_graph().items() if _within(module, source)
            for target, line, _ in imports if not allowed(target)]


def strongly_connected_components(edges: dict[str, set[str]]) -> list[list[str]]:
    """Tarjan's algorithm, iterative: the components of the directed graph ``edges``."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    components = []
    for root in edges:
        if root in index:
            continue
        work = [(root, iter(sorted(edges.get(root, ()))))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is not None:
                if child not in index:
                    index[child] = low[child] = len(index)
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(edges.get(child, ())))))
                elif child in on_stack:
                    low[node] = min(low[node], index[child])
                continue
            work.pop()
            if work:
                parent = work[-1][0]
                low[parent] = min(low[parent], low[node])
            if low[node] == index[node]:
                component = []
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.append(member)
                    if member == node:
                        break
                components.append(sorted(component))
    return components


def test_the_graph_sees_module_and_function_level_imports():
    graph = import_graph()
    assert {"clearbench.kernels.quaternion", "clearbench.harness.cli.main",
            "clearbench.adapters.siconos.worker.engine"} <= set(graph)
    runner = {target for target, _, _ in graph["clearbench.harness.run.runner"]}
    assert "clearbench.harness.run.worker" in runner
    # ``from clearbench.harness.measure import series`` is an import of the series module.
    figures = {target for target, _, _ in graph["clearbench.harness.measure.figures"]}
    assert "clearbench.harness.measure.series" in figures
    assert any(in_function for imports in graph.values() for _, _, in_function in imports)


def test_strongly_connected_components_finds_a_cycle():
    edges = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}
    assert sorted(strongly_connected_components(edges)) == [["a", "b", "c"], ["d"]]


def test_the_floor_imports_nothing_else_of_the_project():
    assert _violations("clearbench.kernels",
                       lambda target: _within(target, "clearbench.kernels")) == []


def test_ref_solver_imports_only_the_floor_and_the_scene_types():
    def allowed(target: str) -> bool:
        if any(_within(target, content) for content in SCENE_CONTENT):
            return False
        return any(_within(target, package) for package in (
            "clearbench.ref_solver", "clearbench.kernels", "clearbench.scenarios"))

    assert _violations("clearbench.ref_solver", allowed) == []


def test_scenarios_import_no_solver_engine_or_harness():
    def allowed(target: str) -> bool:
        return not any(_within(target, package) for package in (
            "clearbench.ref_solver", "clearbench.adapters", "clearbench.harness"))

    assert _violations("clearbench.scenarios", allowed) == []


def test_adapters_import_no_harness():
    assert _violations("clearbench.adapters",
                       lambda target: not _within(target, "clearbench.harness")) == []


def _engine_subpackage(module: str) -> str | None:
    parts = module.split(".")
    if len(parts) > 2 and parts[1] == "adapters" and parts[2] in ENGINE_SUBPACKAGES:
        return parts[2]
    return None


def test_no_adapter_imports_another_adapter():
    crossings = [f"{module}:{line} imports {target}"
                 for module, imports in import_graph().items()
                 if _engine_subpackage(module) is not None
                 for target, line, _ in imports
                 if _engine_subpackage(target) not in (None, _engine_subpackage(module))]
    assert crossings == []


def test_no_import_cycles_among_the_project_modules():
    def parents(module: str) -> set[str]:
        parts = module.split(".")
        return {".".join(parts[:i]) for i in range(1, len(parts))}

    # Importing a module runs its parent packages first: an import of a parent package is not
    # an edge of the module's own (a package's __init__ importing its modules is not a cycle).
    edges = {module: {target for target, _, _ in imports if target not in parents(module)}
             for module, imports in import_graph().items()}
    cycles = [c for c in strongly_connected_components(edges) if len(c) > 1]
    assert cycles == []


def test_the_siconos_worker_imports_nothing_of_the_project_but_the_floor():
    # It runs under Debian's /usr/bin/python3, where clearbench is not installed: it imports the
    # kernels folder by path (worker/project_kernels.py), and nothing else of the project.
    worker = "clearbench.adapters.siconos.worker"
    offending = [f"{module}:{line} imports {target}"
                 for module, imports in import_graph().items() if _within(module, worker)
                 for target, line, _ in imports if not _within(target, "clearbench.kernels")]
    assert offending == []
    geometry = {target for target, _, _ in import_graph()[f"{worker}.geometry"]}
    assert "clearbench.kernels.gaps" in geometry
