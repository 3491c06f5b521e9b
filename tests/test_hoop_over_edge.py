"""The hoop sliding off a plate's edge: its analytic path (scenarios/analytic/edges.py) checked
by methods that share no code with it, and the ``hoop_over_edge`` figures and criterion on
exact and wrong paths."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate

from clearbench.adapters.base import RunSettings
from clearbench.harness.measure.figures import measure
from clearbench.harness.measure.kinds.edges import PATH_FRACTION
from clearbench.scenarios import analytic
from clearbench.scenarios.library import get_scene

from .fake_engine import create as fake_engine

G, R = 9.81, 0.1


def _pivot_by_cartesian_ode(v0: float, radius: float, g: float):
    """The centre as a point in the plane about the edge at the origin, integrated in
    Cartesian coordinates with the constraint force that keeps it at ``radius`` (the
    centripetal balance N = m (g cos - v^2 / r), pushing out), until N = 0 (an event).
    Returns the leave angle from the vertical and the pivot's duration."""
    def rates(_, y):
        x, z, vx, vz = y
        distance = math.hypot(x, z)
        n = np.array([x, z]) / distance
        push = g * n[1] - (vx * vx + vz * vz) / distance  # N / m
        return (vx, vz, push * n[0], push * n[1] - g)

    def leaves(_, y):
        x, z, vx, vz = y
        return g * z / math.hypot(x, z) - (vx * vx + vz * vz) / math.hypot(x, z)

    leaves.terminal = True
    solution = integrate.solve_ivp(rates, (0.0, 10.0), (0.0, radius, v0, 0.0), method="Radau",
                                   rtol=1e-11, atol=1e-13, events=leaves)
    x, z = solution.y_events[0][0][:2]
    return math.atan2(x, z), float(solution.t_events[0][0])


@pytest.mark.parametrize("ratio", [0.2, 0.5, 0.9])
def test_the_leave_angle_and_time_agree_with_a_cartesian_integration(ratio):
    v0 = ratio * math.sqrt(G * R)
    angle, duration = _pivot_by_cartesian_ode(v0, R, G)
    # Both integrations to 1e-11 relative: agreement to 1e-7 leaves room for the event's
    # location and the Cartesian constraint's drift.
    assert analytic.hoop_over_edge_leave_angle(v0, R, G) == pytest.approx(angle, rel=1e-7)
    assert analytic.hoop_over_edge_pivot_time(v0, R, G) == pytest.approx(duration, rel=1e-7)


def test_the_closed_form_leave_angle_is_where_the_edge_stops_pushing():
    # cos(theta1) = (2 + v0^2/(g r)) / 3: 41.41 degrees at v0^2 = g r / 4 (by hand: 2.25 / 3).
    v0 = 0.5 * math.sqrt(G * R)
    assert math.degrees(analytic.hoop_over_edge_leave_angle(v0, R, G)) == pytest.approx(
        math.degrees(math.acos(0.75)), abs=1e-12)
    # At v0^2 >= g r the edge cannot turn the hoop at all: it leaves at once.
    assert analytic.hoop_over_edge_leave_angle(math.sqrt(G * R), R, G) == 0.0
    assert analytic.hoop_over_edge_pivot_time(1.2 * math.sqrt(G * R), R, G) == 0.0


def test_the_path_is_continuous_pivots_on_the_circle_and_clears_the_plate():
    v0, a = 0.5 * math.sqrt(G * R), 0.05
    t = np.linspace(0.0, 0.4, 40001)  # 10 us apart
    path = analytic.hoop_over_edge_path(t, v0, R, G, a)
    d = path.displacement
    step = np.linalg.norm(np.diff(d, axis=0), axis=1)
    # No jump: the largest step is the fastest speed (about 1.3 m/s by the end) times 10 us.
    assert step.max() < 2.0 * 10e-6 * np.max(np.linalg.norm(np.gradient(d, t, axis=0), axis=1))
    # Sliding at v0, then on the circle of radius r about the edge (a, -r), then outside it.
    edge = np.array([a, -R])
    assert np.allclose(d[t < a / v0], np.stack([v0 * t[t < a / v0], 0 * t[t < a / v0]], -1))
    radius = np.linalg.norm(d - edge, axis=1)
    assert np.allclose(radius[path.on_edge], R, rtol=1e-10)
    flying = t > path.leave_time
    assert np.all(radius[flying] > R * (1 - 1e-9))
    # Leaving, the speed is sqrt(g r cos(theta1)) (N = 0) and the energy is v0^2/2 + g drop.
    speed = np.linalg.norm(np.gradient(d, t, axis=0), axis=1)
    k = np.searchsorted(t, path.leave_time)
    assert speed[k] ** 2 == pytest.approx(G * R * math.cos(path.leave_angle), rel=1e-4)
    # (central differences: the two end samples, one-sided, left out)
    assert (0.5 * speed**2 + G * d[:, 1])[1:-1] == pytest.approx(0.5 * v0**2, rel=1e-4)


