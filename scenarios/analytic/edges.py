"""Analytic reference for a body crossing the bound of a face: a hoop sliding off a plate's edge.

Hoop over a sharp edge (frictionless)
-------------------------------------
A thin hoop (a ring, a curve of radius ``r``) stands in a vertical plane on a horizontal face
and slides without friction, without spin, at speed ``v0`` toward the face's straight edge
(perpendicular to the hoop's plane), its lowest point at distance ``a`` from the edge at
t = 0, under gravity ``g``. Frictionless, every contact force on the hoop passes through its
centre, so the hoop never spins and its centre moves as a point mass:

1. sliding, 0 <= t < t0 = a / v0: the centre moves at v0 along the face;
2. pivoting, t0 <= t < t1: the lowest point has reached the edge point E; the hoop stays on
   it, so the centre moves on the circle of radius r about E. With theta the angle of the
   centre from the vertical through E, ``r theta'' = g sin(theta)`` from theta = 0,
   theta' = v0 / r, and the contact force ``N = m (g cos(theta) - r theta'^2)`` with energy
   ``r^2 theta'^2 = v0^2 + 2 g r (1 - cos(theta))``. The hoop leaves the edge where N = 0:
   ``cos(theta1) = (2 + v0^2 / (g r)) / 3`` (a closed form; at v0^2 >= g r it leaves at once);
   the time to get there, ``t1 - t0 = integral_0^theta1 r dtheta / sqrt(v0^2 + 2 g r (1 -
   cos(theta)))``, is an elliptic integral, evaluated here by quadrature;
3. flying, t >= t1: free flight from the leaving state (the hoop moves away from the edge:
   :func:`hoop_over_edge_path` checks that the edge stays outside the hoop).

All functions are unit-agnostic (any consistent units; angles in radians).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import integrate

from clearbench.scenarios.analytic.common import as_times, require_non_negative, require_positive


def hoop_over_edge_leave_angle(v0: float, radius: float, g: float) -> float:
    """Angle theta1 [rad] of the hoop's centre from the vertical through the edge when it
    leaves the edge: ``arccos((2 + v0^2 / (g r)) / 3)``, 0 when ``v0^2 >= g r`` (the edge
    cannot hold the hoop on a circle at that speed)."""
    require_positive("v0", v0)
    require_positive("radius", radius)
    require_positive("g", g)
    cosine = (2.0 + v0 * v0 / (g * radius)) / 3.0
    return 0.0 if cosine >= 1.0 else math.acos(cosine)


def _pivot_rate(theta, v0: float, radius: float, g: float):
    """theta' [1/T] on the pivot from the energy: r^2 theta'^2 = v0^2 + 2 g r (1 - cos)."""
    return np.sqrt(v0 * v0 + 2.0 * g * radius * (1.0 - np.cos(theta))) / radius


def hoop_over_edge_pivot_time(v0: float, radius: float, g: float) -> float:
    """Duration t1 - t0 [T] of the pivot about the edge, by quadrature of dt = dtheta /
    theta'(theta) from 0 to the leave angle (relative error below 1e-12)."""
    leave = hoop_over_edge_leave_angle(v0, radius, g)
    if leave == 0.0:
        return 0.0
    value, _ = integrate.quad(lambda theta: 1.0 / _pivot_rate(theta, v0, radius, g), 0.0,
                              leave, epsabs=0.0, epsrel=1e-13)
    return float(value)


@dataclass(frozen=True)
class HoopOverEdge:
    """The hoop's exact motion: times of the phases [T], the leave angle [rad], and the
    centre's displacement from its initial position, (..., 2) [L]: along the motion
    (horizontal, toward the edge) and up (against gravity); ``on_edge`` marks the pivot."""

    pivot_start: float
    leave_time: float
    leave_angle: float
    displacement: np.ndarray
    on_edge: np.ndarray


def hoop_over_edge_path(t, v0: float, radius: float, g: float, edge_distance: float
                        ) -> HoopOverEdge:
    """The centre's path at times ``t`` (array_like, >= 0).

    Parameters
    ----------
    t : array_like
        Times [T] from the release.
    v0 : float
        Initial sliding speed [L/T], > 0.
    radius : float
        Hoop radius r [L].
    g : float
        Magnitude of gravity [L/T^2].
    edge_distance : float
        Distance a [L] of the hoop's lowest point from the edge at t = 0, >= 0.

    Returns
    -------
    HoopOverEdge
        ``displacement[..., 0]`` along the motion, ``[..., 1]`` up; the pivot's angle comes
        from integrating ``r theta'' = g sin(theta)`` (explicit Runge-Kutta of order 8,
        DOP853, relative tolerance 1e-12) over the quadrature's pivot time.
    """
    times = as_times(t)
    require_non_negative("edge_distance", edge_distance)
    leave = hoop_over_edge_leave_angle(v0, radius, g)
    start = edge_distance / v0
    duration = hoop_over_edge_pivot_time(v0, radius, g)
    # Centre relative to its start: E is at (a, -r) in (along, up).
    edge = np.array([edge_distance, -radius])
    out = np.empty(times.shape + (2,))
    sliding = times < start
    out[sliding] = np.stack([v0 * times[sliding], np.zeros(np.count_nonzero(sliding))], -1)
    pivoting = (times >= start) & (times < start + duration)
    if np.any(pivoting):
        solution = integrate.solve_ivp(
            lambda _, y: (y[1], g / radius * math.sin(y[0])), (0.0, duration),
            (0.0, v0 / radius), method="DOP853", rtol=1e-12, atol=1e-14, dense_output=True)
        theta = solution.sol(times[pivoting] - start)[0]
        out[pivoting] = edge + radius * np.stack([np.sin(theta), np.cos(theta)], -1)
    flying = ~(sliding | pivoting)
    rate = _pivot_rate(leave, v0, radius, g)
    position = edge + radius * np.array([math.sin(leave), math.cos(leave)])
    velocity = radius * rate * np.array([math.cos(leave), -math.sin(leave)])
    tau = times[flying] - (start + duration)
    out[flying] = position + tau[:, None] * velocity + np.stack(
        [np.zeros_like(tau), -0.5 * g * tau**2], -1)
    return HoopOverEdge(start, start + duration, leave, out, pivoting)
