"""Analytic references for impact scenes: the bouncing ball and Housner's rocking block.

Every function is unit-agnostic: give lengths, times and accelerations in one consistent system
(SI: m, s, m/s^2; or mm, ms, mm/ms^2 ...) and the results come back in that system. Angles are
in radians. Time arguments are array_like of any shape and the result has the same shape.

Bouncing ball
-------------
A ball is dropped from rest with its lowest point at height ``h0`` above a fixed plane, under
gravity ``g``, and rebounds by Newton's impact law with restitution ``e`` in [0, 1): the normal
velocity after an impact is ``-e`` times the one before. With ``v0 = sqrt(2 g h0)`` the k-th
impact (k >= 1) happens at ``t_k = (v0/g) (1 + 2 e (1 - e^(k-1)) / (1 - e))``, the k-th apex is
``e^(2k) h0``, and the impacts accumulate at ``t_inf = (v0/g) (1 + e) / (1 - e)`` after which the
ball rests on the plane (Zeno behaviour). With e = 0 it rests from the first impact on.

Rocking block (Housner 1963)
----------------------------
A uniform rectangular block of half-width ``b`` and half-height ``h`` stands on a rigid plane
and rocks about one bottom corner, then about the other. ``alpha = atan(b / h)`` is its
slenderness angle, ``R = sqrt(b^2 + h^2)`` the half-diagonal, ``p = sqrt(3 g / (4 R))`` the
frequency parameter (the inertia about a corner is ``I_O = 4/3 m R^2``). ``theta`` is the tilt
angle, positive while the block rotates about its right corner. Between impacts, about the
right corner, the exact equation is ``theta'' = -p^2 sin(alpha - theta)`` (Housner's linearised
version ``theta'' = -p^2 (alpha - theta)`` holds for slender blocks, alpha << 1). Assumptions:

* friction is large enough that the pivoting corner never slides;
* the impact is a point impact at the new corner, perfectly inelastic there (no bouncing, no
  lift-off), and the block then rotates about the new corner;
* angular momentum about the new corner is conserved through the impact, which gives the
  ratio of angular velocities after / before ``r = 1 - 1.5 sin^2(alpha)``.

For ``alpha >= asin(sqrt(2/3))`` (about 54.7 degrees) the formula gives ``r <= 0``: no rocking
about the new corner is possible and the trajectories here rest after the first impact.

A block released from rest at ``0 < |theta0| < alpha`` falls back to theta = 0, impacts, rises
on the other corner with reduced energy, and so on; the amplitudes decrease and the impacts
accumulate at a finite time after which the block rests (theta = 0).
"""

from __future__ import annotations

import math

import numpy as np

from clearbench.scenarios.analytic.common import (
    as_times,
    require_in_interval,
    require_non_negative,
    require_positive,
)

__all__ = [
    "bouncing_ball_apex_heights",
    "bouncing_ball_apex_times",
    "bouncing_ball_height",
    "bouncing_ball_impact_speed",
    "bouncing_ball_impact_times",
    "bouncing_ball_rest_time",
    "bouncing_ball_velocity",
    "rocking_block_amplitudes",
    "rocking_block_angle",
    "rocking_block_angular_velocity",
    "rocking_block_fall_time",
    "rocking_block_frequency",
    "rocking_block_impact_speed",
    "rocking_block_impact_times",
    "rocking_block_slenderness",
    "rocking_block_velocity_ratio",
]

# ---------------------------------------------------------------------------------------------
# Bouncing ball
# ---------------------------------------------------------------------------------------------


def _check_ball(h0: float, g: float, restitution: float) -> tuple[float, float, float]:
    return (
        require_non_negative("h0", h0),
        require_positive("g", g),
        require_in_interval("restitution", restitution, 0.0, 1.0),
    )


def bouncing_ball_impact_speed(h0: float, g: float) -> float:
    """Speed of the first impact of a ball dropped from rest, ``v0 = sqrt(2 g h0)``.

    Parameters
    ----------
    h0 : float
        Initial height of the ball's lowest point above the plane [length], >= 0.
    g : float
        Magnitude of gravity [length / time^2], > 0.

    Returns
    -------
    float
        Impact speed [length / time].
    """
    return math.sqrt(2.0 * require_positive("g", g) * require_non_negative("h0", h0))


