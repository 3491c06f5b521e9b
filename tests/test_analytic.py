"""The analytic references against independent computations.

Each closed form is checked against a numerical integration of the equations of motion with
scipy's solve_ivp (DOP853, event location for impacts and friction transitions) or against a
limit case. Every bound says why it is what it is. Notes on the integrator used throughout:

* DOP853 is an order-8 Runge–Kutta method: it integrates polynomial solutions of degree <= 8
  exactly up to round-off, so for free flight and constant-force sliding (parabolas) the only
  error left is round-off and event location;
* solve_ivp locates an event by brentq on the dense output with xtol = rtol = 4 eps, so an event
  time carries the dense-output error plus ~1e-15 relative;
* for the smooth problems (pendulum, torque-free body, rocking segments, slider–crank) the
  global error at the chosen rtol was measured; each bound states the measured figure and the
  margin it leaves.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq, minimize_scalar

from clearbench.scenarios import analytic

EPS = np.finfo(float).eps
RTOL = 1e-12  # solve_ivp relative tolerance used by every reference integration below


# ---------------------------------------------------------------------------------------------
# Bouncing ball
# ---------------------------------------------------------------------------------------------


def _simulate_bouncing_ball(h0, g, e, n_impacts):
    """Event-driven flight: DOP853 between impacts, Newton's law v+ = -e v- at each z = 0."""

    def flight(_t, y):
        return [y[1], -g]

    def touchdown(_t, y):
        return y[0]

    touchdown.terminal = True
    touchdown.direction = -1

    def apex(_t, y):
        return y[1]

    apex.direction = -1
    flight_bound = 3.0 * math.sqrt(2.0 * h0 / g)
    t, state = 0.0, [h0, 0.0]
    impacts, apex_heights, segments = [], [h0], []
    for k in range(n_impacts):
        sol = solve_ivp(
            flight,
            (t, t + flight_bound),
            state,
            method="DOP853",
            rtol=RTOL,
            atol=RTOL * h0,
            events=(touchdown, apex),
            dense_output=True,
        )
        t_hit, v_hit = sol.t_events[0][0], sol.y_events[0][0][1]
        if k > 0:
            apex_heights.append(sol.y_events[1][0][0])
        segments.append((t, t_hit, sol.sol))
        impacts.append(t_hit)
        t, state = t_hit, [0.0, -e * v_hit]
    return np.array(impacts), np.array(apex_heights), segments


def test_bouncing_ball_matches_event_driven_integration():
    h0, g, e, n = 1.3, 9.81, 0.7, 8
    impacts, apexes, segments = _simulate_bouncing_ball(h0, g, e, n)
    t_first = math.sqrt(2.0 * h0 / g)
    # Parabolic flights are exact for DOP853; each impact time carries ~4 eps of root finding
    # (of t, up to 6 t_first here) and the restart inherits it: measured 6e-14 t_first after 8
    # impacts; 1e-12 t_first leaves a factor ~15.
    np.testing.assert_allclose(
        analytic.bouncing_ball_impact_times(h0, g, e, n), impacts, rtol=0, atol=1e-12 * t_first
    )
    # Apex heights: same round-off argument, measured 6e-15 h0.
    np.testing.assert_allclose(
        analytic.bouncing_ball_apex_heights(h0, e, n - 1), apexes, rtol=0, atol=1e-13 * h0
    )
    v0 = analytic.bouncing_ball_impact_speed(h0, g)
    for start, end, dense in segments:
        # Interior samples only: at an impact instant the analytic velocity is the post-impact
        # one and the integration's segment ends with the pre-impact one.
        tt = np.linspace(start, end, 101)[1:-1]
        z_ref, v_ref = dense(tt)
        # Dense output of an exact polynomial plus the inherited impact-time round-off:
        # measured 2e-14 h0 and 6e-14 v0; 1e-12 leaves a factor >= 15.
        np.testing.assert_allclose(
            analytic.bouncing_ball_height(tt, h0, g, e), z_ref, rtol=0, atol=1e-12 * h0
        )
        np.testing.assert_allclose(
            analytic.bouncing_ball_velocity(tt, h0, g, e), v_ref, rtol=0, atol=1e-12 * v0
        )


def test_bouncing_ball_accumulates_at_rest_time_and_then_rests():
    h0, g, e = 0.5, 9.81, 0.5
    rest = analytic.bouncing_ball_rest_time(h0, g, e)
    v0 = analytic.bouncing_ball_impact_speed(h0, g)
    assert rest == pytest.approx(v0 / g * (1 + e) / (1 - e), rel=4 * EPS)  # the stated formula
    # Impact 60 is e^59 ~ 2e-18 of the first flight away from t_inf: equal to round-off.
    assert analytic.bouncing_ball_impact_times(h0, g, e, 60)[-1] == pytest.approx(rest, rel=4 * EPS)
    after = rest + np.array([0.0, 1e-9, 1.0, 100.0])
    assert np.all(analytic.bouncing_ball_height(after, h0, g, e) == 0.0)
    assert np.all(analytic.bouncing_ball_velocity(after, h0, g, e) == 0.0)
    # Just before t_inf the ball is in flight k with apex e^(2k) h0 and C e^(k+1) < t_inf - t,
    # C = 2 v0 / (g (1 - e)); so z <= e^(2k) h0 < h0 ((t_inf - t) / (C e))^2. Exact inequality,
    # tested with a 1e-9 h0 slack for round-off of t_inf - t near the accumulation point.
    remaining = np.geomspace(1e-12, 0.1, 2001) * rest
    z = analytic.bouncing_ball_height(rest - remaining, h0, g, e)
    scale = 2.0 * v0 / (g * (1.0 - e))
    assert np.all(z <= h0 * (remaining / (scale * e)) ** 2 + 1e-9 * h0)


