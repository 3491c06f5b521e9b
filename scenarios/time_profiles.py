"""Validation of the piecewise-linear profiles of drivers (their breakpoints).

The profiles' value, slope and integral are pure math: :mod:`clearbench.kernels.time_profiles`.
"""

from __future__ import annotations

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