def bouncing_ball_apex_heights(h0: float, restitution: float, n_bounces: int) -> np.ndarray:
    """Heights of the apexes, ``e^(2k) h0`` for k = 0..n_bounces.

    Parameters
    ----------
    h0 : float
        Release height of the ball's lowest point above the plane [length] (apex 0).
    restitution : float
        Newton restitution coefficient e, in [0, 1).
    n_bounces : int
        Number of rebounds, >= 0.

    Returns
    -------
    ndarray, shape (n_bounces + 1,)
        Apex heights [length]; entry k is the apex after the k-th impact.
    """
    h0 = require_non_negative("h0", h0)
    restitution = require_in_interval("restitution", restitution, 0.0, 1.0)
    if n_bounces < 0:
        raise ValueError(f"n_bounces = {n_bounces!r}: must be >= 0")
    return h0 * restitution ** (2.0 * np.arange(n_bounces + 1))


def bouncing_ball_impact_times(
    h0: float, g: float, restitution: float, n_impacts: int
) -> np.ndarray:
    """Times of the first ``n_impacts`` impacts.

    ``t_k = (v0/g) (1 + 2 e (1 - e^(k-1)) / (1 - e))`` for k = 1..n_impacts. With e = 0 every
    entry equals the first impact time, at which the ball comes to rest.

    Parameters
    ----------
    h0 : float
        Release height of the ball's lowest point above the plane [length], >= 0.
    g : float
        Magnitude of gravity [length / time^2], > 0.
    restitution : float
        Newton restitution coefficient e, in [0, 1).
    n_impacts : int
        Number of impacts, >= 0.

    Returns
    -------
    ndarray, shape (n_impacts,)
        Impact times [time], increasing, all below :func:`bouncing_ball_rest_time`.
    """
    h0, g, e = _check_ball(h0, g, restitution)
    if n_impacts < 0:
        raise ValueError(f"n_impacts = {n_impacts!r}: must be >= 0")
    v0 = math.sqrt(2.0 * g * h0)
    k = np.arange(1, n_impacts + 1, dtype=float)
    # Sum of the flight times written without cancellation: all terms are >= 0.
    return (v0 / g) * (1.0 + 2.0 * e * (1.0 - e ** (k - 1.0)) / (1.0 - e))


def bouncing_ball_apex_times(h0: float, g: float, restitution: float, n_bounces: int) -> np.ndarray:
    """Times of the apexes: 0 for the release, then ``t_k + e^k v0 / g`` after impact k.

    Parameters
    ----------
    h0, g, restitution : float
        As in :func:`bouncing_ball_impact_times`.
    n_bounces : int
        Number of rebounds, >= 0.

    Returns
    -------
    ndarray, shape (n_bounces + 1,)
        Apex times [time]; entry k matches entry k of :func:`bouncing_ball_apex_heights`.
    """
    h0, g, e = _check_ball(h0, g, restitution)
    impacts = bouncing_ball_impact_times(h0, g, e, n_bounces)
    v0 = math.sqrt(2.0 * g * h0)
    k = np.arange(1, n_bounces + 1, dtype=float)
    return np.concatenate(([0.0], impacts + e**k * v0 / g))


def bouncing_ball_rest_time(h0: float, g: float, restitution: float) -> float:
    """Accumulation time of the impacts, ``t_inf = (v0/g) (1 + e) / (1 - e)``.

    Parameters
    ----------
    h0, g, restitution : float
        As in :func:`bouncing_ball_impact_times`.

    Returns
    -------
    float
        Time [time] from which the ball rests on the plane.
    """
    h0, g, e = _check_ball(h0, g, restitution)
    return math.sqrt(2.0 * g * h0) / g * (1.0 + e) / (1.0 - e)


