"""Piecewise-linear functions of time: the one implementation of their value, slope and
integral (drivers, time-switched loads).

A profile is given by its breakpoints ``times`` (n,) [T], non-decreasing, and ``values`` (n,)
(any unit), n >= 1 (validated by :func:`clearbench.scenarios.time_profiles.check_profile`).

Conventions
-----------
- Linear between consecutive breakpoints, constant before the first and after the last.
- Two equal consecutive times make a jump; at the jump time the value right of the jump is
  taken (the value is right-continuous).
- The slope is the right derivative: the slope of the segment that starts at or before ``t``
  and ends after it; 0 outside the breakpoints and at a jump.
- The integral runs from 0 to ``t`` (the scene's start), exact for piecewise-linear profiles
  up to round-off (trapezoids between the breakpoints, each end evaluated just inside its
  interval so that a jump at an end does not leak in); 0 for ``t <= 0``.

Two families, as in :mod:`clearbench.kernels.quaternion`:

- ``profile_*``: scalar kernels on float64 arrays ``times``, ``values`` and a float ``t``,
  compiled with ``numba.njit(cache=True)`` so that the reference solver's compiled step calls
  them;
- ``evaluate_profile*``: numpy front ends taking any sequences and ``t`` a float or an array of
  any shape (returns a float or an array of that shape), looping over the same kernels.

The Siconos worker (``adapters/siconos/worker/engine.py``) keeps a plain-numpy copy of the
value and the slope on purpose (it runs under Debian's Python, without numba or clearbench);
a test holds it bitwise equal to these kernels.
"""

from __future__ import annotations

import numpy as np

from clearbench.kernels.jit import njit

__all__ = [
    "evaluate_profile",
    "evaluate_profile_integral",
    "evaluate_profile_slope",
    "profile_integral",
    "profile_slope",
    "profile_value",
]


@njit(cache=True)
def profile_value(times, values, t):
    """Value of the profile at ``t``: (n,), (n,), float -> float (right value at a jump)."""
    n = times.shape[0]
    if t < times[0]:
        return values[0]
    if t >= times[n - 1]:
        return values[n - 1]
    for i in range(n - 1):
        if times[i] <= t < times[i + 1]:
            return values[i] + (t - times[i]) / (times[i + 1] - times[i]) * (
                values[i + 1] - values[i])
    return values[n - 1]


@njit(cache=True)
def profile_slope(times, values, t):
    """Right derivative of the profile at ``t``: (n,), (n,), float -> float [value unit / T]
    (0 outside the breakpoints and at a jump)."""
    n = times.shape[0]
    for i in range(n - 1):
        if times[i] <= t < times[i + 1]:
            return (values[i + 1] - values[i]) / (times[i + 1] - times[i])
    return 0.0


@njit(cache=True)
def profile_integral(times, values, t):
    """Integral of the profile from 0 to ``t``: (n,), (n,), float -> float [value unit x T]."""
    total = 0.0
    n = times.shape[0]
    # Knots clipped to [0, t]; between consecutive knots the profile is linear.
    knots = np.empty(n + 2)
    knots[0] = 0.0
    count = 1
    for i in range(n):
        if 0.0 < times[i] < t:
            knots[count] = times[i]
            count += 1
    knots[count] = t
    count += 1
    for i in range(count - 1):
        a = knots[i]
        b = knots[i + 1]
        if b <= a:
            continue
        eps = 1e-12 * max(1.0, b - a)
        fa = profile_value(times, values, min(a + eps, b))
        fb = profile_value(times, values, max(b - eps, a))
        total += 0.5 * (fa + fb) * (b - a)
    return total


_VALUE, _SLOPE, _INTEGRAL = 0, 1, 2


@njit(cache=True)
def _evaluate_at(quantity, times, values, t, out):
    """``out[i]`` = value, slope or integral (``quantity`` 0, 1, 2) of the profile at
    ``t[i]``; t and out (m,)."""
    for i in range(t.shape[0]):
        if quantity == _VALUE:
            out[i] = profile_value(times, values, t[i])
        elif quantity == _SLOPE:
            out[i] = profile_slope(times, values, t[i])
        else:
            out[i] = profile_integral(times, values, t[i])


def _evaluate(quantity: int, times, values, t):
    times = np.ascontiguousarray(times, dtype=np.float64)
    values = np.ascontiguousarray(values, dtype=np.float64)
    t_array = np.asarray(t, dtype=np.float64)
    out = np.empty(t_array.size)
    _evaluate_at(quantity, times, values, np.ascontiguousarray(t_array.ravel()), out)
    return float(out[0]) if np.ndim(t) == 0 else out.reshape(t_array.shape)


def evaluate_profile(times, values, t):
    """Value of the profile at time(s) ``t`` (:func:`profile_value`).

    Parameters
    ----------
    times, values : sequence of float, shape (n,)
    t : float or ndarray [T]

    Returns
    -------
    float or ndarray, same shape as ``t``
    """
    return _evaluate(_VALUE, times, values, t)


def evaluate_profile_slope(times, values, t):
    """Right derivative of the profile at time(s) ``t`` (:func:`profile_slope`): float or
    ndarray of the shape of ``t`` [value unit / T]."""
    return _evaluate(_SLOPE, times, values, t)


def evaluate_profile_integral(times, values, t):
    """Integral of the profile from 0 to time(s) ``t`` (:func:`profile_integral`): float or
    ndarray of the shape of ``t`` [value unit x T]."""
    return _evaluate(_INTEGRAL, times, values, t)
