"""Piecewise-linear functions of time, used by drivers and time-switched loads."""

from __future__ import annotations

import numpy as np

from clearbench.scenarios.validation import SceneError, check_finite


def check_profile(times_field: str, times, values_field: str, values) -> tuple[tuple, tuple]:
    """Validate breakpoints of a piecewise-linear profile.

    ``times`` must be non-decreasing (two equal consecutive times make a jump) and finite,
    ``values`` finite and of the same length (at least 1).
    """
    times = tuple(check_finite(f"{times_field}[{i}]", t) for i, t in enumerate(times))
    values = tuple(check_finite(f"{values_field}[{i}]", v) for i, v in enumerate(values))
    if not times:
        raise SceneError(times_field, times, "needs at least one breakpoint")
    if len(times) != len(values):
        raise SceneError(
            values_field, values, f"must have as many entries as {times_field} ({len(times)})"
        )
    for i in range(1, len(times)):
        if times[i] < times[i - 1]:
            raise SceneError(times_field, times, "must be non-decreasing")
        if i >= 2 and times[i] == times[i - 1] == times[i - 2]:
            raise SceneError(times_field, times, "at most two equal consecutive times (a jump)")
    return times, values


def evaluate_profile(times, values, t):
    """Value of the piecewise-linear profile at time(s) ``t``.

    Constant before the first and after the last breakpoint; at a jump (two equal times) the
    value right of the jump is taken at the jump time.

    Parameters
    ----------
    times, values : sequence of float, shape (n,)
    t : float or ndarray

    Returns
    -------
    float or ndarray, same shape as ``t``
    """
    times = np.asarray(times, dtype=float)
    values = np.asarray(values, dtype=float)
    t_arr = np.asarray(t, dtype=float)
    # searchsorted 'right' picks the segment after a jump at the jump time itself.
    index = np.clip(np.searchsorted(times, t_arr, side="right"), 1, max(len(times) - 1, 1))
    if len(times) == 1:
        result = np.full_like(t_arr, values[0])
    else:
        t0, t1 = times[index - 1], times[index]
        v0, v1 = values[index - 1], values[index]
        span = np.where(t1 > t0, t1 - t0, 1.0)
        fraction = np.clip((t_arr - t0) / span, 0.0, 1.0)
        result = np.where(t1 > t0, v0 + fraction * (v1 - v0), v1)
        result = np.where(t_arr < times[0], values[0], result)
        result = np.where(t_arr >= times[-1], values[-1], result)
    return float(result) if np.ndim(t) == 0 else result


def integrate_profile(times, values, t0: float, t1: float) -> float:
    """Exact integral of the piecewise-linear profile over [t0, t1]."""
    knots = np.asarray(times, dtype=float)
    inner = knots[(knots > t0) & (knots < t1)]
    grid = np.unique(np.concatenate(([t0], inner, [t1])))
    total = 0.0
    for a, b in zip(grid[:-1], grid[1:], strict=True):
        # Evaluate just inside the interval so that jumps at its ends do not leak in.
        eps = 1e-12 * max(1.0, abs(b - a))
        fa = evaluate_profile(times, values, min(a + eps, b))
        fb = evaluate_profile(times, values, max(b - eps, a))
        total += 0.5 * (fa + fb) * (b - a)
    return total