def _ball_flight(t: np.ndarray, h0: float, g: float, e: float):
    """Per time sample: post-impact speed of the current flight and the time since its start.

    Returns ``(launch_speed, time_in_flight, phase)`` with phase 0 for the initial drop (launch
    speed 0, time since release), 1 for a rebound flight, 2 for rest.
    """
    v0 = math.sqrt(2.0 * g * h0)
    first_impact = v0 / g
    rest_time = first_impact * (1.0 + e) / (1.0 - e)
    launch = np.zeros_like(t)
    elapsed = t.copy()
    phase = np.where(t < first_impact, 0, np.where(t < rest_time, 1, 2))
    flying = phase == 1
    if e > 0.0 and np.any(flying):
        # The k-th impact happens when the remaining time t_inf - t equals C e^k with
        # C = 2 v0 / (g (1 - e)); so in flight k, e^(k+1) < (t_inf - t) / C <= e^k.
        scale = 2.0 * v0 / (g * (1.0 - e))
        remaining = rest_time - t[flying]
        k = np.floor(np.log(remaining / scale) / math.log(e))
        k = np.maximum(k, 1.0)
        tau = scale * e**k - remaining
        # Round-off at a flight boundary: move to the neighbouring flight.
        k = np.where(tau < 0.0, k - 1.0, k)
        k = np.maximum(k, 1.0)
        flight_time = 2.0 * e**k * v0 / g
        tau = scale * e**k - remaining
        k = np.where(tau >= flight_time, k + 1.0, k)
        tau = np.where(tau >= flight_time, scale * e**k - remaining, tau)
        launch[flying] = e**k * v0
        elapsed[flying] = np.maximum(tau, 0.0)
    return launch, elapsed, phase


def bouncing_ball_height(t, h0: float, g: float, restitution: float) -> np.ndarray:
    """Exact height of the ball's lowest point above the plane, z(t).

    Piecewise parabolas: ``h0 - g t^2 / 2`` until the first impact, then
    ``e^k v0 tau - g tau^2 / 2`` with tau the time since impact k, and 0 from ``t_inf`` on.

    Parameters
    ----------
    t : array_like, any shape
        Times since the release [time], >= 0.
    h0, g, restitution : float
        As in :func:`bouncing_ball_impact_times`.

    Returns
    -------
    ndarray, same shape as ``t``
        Height [length], >= 0.
    """
    h0, g, e = _check_ball(h0, g, restitution)
    times = as_times(t)
    launch, elapsed, phase = _ball_flight(times, h0, g, e)
    drop = h0 - 0.5 * g * times**2
    rebound = launch * elapsed - 0.5 * g * elapsed**2
    height = np.where(phase == 0, drop, np.where(phase == 1, rebound, 0.0))
    return np.maximum(height, 0.0)


def bouncing_ball_velocity(t, h0: float, g: float, restitution: float) -> np.ndarray:
    """Exact vertical velocity of the ball, dz/dt (upwards positive), right-continuous.

    At an impact instant the post-impact velocity is returned.

    Parameters
    ----------
    t : array_like, any shape
        Times since the release [time], >= 0.
    h0, g, restitution : float
        As in :func:`bouncing_ball_impact_times`.

    Returns
    -------
    ndarray, same shape as ``t``
        Vertical velocity [length / time].
    """
    h0, g, e = _check_ball(h0, g, restitution)
    times = as_times(t)
    launch, elapsed, phase = _ball_flight(times, h0, g, e)
    return np.where(phase == 0, -g * times, np.where(phase == 1, launch - g * elapsed, 0.0))


# ---------------------------------------------------------------------------------------------
# Rocking block
# ---------------------------------------------------------------------------------------------

#: Largest slenderness for which Housner's velocity ratio is positive, asin(sqrt(2/3)).
_ALPHA_RATIO_ZERO = math.asin(math.sqrt(2.0 / 3.0))
#: Impacts are generated in chunks of this size until the requested time is covered.
_IMPACT_CHUNK = 4096
#: Refuse to build more impacts than this (only blocks with alpha < ~1e-3 rad come near it).
_MAX_IMPACTS = 1 << 23