def test_bouncing_ball_height_is_continuous_and_energy_follows_the_apexes():
    h0, g, e = 2.0, 9.81, 0.8
    rest = analytic.bouncing_ball_rest_time(h0, g, e)
    tt = np.linspace(0.0, 1.1 * rest, 200_001)
    z = analytic.bouncing_ball_height(tt, h0, g, e)
    v = analytic.bouncing_ball_velocity(tt, h0, g, e)
    v0 = analytic.bouncing_ball_impact_speed(h0, g)
    assert np.all(z >= 0.0)
    # Continuity: |dz| <= v0 dt (speed never exceeds v0), plus round-off.
    assert np.max(np.abs(np.diff(z))) <= v0 * (tt[1] - tt[0]) * (1 + 1e-9)
    # Specific energy v^2/2 + g z equals g times the current apex height: apexes are e^(2k) h0,
    # so it takes only those values (to round-off of g h0) or 0 at rest.
    energy = 0.5 * v**2 + g * z
    levels = np.sort(np.append(g * analytic.bouncing_ball_apex_heights(h0, e, 400), 0.0))
    above = np.clip(np.searchsorted(levels, energy), 1, levels.size - 1)
    nearest = np.minimum(np.abs(energy - levels[above]), np.abs(energy - levels[above - 1]))
    assert np.max(nearest) <= 1e-12 * g * h0


def test_bouncing_ball_without_restitution_rests_at_first_impact():
    h0, g = 1.0, 9.81
    t_first = math.sqrt(2.0 * h0 / g)
    assert analytic.bouncing_ball_rest_time(h0, g, 0.0) == pytest.approx(t_first, rel=4 * EPS)
    tt = np.array([0.5 * t_first, t_first, 2.0 * t_first])
    z = analytic.bouncing_ball_height(tt, h0, g, 0.0)
    assert z[0] == pytest.approx(0.75 * h0, rel=4 * EPS)  # free fall for a quarter of the height
    assert z[1] == 0.0 and z[2] == 0.0
    np.testing.assert_array_equal(analytic.bouncing_ball_apex_heights(h0, 0.0, 2), [h0, 0, 0])


def test_bouncing_ball_rejects_misuse():
    with pytest.raises(ValueError, match="restitution"):
        analytic.bouncing_ball_height([0.0], 1.0, 9.81, 1.0)
    with pytest.raises(ValueError, match="g = "):
        analytic.bouncing_ball_rest_time(1.0, -9.81, 0.5)
    with pytest.raises(ValueError, match="t: min"):
        analytic.bouncing_ball_height([-1.0, 0.0], 1.0, 9.81, 0.5)


# ---------------------------------------------------------------------------------------------
# Friction: incline, sliding box, sliding-to-rolling sphere
# ---------------------------------------------------------------------------------------------


def _incline_world_integration(alpha, mu, g, t_end):
    """A point mass kept on the slope by its normal reaction, Coulomb friction, world axes.

    The slope runs downhill along ``tangent``; the reaction keeps the normal velocity zero, so
    it cancels the normal part of gravity. Returns the displacement along the slope at t_end.
    """
    gravity = np.array([0.0, -g])
    tangent = np.array([math.cos(alpha), -math.sin(alpha)])
    normal = np.array([math.sin(alpha), math.cos(alpha)])
    normal_reaction = -gravity @ normal  # per unit mass, >= 0
    tangential_demand = gravity @ tangent  # friction needed to hold the mass, per unit mass
    if abs(tangential_demand) <= mu * normal_reaction:
        return 0.0  # inside the friction cone: the mass sticks from rest

    def rhs(_t, y):
        velocity = y[2:]
        speed = np.linalg.norm(velocity)
        # Starting from rest the slip is towards the tangential demand.
        slip = velocity / speed if speed > 0.0 else tangent * np.sign(tangential_demand)
        reaction = normal_reaction * (normal - mu * slip)
        return np.concatenate((velocity, gravity + reaction))

    sol = solve_ivp(rhs, (0.0, t_end), np.zeros(4), method="DOP853", rtol=RTOL, atol=1e-14)
    return float(sol.y[:2, -1] @ tangent)


@pytest.mark.parametrize(
    ("alpha", "mu"),
    [(0.5, 0.2), (0.3, 0.5), (math.atan(0.4), 0.4), (1.2, 0.0), (0.5 * math.pi, 0.7)],
)
def test_incline_matches_world_frame_integration(alpha, mu):
    g, t_end = 9.81, 1.7
    expected = _incline_world_integration(alpha, mu, g, t_end)
    s = float(analytic.incline_block_displacement(t_end, alpha, mu, g))
    sticks = analytic.incline_block_sticks(alpha, mu)
    assert sticks == (expected == 0.0)
    # Constant acceleration: a parabola, exact for DOP853 up to round-off (~1e-15 of g t^2).
    assert s == pytest.approx(expected, rel=1e-12, abs=1e-13 * g * t_end**2)


def test_incline_limit_cases():
    g = 9.81
    tt = np.linspace(0.0, 2.0, 5)
    # Frictionless slope: g sin(alpha); vertical wall: free fall whatever mu (no normal force).
    np.testing.assert_allclose(
        analytic.incline_block_displacement(tt, 0.4, 0.0, g),
        0.5 * g * math.sin(0.4) * tt**2,
        rtol=4 * EPS,  # the same product in another order
    )
    np.testing.assert_allclose(
        analytic.incline_block_velocity(tt, 0.5 * math.pi, 3.0, g),
        g * tt,
        rtol=1e-15,
        atol=1e-14 * g,  # mu cos(pi/2) = 3 * 6e-17 leaves a 2e-16 g residue
    )
    assert analytic.incline_block_sticks(0.0, 0.0)  # flat and frictionless: nothing pushes it
    assert analytic.incline_block_acceleration(0.3, math.tan(0.3), g) == 0.0  # on the cone edge


