"""Engine adapters: each turns a Scene into a Trajectory.

One subpackage per engine, with the same module names (``engine.py``; ``build.py``,
``capabilities.py``, ``settings.py`` ... where the engine has them) and the same entry points
in its ``__init__``: ``availability() -> (bool, str)`` and ``create(preset) -> Engine`` (the
contract: :mod:`clearbench.adapters.base`). :data:`ENGINES` lists them; nothing here imports an
engine subpackage until it is asked about, and asking about availability imports neither the
adapter's modules nor the engine's Python package (:func:`installed_package`,
:func:`lazy_engine`): ``clearbench list`` stays quick.

Each ``__init__`` also declares the engine's ``HARNESS_DEFAULTS``
(:mod:`clearbench.adapters.harness_defaults`: its quick regression runs, rigid or compliant,
numba, C-60 ladders, colour), from which the harness derives its suites, plans and styles.

Adding an engine: a subpackage with those two functions, its ``HARNESS_DEFAULTS`` and a
:class:`~clearbench.adapters.base.SteppingEngine` subclass (the one template,
docs/engines/adding.md), and its line in :data:`ENGINES`; the engine-contract test then runs
it over every library scene.
"""

from __future__ import annotations

import importlib
import importlib.metadata
import importlib.util
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

#: Engine name -> its subpackage.
ENGINES: dict[str, str] = {
    "reference": "clearbench.adapters.reference",
    "mujoco": "clearbench.adapters.mujoco",
    "siconos": "clearbench.adapters.siconos",
    "pybullet": "clearbench.adapters.pybullet",
    "exudyn": "clearbench.adapters.exudyn",
    "drake": "clearbench.adapters.drake",
}


@dataclass(frozen=True)
class Availability:
    """Whether an engine can run here, and why not when it cannot."""

    engine: str
    available: bool
    detail: str


def engine_availability(engine: str) -> Availability:
    """Availability of ``engine`` as its subpackage reports it (never raises for a name of
    :data:`ENGINES`; KeyError for another name)."""
    if engine not in ENGINES:
        raise KeyError(f"unknown engine {engine!r}; engines: {', '.join(ENGINES)}")
    try:
        module = importlib.import_module(ENGINES[engine])
        available, detail = module.availability()
    except Exception as error:  # an adapter that cannot even report is unavailable
        return Availability(engine, False, f"adapter failed to load: {error}")
    return Availability(engine, bool(available), detail)


def all_availability() -> list[Availability]:
    """Availability of every engine of :data:`ENGINES`, in their order."""
    return [engine_availability(name) for name in ENGINES]


def installed_package(import_name: str, distribution: str | None = None) -> tuple[bool, str]:
    """(True, ``"NAME VERSION"``) when the package ``import_name`` is installed, else (False,
    why); found without importing it (an engine's package takes up to a second to import).

    Parameters
    ----------
    import_name : str
        The name ``import`` takes (``mujoco``).
    distribution : str, optional
        The distribution that installs it, for its version (default: ``import_name``).
    """
    if importlib.util.find_spec(import_name) is None:
        return False, f"{import_name} is not installed"
    try:
        return True, f"{import_name} {importlib.metadata.version(distribution or import_name)}"
    except importlib.metadata.PackageNotFoundError:  # a source build without metadata
        return True, f"{import_name} (version unknown)"


def lazy_engine(package: str, *names: str) -> tuple[Callable[..., Any], Callable[[str], Any]]:
    """``create`` and a module ``__getattr__`` for the engine subpackage ``package`` whose
    ``engine`` module defines ``create(preset)`` and ``names``: the adapter's modules are
    imported when an engine is created or one of ``names`` is read, not when the subpackage is
    imported for its availability.

    Returns
    -------
    create : callable
        ``package.engine.create``, imported on the first call.
    getattr : callable
        The subpackage's ``__getattr__`` (PEP 562) serving ``names`` from ``package.engine``.
    """
    def engine_module():
        return importlib.import_module(f"{package}.engine")

    def create(preset: str = "default"):
        return engine_module().create(preset)

    def module_getattr(name: str):
        if name in names:
            return getattr(engine_module(), name)
        raise AttributeError(f"module {package!r} has no attribute {name!r}")

    create.__doc__ = f"``{package}.engine.create(preset)``: an engine with that preset."
    return create, module_getattr
