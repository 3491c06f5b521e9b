"""The package list, derived from the folders: pyproject.toml's ``[tool.setuptools]
package-dir`` maps each top-level folder to its name under the ``clearbench`` namespace, and
every folder below it that holds an ``__init__.py`` is installed under that name
(:func:`packages`). Everything else of the build is in pyproject.toml."""

import tomllib
from pathlib import Path

from setuptools import find_packages, setup

ROOT = Path(__file__).resolve().parent


def packages(root: Path = ROOT) -> list[str]:
    """Every package of the ``package-dir`` mapping of ``root``'s pyproject.toml: each mapped
    folder and its sub-packages, named under the mapped name."""
    config = tomllib.loads((root / "pyproject.toml").read_text(encoding="utf-8"))
    found = []
    for name, folder in config["tool"]["setuptools"]["package-dir"].items():
        found.append(name)
        found += [f"{name}.{sub}" for sub in find_packages(where=str(root / folder))]
    return found


if __name__ == "__main__":
    setup(packages=packages())