def _simulate_sliding(v0, mu, g, t_end):
    """Coulomb sliding with a terminal event at v = 0, then rest."""

    def rhs(_t, y):
        return [y[1], -math.copysign(mu * g, v0)]

    def stops(_t, y):
        return y[1]

    stops.terminal = True
    sol = solve_ivp(
        rhs,
        (0.0, t_end),
        [0.0, v0],
        method="DOP853",
        rtol=RTOL,
        atol=1e-14,
        events=stops,
        dense_output=True,
    )
    return sol.t_events[0][0], sol.y_events[0][0][0], sol.sol


@pytest.mark.parametrize("v0", [3.0, -1.5])
def test_sliding_box_matches_event_integration(v0):
    mu, g = 0.35, 9.81
    t_stop, x_stop, dense = _simulate_sliding(v0, mu, g, 10.0)
    # Parabola again: exact for DOP853; event location adds ~4 eps relative.
    assert analytic.sliding_box_stop_time(v0, mu, g) == pytest.approx(t_stop, rel=1e-13)
    assert analytic.sliding_box_stop_distance(v0, mu, g) == pytest.approx(abs(x_stop), rel=1e-13)
    tt = np.linspace(0.0, t_stop, 50)
    x_ref, v_ref = dense(tt)
    np.testing.assert_allclose(
        analytic.sliding_box_position(tt, v0, mu, g), x_ref, rtol=0, atol=1e-13 * abs(x_stop)
    )
    np.testing.assert_allclose(
        analytic.sliding_box_velocity(tt, v0, mu, g), v_ref, rtol=0, atol=1e-13 * abs(v0)
    )
    later = t_stop * np.array([1.5, 3.0])
    np.testing.assert_array_equal(analytic.sliding_box_velocity(later, v0, mu, g), [0.0, 0.0])
    np.testing.assert_allclose(
        analytic.sliding_box_position(later, v0, mu, g), x_stop, rtol=1e-13
    )  # frozen at the stop position found by the event


def test_sliding_box_without_friction_never_stops():
    assert analytic.sliding_box_stop_time(2.0, 0.0, 9.81) == math.inf
    np.testing.assert_array_equal(
        analytic.sliding_box_position([0.0, 5.0], 2.0, 0.0, 9.81), [0.0, 10.0]
    )


def _simulate_sphere(v0, mu, g, radius, inertia_ratio, t_end):
    """3D Newton–Euler of a ball on the plane z = 0: friction opposes the contact-point slip.

    State: centre position (x, y), velocity (vx, vy) and angular velocity (wx, wy, wz), world
    axes. The contact point is at r = (0, 0, -R) from the centre; slip = v + w x r. A terminal
    event stops the integration when the slip vanishes. The friction direction is held at the
    initial slip direction: written as -u/|u| it would flip inside the step that crosses the
    event and spoil that step's dense output (measured 5e-12 relative on the event time). The
    caller checks that the slip stayed along that direction.
    """
    mass = 1.0
    inertia = inertia_ratio * mass * radius**2
    lever = np.array([0.0, 0.0, -radius])

    def slip(y):
        return np.array([y[2], y[3], 0.0]) + np.cross(y[4:7], lever)

    slip_direction = slip(np.array([0.0, 0.0, v0, 0.0, 0.0, 0.0, 0.0]))
    slip_direction /= np.linalg.norm(slip_direction)

    def rhs(_t, y):
        force = -mu * mass * g * slip_direction
        torque = np.cross(lever, force)
        return np.concatenate(([y[2], y[3]], force[:2] / mass, torque / inertia))

    def rolls(_t, y):
        return slip(y) @ slip_direction

    rolls.terminal = True
    y0 = np.array([0.0, 0.0, v0, 0.0, 0.0, 0.0, 0.0])
    sol = solve_ivp(
        rhs,
        (0.0, t_end),
        y0,
        method="DOP853",
        rtol=RTOL,
        atol=1e-14,
        events=rolls,
        dense_output=True,
    )
    slip_normal_to_direction = [np.cross(slip(y), slip_direction) for y in sol.y.T]
    assert np.max(np.abs(slip_normal_to_direction)) == 0.0  # planar motion: exactly collinear
    return sol.t_events[0][0], sol.y_events[0][0], sol.sol


@pytest.mark.parametrize("inertia_ratio", [analytic.SOLID_SPHERE_INERTIA_RATIO, 2.0 / 3.0, 0.5])
def test_sphere_sliding_to_rolling_matches_newton_euler(inertia_ratio):
    v0, mu, g, radius = 4.0, 0.2, 9.81, 0.05
    t_roll, y_roll, dense = _simulate_sphere(v0, mu, g, radius, inertia_ratio, 10.0)
    onset = analytic.rolling_sphere_onset_time(v0, mu, g, inertia_ratio)
    # Constant force and torque: linear velocities, exact for DOP853; event ~4 eps.
    assert onset == pytest.approx(t_roll, rel=1e-13)
    if inertia_ratio == analytic.SOLID_SPHERE_INERTIA_RATIO:
        assert onset == pytest.approx(2.0 * v0 / (7.0 * mu * g), rel=4 * EPS)  # stated formula
        assert analytic.rolling_sphere_final_speed(v0) == pytest.approx(5.0 * v0 / 7.0, rel=EPS)
    tt = np.linspace(0.0, t_roll, 40)
    ref = dense(tt)
    np.testing.assert_allclose(
        analytic.rolling_sphere_position(tt, v0, mu, g, inertia_ratio),
        ref[0],
        rtol=0,
        atol=1e-13 * v0 * t_roll,
    )
    np.testing.assert_allclose(
        analytic.rolling_sphere_velocity(tt, v0, mu, g, inertia_ratio),
        ref[2],
        rtol=0,
        atol=1e-13 * v0,
    )
    spin = analytic.rolling_sphere_angular_velocity(tt, v0, mu, g, radius, inertia_ratio)
    np.testing.assert_allclose(spin, ref[5], rtol=0, atol=1e-13 * v0 / radius)  # +y spin
    # After the onset nothing acts (zero slip, zero friction): uniform rolling from the event
    # state, which the analytic position continues exactly up to round-off.
    later = t_roll + np.array([0.5, 2.0])
    expected_x = y_roll[0] + y_roll[2] * (later - t_roll)
    np.testing.assert_allclose(
        analytic.rolling_sphere_position(later, v0, mu, g, inertia_ratio), expected_x, rtol=1e-13
    )
    final = analytic.rolling_sphere_velocity(later, v0, mu, g, inertia_ratio)
    spin_final = analytic.rolling_sphere_angular_velocity(later, v0, mu, g, radius, inertia_ratio)
    np.testing.assert_allclose(final, spin_final * radius, rtol=1e-15)  # rolls without slip