def rocking_block_slenderness(half_width: float, half_height: float) -> float:
    """Slenderness angle ``alpha = atan(b / h)`` of a rectangular block [rad].

    Parameters
    ----------
    half_width : float
        Half-width b [length], > 0.
    half_height : float
        Half-height h [length], > 0.
    """
    return math.atan2(
        require_positive("half_width", half_width), require_positive("half_height", half_height)
    )


def rocking_block_frequency(half_width: float, half_height: float, g: float) -> float:
    """Frequency parameter ``p = sqrt(3 g / (4 R))`` with ``R = sqrt(b^2 + h^2)`` [1 / time].

    Parameters
    ----------
    half_width, half_height : float
        Half-width b and half-height h of the block [length], > 0.
    g : float
        Magnitude of gravity [length / time^2], > 0.
    """
    half_diagonal = math.hypot(
        require_positive("half_width", half_width), require_positive("half_height", half_height)
    )
    return math.sqrt(3.0 * require_positive("g", g) / (4.0 * half_diagonal))


def rocking_block_velocity_ratio(alpha: float) -> float:
    """Housner's ratio of angular velocities after / before an impact, ``1 - 1.5 sin^2 alpha``.

    From conservation of angular momentum about the new pivot corner (uniform rectangular
    block, point impact, no sliding, no bouncing; see the module docstring). It is <= 0 for
    alpha >= asin(sqrt(2/3)), where the model predicts no further rocking.

    Parameters
    ----------
    alpha : float
        Slenderness angle [rad], in (0, pi/2).

    Returns
    -------
    float
        Ratio r (dimensionless); the kinetic energy ratio per impact is r^2.
    """
    alpha = require_in_interval("alpha", alpha, 0.0, 0.5 * math.pi)
    return 1.0 - 1.5 * math.sin(alpha) ** 2


def _check_block(alpha: float, p: float) -> tuple[float, float]:
    alpha = require_in_interval("alpha", alpha, 0.0, 0.5 * math.pi)
    if alpha == 0.0:
        raise ValueError("alpha = 0.0: must be > 0")
    return alpha, require_positive("p", p)


def _check_amplitude(name: str, amplitude, alpha: float) -> np.ndarray:
    values = np.asarray(amplitude, dtype=float)
    if not np.all(np.isfinite(values)) or np.any(np.abs(values) >= alpha):
        raise ValueError(f"{name} = {amplitude!r}: |{name}| must be < alpha = {alpha!r}")
    return values


def _exact_modulus(amplitude: np.ndarray, alpha: float) -> np.ndarray:
    """Parameter m = k^2 of the inverted-pendulum motion from rest at ``amplitude``."""
    return np.cos(0.5 * (alpha - amplitude)) ** 2


def rocking_block_fall_time(
    amplitude, alpha: float, p: float, *, linearised: bool = False
) -> np.ndarray:
    """Time for the block to fall from rest at tilt ``amplitude`` back to theta = 0.

    Exact: ``F(phi, m) / p`` with ``m = cos^2((alpha - A)/2)`` and
    ``sin^2 phi = sin(alpha - A/2) sin(A/2) / (sin^2(alpha/2) cos^2((alpha - A)/2))``
    (the block about its corner is an inverted pendulum). Linearised (Housner):
    ``acosh(alpha / (alpha - A)) / p``. A half-cycle between two impacts lasts twice the fall
    time of its apex amplitude.

    Parameters
    ----------
    amplitude : array_like, any shape
        Tilt |A| at rest [rad], |A| < alpha.
    alpha : float
        Slenderness angle [rad], in (0, pi/2).
    p : float
        Frequency parameter [1 / time], > 0.
    linearised : bool
        Use Housner's linearised equation instead of the exact one.

    Returns
    -------
    ndarray, same shape as ``amplitude``
        Fall time [time].
    """
    alpha, p = _check_block(alpha, p)
    amp = np.abs(_check_amplitude("amplitude", amplitude, alpha))
    if linearised:
        return np.arccosh(alpha / (alpha - amp)) / p
    m = _exact_modulus(amp, alpha)
    sn_squared = (
        np.sin(alpha - 0.5 * amp)
        * np.sin(0.5 * amp)
        / (math.sin(0.5 * alpha) ** 2 * np.cos(0.5 * (alpha - amp)) ** 2)
    )
    phi = np.arcsin(np.sqrt(np.clip(sn_squared, 0.0, 1.0)))
    from scipy.special import ellipkinc  # on use: scipy.special is slow to import
    return ellipkinc(phi, m) / p


