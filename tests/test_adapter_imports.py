"""What the engines and the pure-math floor may import (read from their source, every import
statement, function-level ones included): no adapter imports another adapter, the floor imports
nothing of the project but itself, and the Siconos worker (Debian's Python) nothing of it."""

from __future__ import annotations

import ast
import importlib.util
from pathlib import Path

import pytest

from clearbench.adapters import ENGINES


def _folder(package: str) -> Path:
    return Path(importlib.util.find_spec(package).submodule_search_locations[0])


def _imports(path: Path, package: str) -> set[str]:
    """Absolute names of the modules ``path`` (a module of ``package``) imports."""
    names = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:  # relative: resolved against the module's package
                parts = package.split(".")
                base = ".".join(parts[:len(parts) - node.level + 1])
                names.add(f"{base}.{node.module}" if node.module else base)
            else:
                names.add(node.module)
    return names


def _modules(package: str):
    folder = _folder(package)
    for path in sorted(folder.rglob("*.py")):
        relative = path.parent.relative_to(folder).parts
        yield path, ".".join((package, *relative))


@pytest.mark.parametrize("engine", list(ENGINES))
def test_no_adapter_imports_another(engine):
    others = [ENGINES[name] for name in ENGINES if name != engine]
    for path, package in _modules(ENGINES[engine]):
        for name in _imports(path, package):
            assert not any(name == other or name.startswith(other + ".") for other in others), \
                f"{path.name} of {engine} imports {name}"


def test_the_floor_imports_nothing_else_of_the_project():
    for path, package in _modules("clearbench.kernels"):
        for name in _imports(path, package):
            assert not name.startswith("clearbench") or name.startswith("clearbench.kernels"), \
                f"{path.name} imports {name}"


def test_the_siconos_worker_imports_nothing_of_the_project():
    for path, package in _modules("clearbench.adapters.siconos.worker"):
        assert not any(name.startswith("clearbench") for name in _imports(path, package)), \
            path.name
