"""Analytic references for Coulomb friction scenes: incline, sliding box, sliding-to-rolling sphere.

Every function is unit-agnostic: give lengths, times, velocities and accelerations in one
consistent system (SI: m, s, m/s, m/s^2; or mm, ms, ...) and results come back in that system.
Angles are in radians. Friction is Coulomb's law with one coefficient ``mu`` for sticking and
sliding (as in the scene description). Time arguments are array_like of any shape and the result
has the same shape; times are measured from the release (t >= 0).

Incline
-------
A box released from rest on a plane inclined by ``alpha`` sticks when ``tan(alpha) <= mu``
(the friction cone contains the reaction that balances gravity); otherwise it slides down with
constant acceleration ``g (sin alpha - mu cos alpha)`` and never stops.

Sliding box
-----------
A box sliding at ``v0`` on a horizontal plane decelerates at ``mu g`` and stops at
``t = |v0| / (mu g)`` after ``v0^2 / (2 mu g)``, then stays at rest.

Sliding sphere
--------------
A ball of radius ``R`` with centroidal inertia ``I = k m R^2`` (uniform solid sphere: k = 2/5)
is launched sliding at ``v0`` without spin on a horizontal plane. Friction ``mu m g`` decelerates
it and spins it up until the contact point stops slipping at ``t_r = k |v0| / ((1 + k) mu g)``
(``2 v0 / (7 mu g)`` for the solid sphere); from then on it rolls at ``v0 / (1 + k)`` (``5 v0 / 7``)
with no friction force. ``omega`` is the spin about the horizontal axis perpendicular to the
motion, oriented so that rolling without slipping reads ``v = omega R`` (for motion along +x
with z up, this is the +y component of the angular velocity).
"""

from __future__ import annotations

import math

import numpy as np

from clearbench.scenarios.analytic.common import (
    as_times,
    require_finite,
    require_in_interval,
    require_non_negative,
    require_positive,
)

__all__ = [
    "SOLID_SPHERE_INERTIA_RATIO",
    "incline_block_acceleration",
    "incline_block_displacement",
    "incline_block_sticks",
    "incline_block_velocity",
    "rolling_sphere_angular_velocity",
    "rolling_sphere_final_speed",
    "rolling_sphere_onset_time",
    "rolling_sphere_position",
    "rolling_sphere_velocity",
    "sliding_box_position",
    "sliding_box_stop_distance",
    "sliding_box_stop_time",
    "sliding_box_velocity",
]

#: I / (m R^2) of a uniform solid sphere about a diameter.
SOLID_SPHERE_INERTIA_RATIO = 0.4

# ---------------------------------------------------------------------------------------------
# Box on an incline
# ---------------------------------------------------------------------------------------------


def _check_incline(alpha: float, mu: float) -> tuple[float, float]:
    return (
        require_in_interval("alpha", alpha, 0.0, 0.5 * math.pi, closed_high=True),
        require_non_negative("mu", mu),
    )


def incline_block_sticks(alpha: float, mu: float) -> bool:
    """Whether a box released from rest on the incline stays stuck, ``tan(alpha) <= mu``.

    Parameters
    ----------
    alpha : float
        Incline angle [rad], in [0, pi/2].
    mu : float
        Coulomb friction coefficient, >= 0.
    """
    alpha, mu = _check_incline(alpha, mu)
    return math.sin(alpha) <= mu * math.cos(alpha)


def incline_block_acceleration(alpha: float, mu: float, g: float) -> float:
    """Acceleration down the slope, ``g (sin alpha - mu cos alpha)``, or 0 if the box sticks.

    Parameters
    ----------
    alpha : float
        Incline angle [rad], in [0, pi/2].
    mu : float
        Coulomb friction coefficient, >= 0.
    g : float
        Magnitude of gravity [length / time^2], > 0.

    Returns
    -------
    float
        Acceleration along the slope, downhill positive [length / time^2], >= 0.
    """
    alpha, mu = _check_incline(alpha, mu)
    g = require_positive("g", g)
    if incline_block_sticks(alpha, mu):
        return 0.0
    return g * (math.sin(alpha) - mu * math.cos(alpha))


def incline_block_displacement(t, alpha: float, mu: float, g: float) -> np.ndarray:
    """Displacement down the slope of a box released from rest, ``a t^2 / 2`` (0 if it sticks).

    Parameters
    ----------
    t : array_like, any shape
        Times since the release [time], >= 0.
    alpha, mu, g : float
        As in :func:`incline_block_acceleration`.

    Returns
    -------
    ndarray, same shape as ``t``
        Displacement along the slope, downhill positive [length].
    """
    acceleration = incline_block_acceleration(alpha, mu, g)
    return 0.5 * acceleration * as_times(t) ** 2