def rocking_block_impact_speed(
    amplitude, alpha: float, p: float, *, linearised: bool = False
) -> np.ndarray:
    """Angular speed |theta'| reached at theta = 0 after falling from rest at ``amplitude``.

    Exact: ``2 p sqrt(sin(alpha - A/2) sin(A/2))``; linearised: ``p sqrt(A (2 alpha - A))``.

    Parameters
    ----------
    amplitude : array_like, any shape
        Tilt |A| at rest [rad], |A| < alpha.
    alpha, p, linearised
        As in :func:`rocking_block_fall_time`.

    Returns
    -------
    ndarray, same shape as ``amplitude``
        Angular speed just before the impact [rad / time].
    """
    alpha, p = _check_block(alpha, p)
    amp = np.abs(_check_amplitude("amplitude", amplitude, alpha))
    if linearised:
        return p * np.sqrt(amp * (2.0 * alpha - amp))
    return 2.0 * p * np.sqrt(np.sin(alpha - 0.5 * amp) * np.sin(0.5 * amp))


def _amplitudes_from_index(theta0_abs: float, alpha: float, k: np.ndarray, linearised: bool):
    """Apex amplitudes |A_k| after impact k (k = 0 is the release), closed form in k."""
    ratio = max(rocking_block_velocity_ratio(alpha), 0.0)
    with np.errstate(divide="ignore"):
        decay = np.where(k == 0, 1.0, ratio ** (2.0 * k))
    if linearised:
        # Linear energy: theta'^2 / p^2 = A (2 alpha - A) at theta = 0, scaled by r^2 per impact.
        q = decay * theta0_abs * (2.0 * alpha - theta0_abs)
        return q / (alpha + np.sqrt(alpha**2 - q))
    # Exact energy: theta'^2 / (2 p^2) = cos(alpha - A) - cos(alpha) = 2 sin(alpha - A/2) sin(A/2).
    c = decay * 2.0 * math.sin(alpha - 0.5 * theta0_abs) * math.sin(0.5 * theta0_abs)
    psi = np.arccos(np.minimum(math.cos(alpha) + c, 1.0))
    # A = alpha - psi, recomputed from 2 sin((alpha + psi)/2) sin(A/2) = c without cancellation.
    return 2.0 * np.arcsin(np.minimum(c / (2.0 * np.sin(0.5 * (alpha + psi))), 1.0))


def rocking_block_amplitudes(
    theta0: float, alpha: float, n_impacts: int, *, linearised: bool = False
) -> np.ndarray:
    """Signed apex tilts: the release angle, then the apex after each of ``n_impacts`` impacts.

    The energy just after an impact is r^2 times the one before (r from
    :func:`rocking_block_velocity_ratio`, clamped at 0), so in the exact model
    ``cos(alpha - A_k) - cos(alpha) = r^(2k) (cos(alpha - A_0) - cos(alpha))``, and in the
    linearised one ``A_k (2 alpha - A_k) = r^(2k) A_0 (2 alpha - A_0)``. Signs alternate.

    Parameters
    ----------
    theta0 : float
        Release tilt [rad], |theta0| < alpha.
    alpha : float
        Slenderness angle [rad], in (0, pi/2).
    n_impacts : int
        Number of impacts, >= 0.
    linearised : bool
        Use Housner's linearised equation instead of the exact one.

    Returns
    -------
    ndarray, shape (n_impacts + 1,)
        Apex tilts [rad]; entry k has sign ``sign(theta0) (-1)^k``.
    """
    alpha = require_in_interval("alpha", alpha, 0.0, 0.5 * math.pi)
    theta0 = float(_check_amplitude("theta0", theta0, alpha))
    if n_impacts < 0:
        raise ValueError(f"n_impacts = {n_impacts!r}: must be >= 0")
    k = np.arange(n_impacts + 1, dtype=float)
    magnitudes = _amplitudes_from_index(abs(theta0), alpha, k, linearised)
    return math.copysign(1.0, theta0) * (-1.0) ** k * magnitudes


