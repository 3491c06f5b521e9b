"""Engine adapters: each turns a Scene into a Trajectory.

One subpackage per engine, with the same module names (``engine.py``; ``build.py``,
``capabilities.py``, ``settings.py`` ... where the engine has them) and the same entry points
in its ``__init__``: ``availability() -> (bool, str)`` and ``create(preset) -> Engine`` (the
contract: :mod:`clearbench.adapters.base`). :data:`ENGINES` lists them; nothing here imports an
engine subpackage (or an engine's Python package) until it is asked about.

Adding an engine: a subpackage with those two functions and an
:class:`~clearbench.adapters.base.Engine` subclass, and its line in :data:`ENGINES`; the
engine-contract test then runs it over every library scene.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass

#: Engine name -> its subpackage.
ENGINES: dict[str, str] = {
    "reference": "clearbench.adapters.reference",
    "mujoco": "clearbench.adapters.mujoco",
    "siconos": "clearbench.adapters.siconos",
    "pybullet": "clearbench.adapters.pybullet",
    "exudyn": "clearbench.adapters.exudyn",
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
