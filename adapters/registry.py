"""Which engines exist and whether each can run on this machine.

An engine is available when its adapter module exists and its own ``availability()`` says so
(its Python package imports, or for Siconos, Debian's interpreter can import it). Nothing here
imports an engine package at module import time.
"""

from __future__ import annotations

import importlib
import importlib.util
from dataclasses import dataclass

#: Engine name -> adapter module (relative to clearbench.adapters).
ENGINE_MODULES: dict[str, str] = {
    "reference": "reference",
    "mujoco": "mujoco",
    "pybullet": "pybullet",
    "exudyn": "exudyn",
    "siconos": "siconos",
}


@dataclass(frozen=True)
class Availability:
    """Whether an engine can run here, and why not when it cannot."""

    engine: str
    available: bool
    detail: str


def engine_availability(engine: str) -> Availability:
    """Availability of ``engine`` (never raises for a known engine name)."""
    if engine not in ENGINE_MODULES:
        raise KeyError(f"unknown engine {engine!r}; engines: {', '.join(ENGINE_MODULES)}")
    module_name = f"clearbench.adapters.{ENGINE_MODULES[engine]}"
    if importlib.util.find_spec(module_name) is None:
        return Availability(engine, False, "adapter not implemented yet")
    try:
        module = importlib.import_module(module_name)
        available, detail = module.availability()
    except Exception as error:  # an adapter that cannot even report is unavailable
        return Availability(engine, False, f"adapter failed to load: {error}")
    return Availability(engine, bool(available), detail)


def all_availability() -> list[Availability]:
    """Availability of every known engine, in a stable order."""
    return [engine_availability(name) for name in ENGINE_MODULES]
