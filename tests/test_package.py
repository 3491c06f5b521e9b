"""The package installs under one namespace and exposes its console entry point."""

import importlib
import tomllib
from pathlib import Path


def test_subpackages_import_under_the_clearbench_namespace():
    for name in ("ref_solver", "scenarios", "adapters", "harness"):
        module = importlib.import_module(f"clearbench.{name}")
        assert module.__name__ == f"clearbench.{name}"


def test_every_subpackage_is_listed_for_the_wheel():
    """pyproject lists packages one by one: a new subpackage left out would be missing from an
    installed (not editable) clearbench."""
    root = Path(__file__).resolve().parents[1]
    config = tomllib.loads((root / "pyproject.toml").read_text())["tool"]["setuptools"]
    listed = set(config["packages"])
    for package, folder in config["package-dir"].items():
        for init in (root / folder).rglob("__init__.py"):
            relative = init.parent.relative_to(root / folder).parts
            assert ".".join((package, *relative)) in listed, init.parent