def test_solid_sphere_keeps_five_sevenths_of_its_energy():
    # Limit check independent of the time history: rolling at 5 v0 / 7 with w = v / R keeps
    # (1/2 m v^2 + 1/2 (2/5 m R^2) w^2) / (1/2 m v0^2) = 5/7 of the energy.
    v0, mu, g, radius, mass = 2.0, 0.3, 9.81, 0.1, 1.7
    t = analytic.rolling_sphere_onset_time(v0, mu, g) * 2.0
    v = float(analytic.rolling_sphere_velocity(t, v0, mu, g))
    w = float(analytic.rolling_sphere_angular_velocity(t, v0, mu, g, radius))
    energy = 0.5 * mass * v**2 + 0.5 * 0.4 * mass * radius**2 * w**2
    assert energy / (0.5 * mass * v0**2) == pytest.approx(5.0 / 7.0, rel=1e-15)


# ---------------------------------------------------------------------------------------------
# Pendulum
# ---------------------------------------------------------------------------------------------


PENDULUM_RTOL = 1e-13  # tighter than RTOL: see test_pendulum_matches_integration


def _integrate_pendulum(theta0, omega0, tt):
    def rhs(_t, y):
        return [y[1], -(omega0**2) * math.sin(y[0])]

    def turns(_t, y):
        return y[1]

    # theta' first takes the sign of -theta0, and returns through zero at theta = -theta0.
    turns.direction = math.copysign(1.0, theta0)
    return solve_ivp(
        rhs,
        (0.0, tt[-1]),
        [theta0, 0.0],
        method="DOP853",
        rtol=PENDULUM_RTOL,
        atol=1e-16,
        t_eval=tt,
        events=turns,
    )


@pytest.mark.parametrize("theta0", [0.1, 2.0, 3.0, -1.0])
def test_pendulum_matches_integration(theta0):
    mass, length, g = 0.8, 0.6, 9.81
    # Uniform rod pivoted at one end: d = L / 2, I_p = m L^2 / 3.
    omega0 = analytic.physical_pendulum_frequency(mass, 0.5 * length, mass * length**2 / 3, g)
    assert omega0 == pytest.approx(math.sqrt(1.5 * g / length), rel=4 * EPS)
    period = analytic.pendulum_period(theta0, omega0)
    tt = np.linspace(0.0, 3.0 * period, 1501)
    sol = _integrate_pendulum(theta0, omega0, tt)
    # The difference is the integrator's global error: for theta0 = 3.0 (long dwell near the
    # top) it falls with rtol, 7.6e-8, 4.9e-9, 3.4e-10, 4.8e-11 of theta0 at rtol 1e-10 ... 1e-13,
    # while the analytic energy holds to 3e-13. At rtol 1e-13: 5e-11 worst case, 2e-12 for the
    # other amplitudes; 1e-9 leaves a factor 20.
    np.testing.assert_allclose(
        analytic.pendulum_angle(tt, theta0, omega0), sol.y[0], rtol=0, atol=1e-9 * abs(theta0)
    )
    np.testing.assert_allclose(
        analytic.pendulum_angular_velocity(tt, theta0, omega0),
        sol.y[1],
        rtol=0,
        atol=1e-9 * abs(theta0) * omega0,
    )
    # The turning points (theta' = 0 going up) come every period, the first at half a period.
    turns = sol.t_events[0]
    expected = 0.5 * period + period * np.arange(turns.size)
    # Same global-error argument (measured 2.4e-11 of the period for theta0 = 3.0 at rtol 1e-12).
    np.testing.assert_allclose(turns, expected, rtol=0, atol=1e-9 * period)


def test_pendulum_small_and_large_amplitude_limits():
    omega0 = analytic.simple_pendulum_frequency(2.0, 9.81)
    assert omega0 == pytest.approx(math.sqrt(9.81 / 2.0), rel=EPS)
    small = 1e-3
    # Series of the period: T = (2 pi / omega0)(1 + theta0^2 / 16 + 11 theta0^4 / 3072 + ...);
    # the next term is O(theta0^6) = 1e-18.
    series = 2 * math.pi / omega0 * (1 + small**2 / 16 + 11 * small**4 / 3072)
    assert analytic.pendulum_period(small, omega0) == pytest.approx(series, rel=1e-15)
    # Small angles, Lindstedt–Poincare: theta = a cos(w t) + a^3 / 192 (cos(w t) - cos(3 w t))
    # with w = omega0 (1 - a^2 / 16 + a^4 / 3072) (from the period series). Left out: O(a^5)
    # amplitude terms (1e-15 a) and the O(a^6) frequency term (1e-18 rad/rad, 2e-17 over the
    # ~19 rad sampled); 1e-13 a covers the round-off of the Jacobi functions.
    tt = np.linspace(0.0, 3.0 * 2 * math.pi / omega0, 301)
    phase = omega0 * (1 - small**2 / 16 + small**4 / 3072) * tt
    lindstedt = small * np.cos(phase) + small**3 / 192 * (np.cos(phase) - np.cos(3 * phase))
    np.testing.assert_allclose(
        analytic.pendulum_angle(tt, small, omega0), lindstedt, rtol=0, atol=1e-13 * small
    )
    # Near the top the period diverges like (4 / omega0) ln(8 / (pi - theta0)).
    near_top = math.pi - 1e-6
    asymptote = 4.0 / omega0 * math.log(8.0 / (math.pi - near_top))
    assert analytic.pendulum_period(near_top, omega0) == pytest.approx(asymptote, rel=1e-10)


