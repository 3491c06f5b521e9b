"""The package installs under one namespace and exposes its console entry point."""

import importlib
import importlib.util
import tomllib
from pathlib import Path


def test_subpackages_import_under_the_clearbench_namespace():
    for name in ("ref_solver", "scenarios", "adapters", "harness"):
        module = importlib.import_module(f"clearbench.{name}")
        assert module.__name__ == f"clearbench.{name}"


def test_the_package_list_is_derived_from_the_folders():
    """setup.py derives the wheel's package list from pyproject's package-dir mapping: every
    folder with an __init__.py under a mapped folder, named under its namespace, and nothing
    listed by hand (a new subpackage is never left out of an installed clearbench)."""
    root = Path(__file__).resolve().parents[1]
    config = tomllib.loads((root / "pyproject.toml").read_text())["tool"]["setuptools"]
    assert "packages" not in config
    spec = importlib.util.spec_from_file_location("clearbench_setup", root / "setup.py")
    setup = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(setup)   # defines packages(); setup() runs only as a script
    expected = set()
    for package, folder in config["package-dir"].items():
        for init in (root / folder).rglob("__init__.py"):
            relative = init.parent.relative_to(root / folder).parts
            expected.add(".".join((package, *relative)))
    derived = setup.packages(root)
    assert len(derived) == len(set(derived)) and set(derived) == expected
    assert {"clearbench.adapters.siconos.worker", "clearbench.ref_solver.compiled"} <= expected


def test_the_readme_lists_every_doc_page():
    """The README's documentation list links every page under docs/ (a page added without its
    line would be found by no reader of the README)."""
    root = Path(__file__).resolve().parents[1]
    readme = (root / "README.md").read_text(encoding="utf-8")
    missing = [page.relative_to(root).as_posix() for page in sorted((root / "docs").rglob("*.md"))
               if f"]({page.relative_to(root).as_posix()})" not in readme]
    assert missing == []