def incline_block_velocity(t, alpha: float, mu: float, g: float) -> np.ndarray:
    """Velocity down the slope of a box released from rest, ``a t`` (0 if it sticks).

    Parameters
    ----------
    t : array_like, any shape
        Times since the release [time], >= 0.
    alpha, mu, g : float
        As in :func:`incline_block_acceleration`.

    Returns
    -------
    ndarray, same shape as ``t``
        Velocity along the slope, downhill positive [length / time].
    """
    return incline_block_acceleration(alpha, mu, g) * as_times(t)


# ---------------------------------------------------------------------------------------------
# Box sliding on a horizontal plane
# ---------------------------------------------------------------------------------------------


def _check_slide(v0: float, mu: float, g: float) -> tuple[float, float, float]:
    return (
        require_finite("v0", v0),
        require_non_negative("mu", mu),
        require_positive("g", g),
    )


def sliding_box_stop_time(v0: float, mu: float, g: float) -> float:
    """Time at which a box sliding at ``v0`` stops, ``|v0| / (mu g)`` (inf if mu = 0).

    Parameters
    ----------
    v0 : float
        Initial velocity along the plane [length / time] (signed).
    mu : float
        Coulomb friction coefficient, >= 0.
    g : float
        Magnitude of gravity [length / time^2], > 0.

    Returns
    -------
    float
        Stop time [time].
    """
    v0, mu, g = _check_slide(v0, mu, g)
    if v0 == 0.0:
        return 0.0
    return math.inf if mu == 0.0 else abs(v0) / (mu * g)


def sliding_box_stop_distance(v0: float, mu: float, g: float) -> float:
    """Distance slid before stopping, ``v0^2 / (2 mu g)`` (inf if mu = 0 and v0 != 0).

    Parameters
    ----------
    v0, mu, g : float
        As in :func:`sliding_box_stop_time`.

    Returns
    -------
    float
        Distance [length], >= 0.
    """
    v0, mu, g = _check_slide(v0, mu, g)
    if v0 == 0.0:
        return 0.0
    return math.inf if mu == 0.0 else v0**2 / (2.0 * mu * g)


def sliding_box_velocity(t, v0: float, mu: float, g: float) -> np.ndarray:
    """Velocity of the sliding box, ``v0 - sign(v0) mu g t`` until it stops, then 0.

    Parameters
    ----------
    t : array_like, any shape
        Times since the launch [time], >= 0.
    v0, mu, g : float
        As in :func:`sliding_box_stop_time`.

    Returns
    -------
    ndarray, same shape as ``t``
        Velocity [length / time], same sign as ``v0``.
    """
    v0, mu, g = _check_slide(v0, mu, g)
    times = as_times(t)
    stop = sliding_box_stop_time(v0, mu, g)
    sliding = times < stop
    return np.where(sliding, v0 - math.copysign(mu * g, v0) * times, 0.0)


def sliding_box_position(t, v0: float, mu: float, g: float) -> np.ndarray:
    """Position of the sliding box from its start, ``v0 t - sign(v0) mu g t^2 / 2``, then frozen.

    Parameters
    ----------
    t : array_like, any shape
        Times since the launch [time], >= 0.
    v0, mu, g : float
        As in :func:`sliding_box_stop_time`.

    Returns
    -------
    ndarray, same shape as ``t``
        Displacement [length], same sign as ``v0``.
    """
    v0, mu, g = _check_slide(v0, mu, g)
    times = as_times(t)
    moving_time = np.minimum(times, sliding_box_stop_time(v0, mu, g))
    return v0 * moving_time - 0.5 * math.copysign(mu * g, v0) * moving_time**2


# ---------------------------------------------------------------------------------------------
# Sphere launched sliding without spin
# ---------------------------------------------------------------------------------------------


def _check_sphere(v0: float, mu: float, g: float, inertia_ratio: float):
    v0, mu, g = _check_slide(v0, mu, g)
    return v0, mu, g, require_positive("inertia_ratio", inertia_ratio)


def rolling_sphere_onset_time(
    v0: float, mu: float, g: float, inertia_ratio: float = SOLID_SPHERE_INERTIA_RATIO
) -> float:
    """Time at which rolling without slipping starts, ``k |v0| / ((1 + k) mu g)``.

    For the uniform solid sphere (k = 2/5) this is ``2 |v0| / (7 mu g)``; inf if mu = 0.

    Parameters
    ----------
    v0 : float
        Initial velocity of the centre [length / time] (signed), no initial spin.
    mu : float
        Coulomb friction coefficient, >= 0.
    g : float
        Magnitude of gravity [length / time^2], > 0.
    inertia_ratio : float
        k = I / (m R^2) about the centre [dimensionless], > 0; 2/5 for a solid sphere.

    Returns
    -------
    float
        Onset time of rolling [time].
    """
    v0, mu, g, k = _check_sphere(v0, mu, g, inertia_ratio)
    if v0 == 0.0:
        return 0.0
    return math.inf if mu == 0.0 else k * abs(v0) / ((1.0 + k) * mu * g)