def test_pendulum_energy_is_conserved_and_matches_rigid_body_energy():
    mass, d, g = 1.2, 0.4, 9.81
    inertia_com = 0.03
    inertia_pivot = inertia_com + mass * d**2
    omega0 = analytic.physical_pendulum_frequency(mass, d, inertia_pivot, g)
    theta0 = 2.5
    tt = np.linspace(0.0, 2.0 * analytic.pendulum_period(theta0, omega0), 400)
    theta = analytic.pendulum_angle(tt, theta0, omega0)
    rate = analytic.pendulum_angular_velocity(tt, theta0, omega0)
    energy = analytic.pendulum_energy(theta, rate, mass, d, inertia_pivot, g)
    initial = mass * g * d * (1.0 - math.cos(theta0))
    # Exact solution: the energy is constant up to round-off of Jacobi functions (~1e-15).
    np.testing.assert_allclose(energy, initial, rtol=1e-13)
    # The same body seen as a free rigid body (pivot at the origin, swinging in the x-z plane
    # about y): centre of mass at d (sin, -cos), speed d theta', body rate theta' about y.
    velocity = np.stack(
        (d * rate * np.cos(theta), np.zeros_like(tt), d * rate * np.sin(theta)), axis=-1
    )
    omega_body = np.stack((np.zeros_like(tt), rate, np.zeros_like(tt)), axis=-1)
    inertia_body = np.diag([0.05, inertia_com, 0.05])
    parts = analytic.rigid_body_energy(
        mass, inertia_body, velocity, omega_body, -d * np.cos(theta), g
    )
    # Parallel-axis theorem: equal up to the constant -m g d of the potential datum.
    np.testing.assert_allclose(parts.total + mass * g * d, energy, rtol=1e-13, atol=1e-13 * initial)


# ---------------------------------------------------------------------------------------------
# Torque-free rigid body
# ---------------------------------------------------------------------------------------------

MOMENTS = np.array([1.0, 2.0, 3.0])


def _euler_equations(moments):
    i1, i2, i3 = moments

    def rhs(_t, w):
        return [
            (i2 - i3) * w[1] * w[2] / i1,
            (i3 - i1) * w[2] * w[0] / i2,
            (i1 - i2) * w[0] * w[1] / i3,
        ]

    return rhs


@pytest.mark.parametrize(
    ("omega0", "axis"),
    [
        ([0.01, 1.0, 0.02], analytic.PolhodeAxis.MAJOR),  # Dzhanibekov, just on the major side
        ([0.02, 1.0, 0.01], analytic.PolhodeAxis.MINOR),  # Dzhanibekov, on the minor side
        ([-0.02, -1.0, 0.01], analytic.PolhodeAxis.MINOR),  # signs flipped
        ([1.0, 0.3, -0.2], analytic.PolhodeAxis.MINOR),
        ([0.2, -0.5, -2.0], analytic.PolhodeAxis.MAJOR),
    ],
)
def test_torque_free_matches_euler_equations(omega0, axis):
    polhode = analytic.torque_free_polhode(MOMENTS, omega0)
    assert polhode.encircled_axis == axis
    period = polhode.period
    tt = np.linspace(0.0, 3.0 * period, 1501)
    sol = solve_ivp(
        _euler_equations(MOMENTS),
        (0.0, tt[-1]),
        omega0,
        method="DOP853",
        rtol=RTOL,
        atol=1e-14,
        t_eval=tt,
    )
    scale = np.linalg.norm(omega0)
    # Measured: 2.4e-11 of |w0| for the minor-side flip case (m = 0.9999), where an error in
    # the flip time is amplified by the long dwell near the saddle; <= 4e-12 elsewhere. 1e-9
    # leaves a factor 40.
    np.testing.assert_allclose(
        analytic.torque_free_angular_velocity(tt, MOMENTS, omega0),
        sol.y.T,
        rtol=0,
        atol=1e-9 * scale,
    )


def test_torque_free_invariants_period_and_flip():
    omega0 = np.array([0.01, 1.0, 0.02])
    tt = np.linspace(-5.0, 80.0, 3001)
    omega = analytic.torque_free_angular_velocity(tt, MOMENTS, omega0)
    energy, momentum = analytic.torque_free_invariants(MOMENTS, omega)
    energy0, momentum0 = analytic.torque_free_invariants(MOMENTS, omega0)
    # Exact solution: invariants hold to round-off of the Jacobi functions.
    np.testing.assert_allclose(energy, energy0, rtol=1e-13)
    np.testing.assert_allclose(momentum, momentum0, rtol=1e-13)
    period = analytic.torque_free_period(MOMENTS, omega0)
    # Periodicity (the elliptic functions' own period 4K): round-off of u = lambda t + u0.
    np.testing.assert_allclose(
        analytic.torque_free_angular_velocity(period, MOMENTS, omega0), omega0, rtol=0, atol=1e-12
    )
    # The flip: after half a period w2 has reversed (the body turned upside down), w1 too.
    half = analytic.torque_free_angular_velocity(0.5 * period, MOMENTS, omega0)
    np.testing.assert_allclose(half, [-omega0[0], -omega0[1], omega0[2]], rtol=0, atol=1e-12)


