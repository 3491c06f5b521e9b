"""Impact localisation of the Moreau–Jean stepper: the crossing-fraction estimate, one split
step against the exact bounce, and the settings and options that switch it."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from clearbench.adapters.base import RunSettings
from clearbench.adapters.reference.engine import create
from clearbench.ref_solver.scene_system import build_system, initial_state
from clearbench.ref_solver.stepper import MoreauJeanStepper, StepperSettings, crossing_fraction
from clearbench.scenarios.library import get_scene


@pytest.mark.parametrize("gap, speed, acceleration", [
    (0.3, -1.0, -0.05),      # accelerating towards the plane
    (0.3, -1.0, 0.4),        # decelerating (a root still inside the step)
    (1e-9, -4.4, -9.81),     # crossing right after the start
    (4.4 - 1e-9, -4.4, 0.0),  # crossing right before the end, no acceleration (linear)
])
def test_crossing_fraction_is_exact_for_ballistic_flight(gap, speed, acceleration):
    # g(s) = g0 + v s + a s^2 / 2 over a unit step: the gap at the end of the free motion
    # fixes the quadratic, whose root the estimate must return to round-off (1e-12 of the step:
    # the cancellations of the quadratic formula cost a few ulps of the 1-sized terms).
    end = gap + speed + 0.5 * acceleration
    roots = np.roots([0.5 * acceleration, speed, gap]) if acceleration else [-gap / speed]
    expected = min(r.real for r in np.atleast_1d(roots) if 0.0 < r.real <= 1.0)
    assert crossing_fraction(gap, speed, end) == pytest.approx(expected, abs=1e-12)


def test_crossing_fraction_of_a_contact_closing_exactly_at_the_end_is_one():
    assert crossing_fraction(0.5, -0.5, 0.0) == pytest.approx(1.0, abs=1e-15)


def test_crossing_fraction_rejects_a_gap_that_does_not_close():
    with pytest.raises(ValueError):
        crossing_fraction(0.1, -1.0, 0.05)
    with pytest.raises(ValueError):
        crossing_fraction(-0.1, -1.0, -0.5)


def _ball_stepper(restitution: float, localise: bool, h: float = 1e-3):
    scene = get_scene(f"bouncing-ball-e{restitution:g}")
    settings = create().run_settings(
        scene, RunSettings(time_step=h, options={"localise_impacts": localise}))
    return MoreauJeanStepper(build_system(scene), settings), initial_state(scene), scene


def test_split_step_reproduces_the_exact_bounce():
    e, h, g, radius, mass = 0.5, 1e-3, 9.81, 0.1, 1.0
    stepper, state, scene = _ball_stepper(e, True, h)
    assert scene.bodies[1].mass == mass
    while True:
        result = stepper.step(state)
        if result.statistics.substeps > 1:
            break
        state = result.state
    # Exact: free fall from the start of the step to the crossing, Newton's law, free flight.
    z0, v0 = state.x[1, 2] - radius, state.v[1, 2]
    crossing = (v0 + math.sqrt(v0 * v0 + 2.0 * g * z0)) / g
    v_impact = v0 - g * crossing
    rest = h - crossing
    z_exact = -e * v_impact * rest - 0.5 * g * rest * rest
    v_exact = -e * v_impact - g * rest
    # The flight is stretched by a relative 1e-9 past the crossing, so that the contact is
    # closed for the impact: the impact comes 1e-9 h late, an error of about
    # (1 + e) |v| 1e-9 h = 7e-12 m and g 1e-9 h = 1e-11 m/s. Bounds: 10x that.
    assert result.state.x[1, 2] - radius == pytest.approx(z_exact, abs=1e-10)
    assert result.state.v[1, 2] == pytest.approx(v_exact, abs=1e-10)
    assert result.state.t == state.t + h  # the time of an unsplit step, to the last bit
    stats = result.statistics
    assert stats.substeps == 3  # flight, zero-length impact, rest of the step
    assert stats.solver_converged and stats.projection_converged
    # Impulses summed over the step: the impact's m (1 + e) |v| (no impulse in free flight),
    # in the contact frame (normal first), to the solver tolerance relative to the impulse.
    normal = result.contact_impulse[result.contact_active][:, 0].sum()
    assert normal == pytest.approx(mass * (1.0 + e) * abs(v_impact), rel=1e-9)


def test_without_localisation_the_step_is_not_split_and_off_by_order_v_h():
    e, h, radius = 0.5, 1e-3, 0.1
    stepper, state, _ = _ball_stepper(e, False, h)
    while True:
        result = stepper.step(state)
        if result.state.v[1, 2] > 0.0:
            break
        state = result.state
    assert result.statistics.substeps == 1
    localised, _, _ = _ball_stepper(e, True, h)
    split = localised.step(state)
    # The classic impact step ends off the exact state by O(|v| h) (|v| = 4.4 m/s): here
    # 1.6e-4 m above it, far beyond the split step's 1e-10 m.
    assert abs(result.state.x[1, 2] - split.state.x[1, 2]) > 1e-2 * 4.4 * h
    assert result.state.x[1, 2] - radius > 0.0


def test_step_takes_its_size_as_an_argument():
    stepper, state, _ = _ball_stepper(0.5, True, 1e-3)
    other = MoreauJeanStepper(stepper.system, replace(stepper.settings, time_step=2e-3))
    # A step of 2e-3 s asked of a stepper set up for 1e-3 s is the step of a stepper set up for
    # 2e-3 s, bit for bit: nothing of the stepper depends on h but the argument.
    for _ in range(3):
        expected = other.step(state).state
        assert np.array_equal(stepper.step(state, 2e-3).state.x, expected.x)
        state = expected
    with pytest.raises(ValueError):
        stepper.step(state, 0.0)


def test_settings_and_options_of_localisation_are_validated():
    with pytest.raises(ValueError):
        StepperSettings(1e-3, projection=False, localise_impacts=True)
    with pytest.raises(ValueError):
        StepperSettings(1e-3, localise_impacts=True, max_impact_splits=0)
    scene = get_scene("bouncing-ball-e0.5")
    engine = create()
    with pytest.raises(ValueError):
        engine.run_settings(scene, RunSettings(options={"localise_impacts": "yes"}))
    assert engine.run_settings(scene, RunSettings()).localise_impacts
    # Without the projection the preset's localisation does not apply; asked for, it fails.
    assert not engine.run_settings(
        scene, RunSettings(options={"projection": False})).localise_impacts
    assert not create("no-projection").run_settings(scene, RunSettings()).localise_impacts
    with pytest.raises(ValueError):
        engine.run_settings(
            scene, RunSettings(options={"projection": False, "localise_impacts": True}))
