"""Expectation verdicts on hand-made trajectories (no engine): the implied energy check, the
stick after a sliding stop, the rolling and output-value kinds, and the detail every
expectation line carries (its figure against its bound)."""

from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
import pytest

from clearbench.harness.cli.run import print_summary
from clearbench.harness.measure.figures import measure
from clearbench.harness.measure.kinds.invariants import ENERGY_GROWTH_ALLOWANCE
from clearbench.scenarios import analytic
from clearbench.scenarios.expectations import Expectation
from clearbench.scenarios.library import get_scene
from clearbench.scenarios.units import UnitSystem
from clearbench.scenarios.validation import SceneError

from .harness_helpers import probe_scene
from .test_measure_from_scene import _still

GRAVITY = 9.81  # m/s^2


def _results(scene, trajectory) -> dict:
    return {r["name"]: r for r in measure(scene, trajectory).expectations}


# ---------------------------------------------------------------- energy on every run
def test_an_energy_gain_fails_a_scene_that_lists_no_energy_expectation():
    # The probe ball flies freely (no expectation at all); speeding it up by 10 % along its
    # path gains 21 % of its kinetic energy, 21 times the allowance.
    scene = probe_scene(horizon=0.1)
    trajectory = _still(scene, 11)
    trajectory.velocities[:, 0] = np.asarray(scene.body("ball").velocity) * np.linspace(
        1.0, 1.1, 11)[:, None]
    results = _results(scene, trajectory)
    check = results["energy_balance"]
    assert check["passed"] is False
    assert check["figures"]["energy_growth_relative"] > ENERGY_GROWTH_ALLOWANCE
    assert check["detail"].startswith("energy growth") and "> 1 %" in check["detail"]


def test_a_scene_with_a_working_load_gets_no_energy_check():
    scene = get_scene("slider-crank")  # a driver does work the balance does not count
    trajectory = _still(scene, 3)
    assert "energy_balance" not in _results(scene, trajectory)


# ---------------------------------------------------------------- sliding stop, then stick
def _sliding_box(creep_speed: float):
    """The sliding box on its analytic path, then still moving at ``creep_speed`` [m/s]
    after the stop (0: at rest), 1 ms samples."""
    scene = get_scene("sliding-box")
    p = scene.expectations[0].parameters
    v0, mu = p["initial_speed"], p["friction"]
    stop = analytic.sliding_box_stop_time(v0, mu, GRAVITY)
    times = np.arange(0.0, scene.horizon + 5e-4, 1e-3)
    trajectory = _still(scene, len(times))
    trajectory.times = times
    box = scene.body_index("box")
    speed = np.maximum(analytic.sliding_box_velocity(times, v0, mu, GRAVITY),
                       np.where(times > stop - 0.05, creep_speed, 0.0))
    x = np.concatenate([[0.0], np.cumsum(0.5 * (speed[1:] + speed[:-1]) * np.diff(times))])
    trajectory.positions[:, box, 0] += x
    trajectory.velocities[:, box, 0] = speed
    return scene, trajectory


def test_a_box_that_stops_and_stays_passes():
    scene, trajectory = _sliding_box(0.0)
    stop = _results(scene, trajectory)["stop"]
    assert stop["passed"] is True, stop["detail"]
    expected = analytic.sliding_box_stop_time(2.0, 0.3, GRAVITY)
    # Stopped at 1e-3 v0: a fraction 1e-3 of the stop time early, plus one 1 ms sample.
    assert abs(stop["figures"]["stop_time"] - expected) <= 1e-3 * expected + 1e-3


def test_a_box_still_sliding_at_the_end_fails():
    # 20 mm/s after the stop: 6 mm more in the 0.3 s left, within the 2 % of the stop
    # distance (0.68 m) that the distance criterion allows, but never stopped.
    scene, trajectory = _sliding_box(0.02)
    stop = _results(scene, trajectory)["stop"]
    assert abs(stop["figures"]["stop_distance_error"]) < 0.02 * 0.68
    assert stop["passed"] is False and "never stopped" in stop["detail"]


def test_a_box_that_creeps_on_after_its_stop_fails():
    # 1 mm/s, below the 2 mm/s stop threshold: stopped, then 0.3 mm more, 20 times the stick
    # bound of 1e-4 of the box's size (15 um).
    scene, trajectory = _sliding_box(0.001)
    stop = _results(scene, trajectory)["stop"]
    assert math.isfinite(stop["figures"]["stop_time"])
    assert stop["passed"] is False and "slid after the stop" in stop["detail"]