def test_torque_free_small_wobble_limit():
    # Near-steady spin w3 about the major axis: linearised Euler equations give a wobble of
    # angular frequency w3 sqrt((I3 - I1)(I3 - I2) / (I1 I2)); the exact period differs by
    # O(epsilon^2) with epsilon = 1e-5 the relative wobble amplitude.
    spin, wobble = 2.0, 1e-5
    omega0 = [wobble * spin, 0.0, spin]
    i1, i2, i3 = MOMENTS
    linear = 2 * math.pi / (spin * math.sqrt((i3 - i1) * (i3 - i2) / (i1 * i2)))
    assert analytic.torque_free_period(MOMENTS, omega0) == pytest.approx(linear, rel=1e-9)


def test_torque_free_steady_rotations_and_misuse():
    tt = np.array([0.0, 1.0, 10.0])
    for steady in ([0.0, 0.0, 3.0], [0.0, -2.0, 0.0], [0.5, 0.0, 0.0], [0.0, 0.0, 0.0]):
        np.testing.assert_array_equal(
            analytic.torque_free_angular_velocity(tt, MOMENTS, steady), np.tile(steady, (3, 1))
        )
    with pytest.raises(ValueError, match="I1 < I2 < I3"):
        analytic.torque_free_polhode([2.0, 1.0, 3.0], [1.0, 0.0, 0.0])
    with pytest.raises(ValueError, match="triangle"):
        analytic.torque_free_polhode([1.0, 2.0, 5.0], [1.0, 0.0, 0.0])


# ---------------------------------------------------------------------------------------------
# Slider–crank
# ---------------------------------------------------------------------------------------------


@pytest.mark.parametrize("offset", [0.0, 0.03, -0.05])
def test_slider_crank_closes_the_loop_and_its_derivatives_integrate_back(offset):
    l1, l2, omega, phi0 = 0.1, 0.35, 25.0, 0.4
    tt = np.linspace(0.0, 2.0 * 2 * math.pi / omega, 401)
    motion = analytic.slider_crank_motion(tt, l1, l2, omega, offset=offset, crank_angle0=phi0)
    # Independent position: root of the loop-closure |slider - pin| = l2 on the +x branch.
    position = np.empty_like(tt)
    for i, phi in enumerate(motion.crank_angle):
        pin = l1 * np.array([math.cos(phi), math.sin(phi)])

        def closure(x, pin=pin):
            return (x - pin[0]) ** 2 + (offset - pin[1]) ** 2 - l2**2

        position[i] = brentq(closure, pin[0], pin[0] + l2, xtol=1e-15, rtol=4 * EPS)
    np.testing.assert_allclose(motion.slider_position, position, rtol=1e-13)  # brentq to ~eps
    pin_x = l1 * np.cos(motion.crank_angle)
    pin_y = l1 * np.sin(motion.crank_angle)
    np.testing.assert_allclose(pin_x + l2 * np.cos(motion.rod_angle), position, rtol=1e-13)
    np.testing.assert_allclose(
        pin_y + l2 * np.sin(motion.rod_angle), offset, rtol=0, atol=1e-15 * l2 * 10
    )  # a few round-offs of l2

    # Integrate the closed-form accelerations twice from the closed-form initial state: the
    # result must reproduce the closed-form velocities and positions (catches any wrong sign
    # or factor in x', x'', psi', psi''). rtol 1e-12 on a smooth periodic signal over two
    # turns: measured <= 1e-11 of l1 (position) and <= 2.5e-12 in the scaled velocity and angle;
    # 1e-9 leaves a factor >= 100.
    def rhs(t, y):
        m = analytic.slider_crank_motion(t, l1, l2, omega, offset=offset, crank_angle0=phi0)
        return [y[1], m.slider_acceleration, y[3], m.rod_angular_acceleration]

    y0 = [
        motion.slider_position[0],
        motion.slider_velocity[0],
        motion.rod_angle[0],
        motion.rod_angular_velocity[0],
    ]
    sol = solve_ivp(rhs, (0.0, tt[-1]), y0, method="DOP853", rtol=RTOL, atol=1e-14, t_eval=tt)
    np.testing.assert_allclose(sol.y[0], motion.slider_position, rtol=0, atol=1e-9 * l1)
    np.testing.assert_allclose(sol.y[1], motion.slider_velocity, rtol=0, atol=1e-9 * l1 * omega)
    np.testing.assert_allclose(sol.y[2], motion.rod_angle, rtol=0, atol=1e-9)
    np.testing.assert_allclose(sol.y[3], motion.rod_angular_velocity, rtol=0, atol=1e-9 * omega)


def test_slider_crank_dead_centres_and_long_rod_limit():
    l1, l2, offset = 0.1, 0.35, 0.04
    inner, outer = analytic.slider_crank_dead_centres(l1, l2, offset)

    def slider(phi):
        return float(analytic.slider_crank_motion(phi, l1, l2, 1.0, offset=offset).slider_position)

    # Independent extremes: Brent's bounded search over the crank angle (unit crank speed, so
    # t = phi). At an extremum x is flat, so an angle error of xatol = 1e-9 costs ~l1 * 1e-18:
    # the found values are exact to round-off of x (~1e-16 l2).
    grid = np.linspace(0.0, 2 * math.pi, 361)
    x_grid = analytic.slider_crank_motion(grid, l1, l2, 1.0, offset=offset).slider_position
    found = []
    for index, sign in ((np.argmin(x_grid), 1.0), (np.argmax(x_grid), -1.0)):
        bracket = (grid[index] - 0.02, grid[index] + 0.02)
        best = minimize_scalar(
            lambda phi, s=sign: s * slider(phi),
            bounds=bracket,
            method="bounded",
            options={"xatol": 1e-9},
        )
        found.append(slider(best.x))
    assert found[0] == pytest.approx(inner, rel=1e-14)
    assert found[1] == pytest.approx(outer, rel=1e-14)
    phi = np.linspace(0.0, 2 * math.pi, 201)
    inner_centred, outer_centred = analytic.slider_crank_dead_centres(l1, l2)
    assert outer_centred - inner_centred == pytest.approx(2 * l1, rel=1e-15)  # stroke, offset 0
    # Long rod, no offset: x = l1 cos(phi) + l2 - l1^2 sin^2(phi) / (2 l2) - l1^4 sin^4(phi) /
    # (8 l2^3) - ...; the bound l1^4 / l2^3 is 8 times the first neglected term's maximum.
    long_rod = 100.0 * l1
    x_long = analytic.slider_crank_motion(phi, l1, long_rod, 1.0).slider_position
    approx = l1 * np.cos(phi) + long_rod - l1**2 * np.sin(phi) ** 2 / (2 * long_rod)
    np.testing.assert_allclose(x_long, approx, rtol=0, atol=l1**4 / long_rod**3)
    with pytest.raises(ValueError, match="rod_length"):
        analytic.slider_crank_motion([0.0], 0.1, 0.12, 1.0, offset=0.05)


