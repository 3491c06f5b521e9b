"""Argument checks shared by the analytic reference modules.

The analytic references (:mod:`clearbench.scenarios.analytic`) are pure functions of their
parameters. Misuse (a negative gravity, a restitution outside its range, a time before the
release) raises :class:`ValueError` whose message names the argument and its value.
"""

from __future__ import annotations

import math

import numpy as np


def require_positive(name: str, value: float) -> float:
    """Return ``value`` as a float if it is finite and > 0, else raise ValueError."""
    number = float(value)
    if not (math.isfinite(number) and number > 0.0):
        raise ValueError(f"{name} = {value!r}: must be finite and > 0")
    return number


def require_non_negative(name: str, value: float) -> float:
    """Return ``value`` as a float if it is finite and >= 0, else raise ValueError."""
    number = float(value)
    if not (math.isfinite(number) and number >= 0.0):
        raise ValueError(f"{name} = {value!r}: must be finite and >= 0")
    return number


def require_finite(name: str, value: float) -> float:
    """Return ``value`` as a float if it is finite, else raise ValueError."""
    number = float(value)
    if not math.isfinite(number):
        raise ValueError(f"{name} = {value!r}: must be finite")
    return number


def require_in_interval(
    name: str, value: float, low: float, high: float, *, closed_high: bool = False
) -> float:
    """Return ``value`` as a float if ``low <= value < high`` (``<= high`` if ``closed_high``)."""
    number = float(value)
    upper_ok = number <= high if closed_high else number < high
    if not (math.isfinite(number) and low <= number and upper_ok):
        bracket = "]" if closed_high else ")"
        raise ValueError(f"{name} = {value!r}: must lie in [{low}, {high}{bracket}")
    return number


def as_times(t, *, non_negative: bool = True) -> np.ndarray:
    """Return the time samples as a float array of the same shape, checking they are usable.

    Parameters
    ----------
    t : array_like, any shape
        Time samples [time].
    non_negative : bool
        Whether times before the release (t < 0) are rejected.
    """
    times = np.asarray(t, dtype=float)
    if not np.all(np.isfinite(times)):
        raise ValueError("t: every time sample must be finite")
    if non_negative and np.any(times < 0.0):
        raise ValueError(f"t: min = {times.min()!r}: the solution starts at t = 0")
    return times