def rolling_sphere_final_speed(
    v0: float, inertia_ratio: float = SOLID_SPHERE_INERTIA_RATIO
) -> float:
    """Velocity once rolling, ``v0 / (1 + k)`` (``5 v0 / 7`` for the solid sphere).

    Parameters
    ----------
    v0 : float
        Initial velocity of the centre [length / time] (signed), no initial spin.
    inertia_ratio : float
        k = I / (m R^2) [dimensionless], > 0.

    Returns
    -------
    float
        Rolling velocity [length / time], same sign as ``v0``.
    """
    return require_finite("v0", v0) / (1.0 + require_positive("inertia_ratio", inertia_ratio))


def rolling_incline_acceleration(angle: float, g: float, inertia_ratio: float) -> float:
    """Acceleration down an incline of a body rolling without slipping,
    ``g sin(angle) / (1 + k)`` (``5/7 g sin`` for the solid sphere).

    Parameters
    ----------
    angle : float
        Slope angle [rad].
    g : float
        Gravity [length / time^2], > 0.
    inertia_ratio : float
        k = I / (m r^2) [dimensionless], > 0, I about the rolling axis, r the rolling radius.

    Returns
    -------
    float
        [length / time^2]. Rolling needs tan(angle) <= mu (1 + k) / k; beyond, it slips.
    """
    return (require_positive("g", g) * math.sin(require_finite("angle", angle))
            / (1.0 + require_positive("inertia_ratio", inertia_ratio)))


def rolling_sphere_velocity(
    t, v0: float, mu: float, g: float, inertia_ratio: float = SOLID_SPHERE_INERTIA_RATIO
) -> np.ndarray:
    """Velocity of the centre: ``v0 - sign(v0) mu g t`` while slipping, then ``v0 / (1 + k)``.

    Parameters
    ----------
    t : array_like, any shape
        Times since the launch [time], >= 0.
    v0, mu, g, inertia_ratio : float
        As in :func:`rolling_sphere_onset_time`.

    Returns
    -------
    ndarray, same shape as ``t``
        Velocity of the centre [length / time].
    """
    v0, mu, g, k = _check_sphere(v0, mu, g, inertia_ratio)
    times = np.minimum(as_times(t), rolling_sphere_onset_time(v0, mu, g, k))
    return v0 - math.copysign(mu * g, v0) * times


def rolling_sphere_angular_velocity(
    t,
    v0: float,
    mu: float,
    g: float,
    radius: float,
    inertia_ratio: float = SOLID_SPHERE_INERTIA_RATIO,
) -> np.ndarray:
    """Spin ``omega``: ``sign(v0) mu g t / (k R)`` while slipping, then ``v0 / ((1 + k) R)``.

    ``omega`` is signed so that rolling without slipping is ``v = omega R`` (module docstring).

    Parameters
    ----------
    t : array_like, any shape
        Times since the launch [time], >= 0.
    v0, mu, g, inertia_ratio : float
        As in :func:`rolling_sphere_onset_time`.
    radius : float
        Radius R [length], > 0.

    Returns
    -------
    ndarray, same shape as ``t``
        Angular velocity [rad / time].
    """
    v0, mu, g, k = _check_sphere(v0, mu, g, inertia_ratio)
    radius = require_positive("radius", radius)
    times = np.minimum(as_times(t), rolling_sphere_onset_time(v0, mu, g, k))
    return math.copysign(mu * g, v0) * times / (k * radius)


def rolling_sphere_position(
    t, v0: float, mu: float, g: float, inertia_ratio: float = SOLID_SPHERE_INERTIA_RATIO
) -> np.ndarray:
    """Position of the centre from its start: the sliding parabola, then uniform rolling.

    Parameters
    ----------
    t : array_like, any shape
        Times since the launch [time], >= 0.
    v0, mu, g, inertia_ratio : float
        As in :func:`rolling_sphere_onset_time`.

    Returns
    -------
    ndarray, same shape as ``t``
        Displacement of the centre [length].
    """
    v0, mu, g, k = _check_sphere(v0, mu, g, inertia_ratio)
    times = as_times(t)
    onset = rolling_sphere_onset_time(v0, mu, g, k)
    sliding_time = np.minimum(times, onset)
    rolling_time = times - sliding_time
    sliding = v0 * sliding_time - 0.5 * math.copysign(mu * g, v0) * sliding_time**2
    return sliding + v0 / (1.0 + k) * rolling_time