# ---------------------------------------------------------------------------------------------
# Housner rocking block
# ---------------------------------------------------------------------------------------------


def _simulate_rocking(theta0, alpha, p, ratio, n_impacts, linearised):
    """Event-driven rocking: pivot about the corner on the side of the tilt, and at each
    theta = 0 event multiply the angular velocity by Housner's ratio and switch corner."""

    def rhs(_t, y):
        side = y[2]
        if linearised:
            return [y[1], -(p**2) * (side * alpha - y[0]), 0.0]
        return [y[1], -side * p**2 * math.sin(alpha - side * y[0]), 0.0]

    def upright(_t, y):
        return y[0]

    upright.terminal = True

    def apex(_t, y):
        return y[1]

    t, state = 0.0, [theta0, 0.0, math.copysign(1.0, theta0)]
    impacts, apexes, segments = [], [theta0], []
    for k in range(n_impacts):
        upright.direction = -state[2]  # crossing back through zero from the current side
        sol = solve_ivp(
            rhs,
            (t, t + 100.0 / p),
            state,
            method="DOP853",
            rtol=RTOL,
            atol=1e-15,
            events=(upright, apex),
            dense_output=True,
        )
        t_hit, y_hit = sol.t_events[0][0], sol.y_events[0][0]
        if k > 0:
            apexes.append(sol.y_events[1][0][0])
        impacts.append(t_hit)
        segments.append((t, t_hit, sol.sol))
        t, state = t_hit, [0.0, ratio * y_hit[1], -state[2]]
    return np.array(impacts), np.array(apexes), segments


@pytest.mark.parametrize("linearised", [False, True])
@pytest.mark.parametrize("release_fraction", [0.8, -0.3])
def test_rocking_block_matches_event_driven_integration(linearised, release_fraction):
    half_width, half_height, g = 0.1, 0.5, 9.81
    alpha = analytic.rocking_block_slenderness(half_width, half_height)
    p = analytic.rocking_block_frequency(half_width, half_height, g)
    ratio = analytic.rocking_block_velocity_ratio(alpha)
    theta0, n = release_fraction * alpha, 6
    impacts, apexes, segments = _simulate_rocking(theta0, alpha, p, ratio, n, linearised)
    mode = {"linearised": linearised}
    # Smooth segments at rtol 1e-12 and ~4 eps event location per impact: measured <= 3.4e-12
    # relative on the impact times, <= 2e-12 theta0 on the apexes, <= 6e-12 of theta0 (angle)
    # and of the first impact speed (angular velocity) along the segments; 1e-10 leaves a
    # factor >= 17.
    np.testing.assert_allclose(
        analytic.rocking_block_impact_times(theta0, alpha, p, n, **mode), impacts, rtol=1e-10
    )
    np.testing.assert_allclose(
        analytic.rocking_block_amplitudes(theta0, alpha, n - 1, **mode),
        apexes,
        rtol=0,
        atol=1e-10 * abs(theta0),
    )
    speed0 = float(analytic.rocking_block_impact_speed(theta0, alpha, p, **mode))
    for start, end, dense in segments:
        tt = np.linspace(start, end, 60)[1:-1]  # interior: impacts switch the velocity
        ref = dense(tt)
        np.testing.assert_allclose(
            analytic.rocking_block_angle(tt, theta0, alpha, p, **mode),
            ref[0],
            rtol=0,
            atol=1e-10 * abs(theta0),
        )
        np.testing.assert_allclose(
            analytic.rocking_block_angular_velocity(tt, theta0, alpha, p, **mode),
            ref[1],
            rtol=0,
            atol=1e-10 * speed0,
        )
    # The first impact speed equals the integrated pre-impact speed (energy argument);
    # measured <= 1.1e-14 relative, 1e-12 leaves a factor ~90.
    first_impact_speed = abs(segments[0][2](impacts[0])[1])
    assert speed0 == pytest.approx(first_impact_speed, rel=1e-12)


def test_rocking_block_parameters_and_slender_limit():
    half_width, half_height, g = 0.05, 1.0, 9.81
    alpha = analytic.rocking_block_slenderness(half_width, half_height)
    assert alpha == pytest.approx(math.atan(0.05), rel=EPS)
    p = analytic.rocking_block_frequency(half_width, half_height, g)
    assert p == pytest.approx(math.sqrt(3 * g / (4 * math.hypot(0.05, 1.0))), rel=2 * EPS)
    # Slender block: exact and linearised fall times agree to O(alpha^2) ~ 2.5e-3 relative.
    theta0 = 0.5 * alpha
    exact = float(analytic.rocking_block_fall_time(theta0, alpha, p))
    linear = float(analytic.rocking_block_fall_time(theta0, alpha, p, linearised=True))
    assert exact == pytest.approx(linear, rel=alpha**2)
    assert linear == pytest.approx(math.acosh(2.0) / p, rel=4 * EPS)  # alpha / (alpha - a/2) = 2
    # Velocity ratio: 1 - 1.5 sin^2(alpha); zero at asin(sqrt(2/3)).
    assert analytic.rocking_block_velocity_ratio(math.asin(math.sqrt(2 / 3))) == pytest.approx(
        0.0, abs=4 * EPS
    )


