"""Units of the harness's figures: a dimension in the scene's units, or a ratio saying what it
is of (:class:`FigureUnit`), shared by the run figures (:mod:`.units`) and the expectation
kinds' figures (:mod:`.kinds`)."""

from __future__ import annotations

from dataclasses import dataclass

from clearbench.scenarios.units import UnitSystem
from clearbench.scenarios.validation import ACCELERATION, FORCE, LENGTH, TIME, VELOCITY

#: Exponents (length, mass, time) of an energy (a force times a length).
ENERGY = (2, 1, -2)


@dataclass(frozen=True)
class FigureUnit:
    """A dimension (exponents of length, mass, time), or a ratio with what it is of (``of``),
    or a plain count / angle / number (``word``: ``rad``, ``count``, ``-``)."""

    dimension: tuple | None = None
    of: str = ""
    word: str = ""

    def text(self, units: UnitSystem) -> str:
        """The unit as printed beside a value, in ``units`` (``mm``, ``of energy_scale``)."""
        if self.dimension is not None:
            return dimension_text(self.dimension, units)
        if self.of:
            return f"of {self.of}"
        return self.word

    def short(self, units: UnitSystem) -> str:
        """The unit in a table header: ``mm``, ``rel.``, ``rad`` (empty for counts)."""
        if self.dimension is not None:
            return dimension_text(self.dimension, units)
        if self.of:
            return "rel."
        return "" if self.word in COUNT_WORDS else self.word


#: Words of plain counts (no unit in a table header).
COUNT_WORDS = ("count", "steps", "iterations")


def of(what: str) -> FigureUnit:
    """A ratio to ``what`` (``of the radial clearance``)."""
    return FigureUnit(of=what)


L, T, V, A, E = (FigureUnit(LENGTH), FigureUnit(TIME), FigureUnit(VELOCITY),
                 FigureUnit(ACCELERATION), FigureUnit(ENERGY))
RAD, COUNT, PURE = FigureUnit(word="rad"), FigureUnit(word="count"), FigureUnit(word="-")

def dimension_text(dimension: tuple, units: UnitSystem) -> str:
    """``(1, 0, -1)`` in mm-g-ms -> ``mm/ms``; a force in a system whose force is the newton
    -> ``N``, an energy -> ``N*mm`` (``J`` in SI)."""
    force = units.force_unit()
    if tuple(dimension) == FORCE and force == "N":
        return "N"
    if tuple(dimension) == ENERGY and force == "N":
        return "J" if units.length == "m" else f"N*{units.length}"
    parts = {"up": [], "down": []}
    length, mass, time = dimension
    for name, exponent in ((units.mass, mass), (units.length, length), (units.time, time)):
        if exponent:
            power = f"^{abs(exponent)}" if abs(exponent) != 1 else ""
            parts["up" if exponent > 0 else "down"].append(f"{name}{power}")
    text = "*".join(parts["up"]) or "1"
    return text + ("/" + "/".join(parts["down"]) if parts["down"] else "")
