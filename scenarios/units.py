"""Consistent unit systems and the rescaling of dimensioned values.

A scene declares one unit system for length, mass and time; every other quantity is derived
(force = mass * length / time^2, ...). The C-60 uses mm, g, ms, in which a force is exactly 1 N.
Each numeric field of the scene description declares its dimension as exponents
(length, mass, time) in its dataclass metadata (see :mod:`.validation`).
"""

from __future__ import annotations

from dataclasses import dataclass

from clearbench.scenarios.validation import SceneError

#: Size of each accepted unit in SI base units.
LENGTH_UNITS = {"m": 1.0, "cm": 1e-2, "mm": 1e-3, "um": 1e-6}
MASS_UNITS = {"kg": 1.0, "g": 1e-3, "mg": 1e-6}
TIME_UNITS = {"s": 1.0, "ms": 1e-3, "us": 1e-6}


@dataclass(frozen=True)
class UnitSystem:
    """A consistent unit system: one unit of length, mass and time.

    Parameters
    ----------
    length, mass, time : str
        Unit names, keys of ``LENGTH_UNITS``, ``MASS_UNITS``, ``TIME_UNITS``.
    """

    length: str = "m"
    mass: str = "kg"
    time: str = "s"

    def __post_init__(self) -> None:
        for field, table in (
            ("length", LENGTH_UNITS),
            ("mass", MASS_UNITS),
            ("time", TIME_UNITS),
        ):
            value = getattr(self, field)
            if value not in table:
                raise SceneError(f"units.{field}", value, f"must be one of {sorted(table)}")

    @property
    def si_factors(self) -> tuple[float, float, float]:
        """Size of this system's length, mass and time units in metres, kilograms, seconds."""
        return LENGTH_UNITS[self.length], MASS_UNITS[self.mass], TIME_UNITS[self.time]

    def factor_to(self, other: UnitSystem, dimension: tuple[int, int, int]) -> float:
        """Multiplier converting a value of ``dimension`` from this system to ``other``."""
        factor = 1.0
        for mine, theirs, exponent in zip(
            self.si_factors, other.si_factors, dimension, strict=True
        ):
            factor *= (mine / theirs) ** exponent
        return factor

    def force_unit(self) -> str:
        """Readable name of the derived force unit (``N`` when it is exactly one newton)."""
        length, mass, time = self.si_factors
        newtons = mass * length / time**2
        if abs(newtons - 1.0) < 1e-12:
            return "N"
        return f"{self.mass}*{self.length}/{self.time}^2"

    def describe(self) -> str:
        """Short description, e.g. ``mm-g-ms (force N)``."""
        return f"{self.length}-{self.mass}-{self.time} (force {self.force_unit()})"


SI = UnitSystem()
MM_G_MS = UnitSystem("mm", "g", "ms")