def test_rocking_block_rests_after_accumulated_impacts():
    alpha, p = 0.2, 3.0
    theta0 = 0.15
    ratio = analytic.rocking_block_velocity_ratio(alpha)
    # The apex energy ratio per impact is r^2 (exact model): check it on the amplitudes.
    amps = np.abs(analytic.rocking_block_amplitudes(theta0, alpha, 10))
    energy = np.cos(alpha - amps) - math.cos(alpha)
    np.testing.assert_allclose(energy[1:] / energy[:-1], ratio**2, rtol=1e-12)  # round-off
    # Impacts accumulate: after enough time the block rests upright.
    impacts = analytic.rocking_block_impact_times(theta0, alpha, p, 2000)
    tt = np.linspace(0.0, impacts[-1] + 5.0, 20001)
    theta = analytic.rocking_block_angle(tt, theta0, alpha, p)
    assert np.all(theta[tt > impacts[-1] + 1.0] == 0.0)
    assert np.all(np.abs(theta) <= theta0 * (1 + 1e-12))  # never beyond the release tilt
    # A wide block (r <= 0) stops at its first impact.
    wide = 1.0
    theta_wide = analytic.rocking_block_angle([0.0, 10.0], 0.5, wide, p)
    assert theta_wide[0] == 0.5 and theta_wide[1] == 0.0


def test_rocking_block_schedule_is_consistent_across_chunks():
    # A slender block (r = 0.9963) needs more impacts than one 4096-impact chunk of the internal
    # schedule: the trajectory must still vanish at every impact and reach the apex amplitudes
    # midway between impacts.
    alpha, p, theta0, n = 0.05, 4.0, 0.04, 6000
    impacts = analytic.rocking_block_impact_times(theta0, alpha, p, n)
    amplitudes = analytic.rocking_block_amplitudes(theta0, alpha, n - 1)
    # At an impact instant the angle is the impact speed times the round-off of that instant
    # within its half-cycle (differences of impact times: a few ulps of t <= impacts[-1]);
    # 8 ulps of the largest time at the largest speed bounds it (measured 4.9e-15 rad).
    speed = float(analytic.rocking_block_impact_speed(theta0, alpha, p))
    np.testing.assert_allclose(
        analytic.rocking_block_angle(impacts, theta0, alpha, p),
        0.0,
        rtol=0,
        atol=8 * EPS * impacts[-1] * speed,
    )
    midpoints = 0.5 * (impacts[:-1] + impacts[1:])
    # At the apex the angle is flat in time: only round-off of the apex amplitude remains.
    np.testing.assert_allclose(
        analytic.rocking_block_angle(midpoints, theta0, alpha, p),
        amplitudes[1:],
        rtol=0,
        atol=1e-13 * theta0,
    )


def test_functions_keep_the_shape_of_their_time_argument():
    tt = np.linspace(0.0, 1.0, 6).reshape(2, 3)
    assert analytic.bouncing_ball_height(tt, 1.0, 9.81, 0.5).shape == (2, 3)
    assert analytic.sliding_box_position(tt, 1.0, 0.3, 9.81).shape == (2, 3)
    assert analytic.rolling_sphere_angular_velocity(tt, 1.0, 0.3, 9.81, 0.1).shape == (2, 3)
    assert analytic.incline_block_displacement(tt, 0.4, 0.1, 9.81).shape == (2, 3)
    assert analytic.pendulum_angle(tt, 1.0, 3.0).shape == (2, 3)
    assert analytic.rocking_block_angle(tt, 0.1, 0.2, 3.0).shape == (2, 3)
    assert analytic.slider_crank_motion(tt, 0.1, 0.3, 5.0).slider_acceleration.shape == (2, 3)
    assert analytic.torque_free_angular_velocity(tt, MOMENTS, [0.1, 1.0, 0.1]).shape == (2, 3, 3)
    assert float(analytic.bouncing_ball_height(0.0, 1.0, 9.81, 0.5)) == 1.0  # scalar in


# ---------------------------------------------------------------------------------------------
# Energy helper
# ---------------------------------------------------------------------------------------------


def test_rigid_body_energy_is_frame_consistent_and_vectorised():
    rng = np.random.default_rng(7)
    mass, g = 2.5, 9.81
    half = rng.normal(size=(3, 3))
    inertia = half @ half.T + 3.0 * np.eye(3)  # symmetric positive definite, body axes
    velocity = rng.normal(size=(50, 3))
    omega_body = rng.normal(size=(50, 3))
    height = rng.normal(size=50)
    parts = analytic.rigid_body_energy(mass, inertia, velocity, omega_body, height, g)
    assert parts.total.shape == (50,)
    # Rotational energy is frame independent: with a rotation R (body -> world),
    # w_world = R w_body and I_world = R I R^T give the same value (to round-off).
    rotation, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    omega_world = omega_body @ rotation.T
    inertia_world = rotation @ inertia @ rotation.T
    world = 0.5 * np.einsum("ti,ij,tj->t", omega_world, inertia_world, omega_world)
    np.testing.assert_allclose(parts.rotational, world, rtol=1e-13)
    np.testing.assert_allclose(parts.potential, mass * g * height, rtol=EPS)
    # Diagonal inertia: the rotational part is the torque-free kinetic energy.
    diagonal = np.diag(MOMENTS)
    kinetic, _ = analytic.torque_free_invariants(MOMENTS, omega_body)
    rotational = analytic.rigid_body_energy(mass, diagonal, velocity, omega_body, height, g)
    np.testing.assert_allclose(rotational.rotational, kinetic, rtol=1e-15)
    with pytest.raises(ValueError, match="mass"):
        analytic.rigid_body_energy(-1.0, inertia, velocity, omega_body, height, g)