def _impact_schedule(theta0_abs: float, alpha: float, p: float, t_max: float, linearised: bool):
    """Impact times covering [0, t_max] and the apex amplitude of each half-cycle.

    Returns ``(impact_times, amplitudes, at_rest_from)``: ``impact_times[j]`` is impact j+1,
    ``amplitudes[j]`` the apex of the release (j = 0) or of the half-cycle after impact j, and
    ``at_rest_from`` the accumulation time if it was reached (else inf).
    """
    ratio = max(rocking_block_velocity_ratio(alpha), 0.0)
    first = float(rocking_block_fall_time(theta0_abs, alpha, p, linearised=linearised))
    amplitudes = [np.array([theta0_abs])]
    impacts = [np.array([first])]
    if ratio == 0.0:
        return impacts[0], amplitudes[0], first
    last_time = first
    start = 1
    while last_time <= t_max:
        k = np.arange(start, start + _IMPACT_CHUNK, dtype=float)
        amp = _amplitudes_from_index(theta0_abs, alpha, k, linearised)
        half_cycles = 2.0 * rocking_block_fall_time(amp, alpha, p, linearised=linearised)
        times = last_time + np.cumsum(half_cycles)
        amplitudes.append(amp)
        impacts.append(times)
        last_time = float(times[-1])
        start += _IMPACT_CHUNK
        # Small amplitudes: the half-cycle shrinks by r per impact, so the tail after the last
        # impact sums to about half_cycle * r / (1 - r). Once below round-off of the time, the
        # impacts have accumulated.
        tail = half_cycles[-1] * ratio / (1.0 - ratio)
        if amp[-1] == 0.0 or tail <= 4.0 * np.finfo(float).eps * last_time:
            return np.concatenate(impacts), np.concatenate(amplitudes), last_time + tail
        if start > _MAX_IMPACTS:
            raise ValueError(
                f"alpha = {alpha!r}: more than {_MAX_IMPACTS} impacts needed to reach t = "
                f"{t_max!r}; the block is too slender for an explicit impact schedule"
            )
    return np.concatenate(impacts), np.concatenate(amplitudes), math.inf


def _from_rest(amplitude: np.ndarray, tau: np.ndarray, alpha: float, p: float, linearised: bool):
    """|theta| and d|theta|/dtau a time tau after rest at ``amplitude`` (before the impact)."""
    if linearised:
        gap = alpha - amplitude
        return alpha - gap * np.cosh(p * tau), -gap * p * np.sinh(p * tau)
    # Exact: with psi = alpha - theta the angle of the corner-to-centre line from the vertical,
    # psi'' = p^2 sin(psi), i.e. sin(psi / 2) = sin(psi0 / 2) / dn(p tau | m).
    m = _exact_modulus(amplitude, alpha)
    from scipy.special import ellipj  # on use: scipy.special is slow to import
    sn, cn, dn, _ = ellipj(p * tau, m)
    complement = np.sin(0.5 * (alpha - amplitude))  # sqrt(1 - m)
    half_psi = np.arcsin(np.minimum(complement / dn, 1.0))
    psi_rate = 2.0 * p * complement * m * sn * cn / (dn**2 * np.cos(half_psi))
    return alpha - 2.0 * half_psi, -psi_rate