# ---------------------------------------------------------------- rolling and output value
def _rolling(slide: bool):
    """The rolling-incline ball on its analytic path, spinning as it rolls or (``slide``)
    not at all."""
    scene = get_scene("rolling-incline")
    times = np.arange(0.0, scene.horizon + 5e-4, 1e-3)
    trajectory = _still(scene, len(times))
    trajectory.times = times
    angle, radius = math.radians(20.0), 0.1
    acceleration = analytic.rolling_incline_acceleration(angle, GRAVITY, 0.4)
    down = np.array([math.cos(angle), 0.0, -math.sin(angle)])
    ball = scene.body_index("ball")
    trajectory.positions[:, ball] += np.outer(0.5 * acceleration * times**2, down)
    trajectory.velocities[:, ball] = np.outer(acceleration * times, down)
    if not slide:
        # Rolling: omega = v / r about the axis n x down = +y (world); body axes are the
        # ball's tilted frame, whose y axis is world y.
        trajectory.angular_velocities[:, ball, 1] = acceleration * times / radius
    return scene, trajectory


def test_a_ball_rolling_down_the_incline_passes_both_new_kinds():
    scene, trajectory = _rolling(slide=False)
    results = _results(scene, trajectory)
    assert results["rolling"]["passed"] is True, results["rolling"]["detail"]
    # Rolling exactly: no slip, to round-off of the 1.7 m/s speed.
    assert results["rolling"]["figures"]["slip_speed_max"] < 1e-12
    assert results["ball_x_at_half_second"]["passed"] is True


def test_a_ball_sliding_down_without_spin_fails_the_slip_check():
    scene, trajectory = _rolling(slide=True)
    rolling = _results(scene, trajectory)["rolling"]
    assert rolling["passed"] is False and "slip speed" in rolling["detail"]


def test_an_output_value_off_its_tolerance_fails_with_its_figure():
    scene, trajectory = _rolling(slide=False)
    trajectory.positions[:, scene.body_index("ball"), 0] += 0.01  # 10 mm, tolerance 5.6 mm
    check = _results(scene, trajectory)["ball_x_at_half_second"]
    assert check["passed"] is False
    assert check["figures"]["deviation"] == pytest.approx(0.01, rel=1e-9)
    assert "ball_x off by 0.01 m > 0.00563 m" in check["detail"]


@pytest.mark.parametrize(("changes", "field"), [
    (dict(output=None), "output"),
    (dict(parameters={"value": 1.0}), "parameters"),
    (dict(parameters={"value": 1.0, "relative_tolerance": -0.1}), "parameters.relative_tolerance"),
])
def test_a_bad_output_value_expectation_names_its_field(changes, field):
    given = dict(kind="output_value", output="ball_x",
                 parameters={"value": 1.0, "relative_tolerance": 0.1})
    given.update(changes)
    with pytest.raises(SceneError) as error:
        Expectation("check", **given)
    assert error.value.field.endswith(field)


def test_an_output_value_expectation_names_an_existing_output():
    scene = get_scene("rolling-incline")
    bad = Expectation("check", kind="output_value", output="nowhere",
                      parameters={"value": 1.0, "absolute_tolerance": 0.1})
    with pytest.raises(SceneError, match="nowhere") as error:
        dataclasses.replace(scene, expectations=(bad,))
    assert error.value.field == "expectations['check'].output"


def test_an_output_value_is_converted_with_its_output_unit():
    scene = get_scene("rolling-incline")
    before = next(e for e in scene.expectations if e.kind == "output_value").parameters
    after = next(e for e in scene.rescaled(UnitSystem("mm", "g", "ms")).expectations
                 if e.kind == "output_value").parameters
    assert after["value"] == pytest.approx(1e3 * before["value"])  # m -> mm
    assert after["absolute_tolerance"] == pytest.approx(1e3 * before["absolute_tolerance"])
    assert after["time"] == pytest.approx(1e3 * before["time"])    # s -> ms


# ---------------------------------------------------------------- the expectation lines
def test_every_expectation_line_shows_its_figure_against_its_bound(capsys):
    scene, trajectory = _bob_out_of_bore()
    results = measure(scene, trajectory).expectations
    for result in results:
        assert result["detail"], result
    penetration = next(r for r in results if r["kind"] == "no_penetration")
    assert penetration["detail"].startswith("penetration ")
    # 1 % of the smallest feature, the 0.1 mm radial clearance.
    assert " m > 1e-06 m (pivot.ring_" in penetration["detail"]
    row = {"scene_name": scene.name, "engine": "hand", "preset": "default", "time_step": 1e-3,
           "horizon": 2e-3, "status": "ok", "expectations_passed": 0, "message": "",
           "engine_status": "ok", "engine_message": "", "engine_version": "hand 0",
           "worker_seconds": 0.0, "build_seconds": 0.0, "stepping_seconds": 0.0, "steps": 2,
           "stepping_seconds_per_step": 0.0, "stepping_seconds_per_simulated_second": 0.0,
           "metrics": "{}", "error_source": "", "metrics_error": "", "trajectory": "",
           "key": "k", "expectations": json.dumps(results)}
    print_summary(row)
    printed = capsys.readouterr().out
    assert f"FAIL  no_penetration: {penetration['detail']}" in printed


def _bob_out_of_bore():
    scene = get_scene("clearance-pendulum")
    trajectory = _still(scene, 3)
    trajectory.positions[-1, scene.body_index("bob"), 0] += 0.05  # 5 cm out of a 1 cm pin
    return scene, trajectory