def test_the_path_agrees_with_a_penalty_integration_of_the_hoop_against_the_plate():
    # The hoop's centre as a point pushed out of the plate (the slab x <= 0, -depth <= z <= 0)
    # by a stiff spring wherever the circle of radius r about it reaches into the slab, along
    # the line from the slab's nearest point: the face, then the edge, then nothing. No
    # pivot, no leave angle is written in: both come out of the contact geometry.
    v0, a, depth, stiffness = 0.5 * math.sqrt(G * R), 0.05, 0.02, 1e7  # [N/m per kg]

    def rates(_, y):
        centre = y[:2]
        nearest = np.array([min(centre[0], 0.0), min(max(centre[1], -depth), 0.0)])
        away = centre - nearest
        distance = float(np.linalg.norm(away))
        push = stiffness * (R - distance) * away / distance if distance < R else np.zeros(2)
        return (y[2], y[3], push[0], push[1] - G)

    horizon = 0.269  # the library scene's
    solution = integrate.solve_ivp(rates, (0.0, horizon), (-a, R, v0, 0.0), method="DOP853",
                                   rtol=1e-10, atol=1e-12, max_step=1e-4, dense_output=True)
    t = np.linspace(0.0, horizon, 200)
    penalty = solution.sol(t)[:2].T - np.array([-a, R])
    exact = analytic.hoop_over_edge_path(t, v0, R, G, a).displacement
    # The spring sinks the hoop by g / stiffness (1 um) and a little more on the pivot: the
    # paths agree to 1e-3 r (measured 5.4e-4 r), 20 times inside the 2 % criterion.
    assert np.max(np.linalg.norm(penalty - exact, axis=1)) < 1e-3 * R


def _run_on(scene, path_of):
    """The fake engine's run of ``scene`` with the hoop's centre moved onto ``path_of(t)``
    (displacement (n, 2) along x and up)."""
    trajectory = fake_engine()._run(scene, RunSettings())
    hoop = scene.body_index("hoop")
    start = np.asarray(scene.body("hoop").position)
    d = path_of(trajectory.times)
    trajectory.positions[:, hoop] = start + np.stack([d[:, 0], 0 * d[:, 0], d[:, 1]], -1)
    return trajectory


def test_the_criterion_passes_the_exact_path_and_fails_a_hoop_that_misses_the_edge():
    scene = get_scene("hoop-off-edge")
    p = next(e for e in scene.expectations if e.kind == "hoop_over_edge").parameters
    v0, a = p["initial_speed"], p["edge_distance"]

    def exact(t):
        return analytic.hoop_over_edge_path(t, v0, R, G, a).displacement

    def free_fall_from_the_edge(t):  # the edge unseen: the contact dropped at t0 = a / v0
        tau = np.maximum(t - a / v0, 0.0)
        return np.stack([v0 * t, -0.5 * G * tau**2], -1)

    results = {}
    for label, path in (("exact", exact), ("unseen edge", free_fall_from_the_edge)):
        measured = measure(scene, _run_on(scene, path))
        results[label] = next(r for r in measured.expectations if r["name"] == "over_the_edge")
    assert results["exact"]["passed"] is True
    assert results["exact"]["figures"]["path_relative_error"] < 1e-9
    missed = results["unseen edge"]
    assert missed["passed"] is False
    # 0.44 r off at the leave time already, and more by the end: far beyond the 2 % bound.
    assert missed["figures"]["path_relative_error"] > 20 * PATH_FRACTION
    assert "inside its circle about the edge" in missed["detail"]


def test_the_library_scene_is_in_the_default_comparison_and_clear_of_the_plate():
    scene = get_scene("hoop-off-edge")
    assert {"smoke", "analytic", "edge"} <= set(scene.tags)
    assert "pair:circle-rectangle" in scene.features
    # The horizon ends 0.05 s after the hoop leaves, before it can meet the plate again.
    p = next(e for e in scene.expectations if e.kind == "hoop_over_edge").parameters
    leave = analytic.hoop_over_edge_path([0.0], p["initial_speed"], R, G, p["edge_distance"])
    assert scene.horizon == pytest.approx(leave.leave_time + 0.05, abs=1e-3)


def test_the_reference_follows_the_hoop_over_the_edge_without_spin():
    # The reference on the library scene, as `clearbench run` steps it. Without friction no
    # contact can spin the hoop: its normal at the edge is the common normal of ring and edge,
    # through the hoop's centre. A normal taken from the plate's faces at the edge (the top
    # face's or the side's, as the gap kernel gave while the ring sat on the edge to round-off)
    # spun it to 1.9 rad/s and left the path 25 % off (measured). Bounds: the criterion's own
    # (PATH_FRACTION of the radius), and a spin of 1e-6 rad/s, a million times below that.
    from clearbench.adapters.reference.engine import create

    scene = get_scene("hoop-off-edge")
    trajectory = create("default").run(scene, RunSettings(record_every=1))
    assert trajectory.status.value == "ok", trajectory.message
    over = next(r for r in measure(scene, trajectory).expectations
                if r["name"] == "over_the_edge")
    assert over["passed"] is True, over["detail"]
    hoop = trajectory.body_names.index("hoop")
    assert np.max(np.abs(trajectory.angular_velocities[:, hoop])) <= 1e-6
