"""Piecewise-linear time profiles (the floor's kernels) and the drivers built on them."""

from __future__ import annotations

import numpy as np
import pytest

from clearbench.kernels.time_profiles import (
    evaluate_profile,
    evaluate_profile_integral,
    evaluate_profile_slope,
)
from clearbench.scenarios.drivers import Driver
from clearbench.scenarios.validation import SceneError

# The C-60 plunger: 0 before 0.7 ms, 0.2 mm/ms afterwards.
STEP_TIMES = (0.0, 0.7, 0.7)
STEP_VALUES = (0.0, 0.0, 0.2)


def test_step_profile_jumps_at_the_switch_time():
    t = np.array([0.0, 0.5, 0.6999, 0.7, 1.0, 20.0])
    assert np.array_equal(evaluate_profile(STEP_TIMES, STEP_VALUES, t),
                          [0.0, 0.0, 0.0, 0.2, 0.2, 0.2])


def test_ramp_is_interpolated_and_constant_outside():
    times, values = (1.0, 3.0), (2.0, 6.0)
    assert evaluate_profile(times, values, 0.0) == 2.0
    assert evaluate_profile(times, values, 2.0) == 4.0
    assert evaluate_profile(times, values, 5.0) == 6.0


def test_integral_of_the_step_is_exact():
    # 0.2 mm/ms for 1.3 ms = 0.26 mm; the integral is piecewise exact up to round-off.
    assert evaluate_profile_integral(STEP_TIMES, STEP_VALUES, 2.0) == pytest.approx(0.26, rel=1e-12)


def test_velocity_driver_displacement_and_rate():
    driver = Driver("push", body="plunger", component="x", quantity="velocity",
                    times=STEP_TIMES, values=STEP_VALUES)
    assert driver.velocity(1.0) == 0.2
    assert driver.displacement(2.0) == pytest.approx(0.26, rel=1e-12)


def test_position_driver_rate_is_the_slope():
    driver = Driver("turn", body="crank", component="rz", quantity="position",
                    times=(0.0, 2.0), values=(0.0, 1.0))
    assert driver.velocity(1.0) == 0.5
    assert driver.displacement(1.0) == 0.5


def test_decreasing_times_are_refused():
    with pytest.raises(SceneError, match="times"):
        Driver("bad", body="b", times=(1.0, 0.5), values=(0.0, 1.0))
    with pytest.raises(SceneError, match="values"):
        Driver("bad", body="b", times=(0.0, 1.0), values=(0.0,))


def _antiderivative(times, values, t):
    """Closed-form integral from 0 to t (T,) of the profile, an independent oracle: the area
    of whole segments plus the part of the current one."""
    knots = np.asarray(times, dtype=float)
    levels = np.asarray(values, dtype=float)

    def from_first_knot(x):
        if len(knots) == 1:
            return levels[0] * (x - knots[0])
        widths = np.diff(knots)
        areas = np.concatenate(([0.0], np.cumsum(0.5 * (levels[:-1] + levels[1:]) * widths)))
        index = np.clip(np.searchsorted(knots, x, side="right") - 1, 0, len(knots) - 2)
        width = widths[index]
        slope = np.where(width > 0, (levels[index + 1] - levels[index])
                         / np.where(width > 0, width, 1.0), 0.0)
        offset = x - knots[index]
        inside = areas[index] + levels[index] * offset + 0.5 * slope * offset**2
        before = levels[0] * (x - knots[0])
        after = areas[-1] + levels[-1] * (x - knots[-1])
        return np.where(x < knots[0], before, np.where(x >= knots[-1], after, inside))

    return from_first_knot(np.asarray(t, dtype=float)) - from_first_knot(0.0)


@pytest.mark.parametrize("times, values", [
    ((0.0,), (2.0,)),
    ((0.0, 0.7, 0.7, 2.0), (0.0, 0.0, 0.2, 0.2)),      # switched on at 0.7 (the C-60 plunger)
    ((0.1, 0.5, 0.9, 0.9, 1.5), (1.0, -2.0, 3.0, 0.5, 0.0)),
])
def test_profile_integral_and_slope(times, values):
    t = np.linspace(0.0, 2.5, 251)
    # Both exact for piecewise-linear profiles: only round-off differs.
    integral = evaluate_profile_integral(times, values, t)
    assert np.allclose(integral, _antiderivative(times, values, t), rtol=1e-12, atol=1e-12)
    slope = evaluate_profile_slope(times, values, t)
    h = 1e-7
    numeric = (evaluate_profile(times, values, t + h) - evaluate_profile(times, values, t)) / h
    away_from_knots = np.min(np.abs(t[:, None] - np.asarray(times)[None, :]), axis=1) > 1e-3
    # Forward difference of a linear segment: exact up to round-off (1e-7 step, O(1) values).
    assert np.allclose(slope[away_from_knots], numeric[away_from_knots], atol=1e-6)


def test_front_ends_keep_the_shape_of_t():
    assert isinstance(evaluate_profile_integral(STEP_TIMES, STEP_VALUES, 1.0), float)
    grid = np.linspace(0.0, 2.0, 6).reshape(2, 3)
    assert evaluate_profile(STEP_TIMES, STEP_VALUES, grid).shape == (2, 3)
    assert evaluate_profile_integral(STEP_TIMES, STEP_VALUES, -1.0) == 0.0