def _rocking_state(t, theta0, alpha, p, linearised):
    alpha, p = _check_block(alpha, p)
    theta0 = float(_check_amplitude("theta0", theta0, alpha))
    times = as_times(t)
    angle = np.zeros_like(times)
    rate = np.zeros_like(times)
    if theta0 == 0.0 or times.size == 0:
        return angle, rate
    side = math.copysign(1.0, theta0)
    impacts, amplitudes, rest_from = _impact_schedule(
        abs(theta0), alpha, p, float(times.max()), linearised
    )
    # phase j: 0 before the first impact, j >= 1 after impact j.
    phase = np.searchsorted(impacts, times, side="right")
    moving = (phase < impacts.size) & (times < rest_from)
    j = phase[moving]
    amp = amplitudes[j]
    apex_time = np.where(j == 0, 0.0, impacts[j - 1] + 0.5 * (impacts[j] - impacts[j - 1]))
    since_apex = times[moving] - apex_time
    magnitude, magnitude_rate = _from_rest(amp, np.abs(since_apex), alpha, p, linearised)
    sign = side * (-1.0) ** j
    angle[moving] = sign * np.maximum(magnitude, 0.0)
    # Before the apex the tilt grows: the time-reversed fall.
    rate[moving] = sign * np.where(since_apex < 0.0, -magnitude_rate, magnitude_rate)
    return angle, rate


def rocking_block_impact_times(
    theta0: float, alpha: float, p: float, n_impacts: int, *, linearised: bool = False
) -> np.ndarray:
    """Times of the first ``n_impacts`` impacts of a block released from rest at ``theta0``.

    The first impact is at the fall time of ``theta0``; half-cycle k (between impacts k and
    k+1) lasts twice the fall time of its apex amplitude (see :func:`rocking_block_amplitudes`).

    Parameters
    ----------
    theta0 : float
        Release tilt [rad], 0 < |theta0| < alpha.
    alpha : float
        Slenderness angle [rad], in (0, pi/2).
    p : float
        Frequency parameter [1 / time], > 0.
    n_impacts : int
        Number of impacts, >= 0.
    linearised : bool
        Use Housner's linearised equation instead of the exact one.

    Returns
    -------
    ndarray, shape (n_impacts,)
        Impact times [time]; all equal to the first one if r <= 0 (the block stops there).
    """
    alpha, p = _check_block(alpha, p)
    theta0 = float(_check_amplitude("theta0", theta0, alpha))
    if theta0 == 0.0:
        raise ValueError("theta0 = 0.0: a block released upright never impacts")
    if n_impacts < 0:
        raise ValueError(f"n_impacts = {n_impacts!r}: must be >= 0")
    amp = _amplitudes_from_index(abs(theta0), alpha, np.arange(n_impacts, dtype=float), linearised)
    durations = rocking_block_fall_time(amp, alpha, p, linearised=linearised)
    durations[1:] *= 2.0  # with r <= 0 the amplitudes after the first impact are 0
    return np.cumsum(durations)


def rocking_block_angle(
    t, theta0: float, alpha: float, p: float, *, linearised: bool = False
) -> np.ndarray:
    """Tilt angle theta(t) of a block released from rest at ``theta0``, through all impacts.

    Piecewise: each half-cycle is the time-symmetric rise and fall of the inverted-pendulum
    motion about the pivot corner (exactly through Jacobi's dn, or Housner's cosh solution
    ``alpha - (alpha - A) cosh(p tau)`` when linearised); after the accumulation of the impacts
    the block rests at theta = 0.

    Parameters
    ----------
    t : array_like, any shape
        Times since the release [time], >= 0.
    theta0 : float
        Release tilt [rad], |theta0| < alpha; positive = rotated about the right corner.
    alpha : float
        Slenderness angle [rad], in (0, pi/2).
    p : float
        Frequency parameter [1 / time], > 0.
    linearised : bool
        Use Housner's linearised equation instead of the exact one.

    Returns
    -------
    ndarray, same shape as ``t``
        Tilt [rad].
    """
    return _rocking_state(t, theta0, alpha, p, linearised)[0]


def rocking_block_angular_velocity(
    t, theta0: float, alpha: float, p: float, *, linearised: bool = False
) -> np.ndarray:
    """Angular velocity theta'(t) matching :func:`rocking_block_angle`, right-continuous.

    Parameters
    ----------
    t, theta0, alpha, p, linearised
        As in :func:`rocking_block_angle`.

    Returns
    -------
    ndarray, same shape as ``t``
        Angular velocity [rad / time]; at an impact instant the post-impact value.
    """
    return _rocking_state(t, theta0, alpha, p, linearised)[1]
