"""Piecewise-linear time profiles of drivers and their integrals."""

from __future__ import annotations

import numpy as np
import pytest

from clearbench.scenarios.drivers import Driver
from clearbench.scenarios.time_profiles import evaluate_profile, integrate_profile
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
    assert integrate_profile(STEP_TIMES, STEP_VALUES, 0.0, 2.0) == pytest.approx(0.26, rel=1e-12)


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
