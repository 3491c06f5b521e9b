"""The pieces every expectation kind's criterion is written with: what a criterion judges
(:class:`Case`), the rule and its words (:class:`Criterion`), and the wording of a figure
against its bound (:func:`percent`, :func:`bounded`, :func:`all_of`), so that every verdict
reads the same way: ``"displacement 0.000639 m > 1e-05 m"``, ``"apex error 6.2 % > 5 %"``.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

from clearbench.scenarios.scales import body_size
from clearbench.scenarios.scene import Scene

#: Criterion of the stick expectations, and of the stick after a ``sliding_stop``: the body
#: moves by at most this fraction of its size.
STICK_FRACTION = 1e-4

#: (passed or None, detail, criterion) of one judged expectation: ``passed`` is None when the
#: figures allow no verdict (no samples, event not reached).
Judged = tuple


@dataclass(frozen=True)
class Case:
    """What a criterion judges: the scene, the expectation's body, its figures and the
    scene's :class:`~clearbench.scenarios.expectations.Expectation` (None when implied)."""

    scene: Scene
    body: str | None
    figures: dict
    expectation: object = None

    def get(self, name: str, default=None):
        return self.figures.get(name, default)

    @property
    def length(self) -> str:
        return self.scene.units.length

    def stick_bound(self) -> float:
        """:data:`STICK_FRACTION` of the body's size [L]."""
        return STICK_FRACTION * body_size(self.scene.body(self.body))


@dataclass(frozen=True)
class Criterion:
    """The pass/fail rule of one expectation kind: what passes, in words (the table of the
    docs and the report), and ``judge(case) -> (passed or None, detail, criterion)``."""

    passes_when: str
    judge: Callable[[Case], Judged]


def number(value: float) -> str:
    """Three significant digits."""
    return f"{value:.3g}"


def within(value, bound) -> bool | None:
    """|value| <= bound; None when ``value`` is missing or not finite."""
    if value is None or not math.isfinite(value):
        return None
    return abs(value) <= bound


def percent(name: str, value, bound: float) -> tuple[bool | None, str]:
    """Relative figure ``value`` against ``bound``, both as fractions, worded in percent."""
    passed = within(value, bound)
    if passed is None:
        return None, f"{name} not measured"
    sign = "<=" if passed else ">"
    return passed, f"{name} {number(100 * abs(value))} % {sign} {number(100 * bound)} %"


def bounded(name: str, value, bound: float, unit: str) -> tuple[bool | None, str]:
    """Figure ``value`` [unit] against ``bound`` [unit]."""
    passed = within(value, bound)
    if passed is None:
        return None, f"{name} not measured"
    unit = f" {unit}" if unit else ""
    sign = "<=" if passed else ">"
    return passed, f"{name} {number(abs(value))}{unit} {sign} {number(bound)}{unit}"


def all_of(parts: list[tuple[bool | None, str]]) -> tuple[bool | None, str]:
    """Every part must pass; a part not measured leaves the verdict to the others."""
    verdicts = [p for p, _ in parts if p is not None]
    passed = (all(verdicts) if verdicts else None)
    return passed, "; ".join(text for _, text in parts)


def unit_text(scene: Scene, dimension: tuple[int, int, int]) -> str:
    """The scene's unit of a (length, mass, time) dimension, e.g. ``mm``, ``m/s``, ``N``,
    ``kg m^2/s^2``; empty for a dimensionless value."""
    if tuple(dimension) == (0, 0, 0):
        return ""
    if tuple(dimension) == (1, 1, -2):
        return scene.units.force_unit()
    names = (scene.units.length, scene.units.mass, scene.units.time)
    up = [name if p == 1 else f"{name}^{p}" for name, p in zip(names, dimension, strict=True)
          if p > 0]
    down = [name if p == -1 else f"{name}^{-p}" for name, p in
            zip(names, dimension, strict=True) if p < 0]
    return " ".join(up or ["1"]) + ("/" + " ".join(down) if down else "")
