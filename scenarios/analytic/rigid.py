"""Analytic references for rigid-body dynamics without contact: pendulum, torque-free body, energy.

Every function is unit-agnostic: give masses, lengths and times in one consistent system
(SI: kg, m, s; the C-60's mm, g, ms; ...) and the results come back in that system (energies in
mass * length^2 / time^2). Angles are in radians. Time arguments are array_like of any shape.

Pendulum
--------
A rigid body on an ideal revolute joint with a horizontal axis: mass ``m``, distance ``d`` from
the pivot to the centre of mass, inertia ``I_p`` about the joint axis through the pivot (a simple
pendulum of length L is ``I_p = m L^2``, ``d = L``). ``theta`` is measured from the downward
vertical. Released from rest at ``theta0`` (|theta0| < pi), with ``omega0 = sqrt(m g d / I_p)``
and ``k = sin(theta0 / 2)``:

* ``theta(t) = 2 asin(k cd(omega0 t | k^2))`` (Jacobi ``cd = cn / dn``; equivalently
  ``2 asin(k sn(K - omega0 t))``), exact for all amplitudes;
* period ``4 K(k^2) / omega0``, where scipy's ``ellipk`` takes the *parameter* m = k^2, not
  the modulus k.

Near the top (theta0 -> pi) the period stays accurate (it is computed from 1 - m), but
``theta(t)`` goes through ``ellipj``, whose only input is m: once 1 - m = cos^2(theta0 / 2) is
not much larger than the round-off of m (1e-16), i.e. pi - |theta0| below ~1e-6, its phase
drifts from the exact one by ~eps / (1 - m) of a period per period.

Torque-free rigid body
----------------------
Euler's equations ``I1 w1' = (I2 - I3) w2 w3`` (and cyclic) in principal body axes with
``I1 < I2 < I3``. The rotational kinetic energy ``T = 1/2 sum I_i w_i^2`` and the norm of the
angular momentum ``|L| = sqrt(sum I_i^2 w_i^2)`` are invariant. With ``D = |L|^2 / (2 T)``:

* ``D > I2``: the polhode encircles the major axis 3,
  ``w = (A1 cn u, A2 sn u, +-A3 dn u)``;
* ``D < I2``: it encircles the minor axis 1, ``w = (+-A1 dn u, A2 sn u, A3 cn u)``;

with ``u = lambda t + u0`` (Landau & Lifshitz, Mechanics, section 37). The body angular velocity
is periodic with period ``4 K(m) / |lambda|``. Near the intermediate axis (the Dzhanibekov /
tennis-racket flip) ``m`` is close to 1, ``w2`` dwells near +-A2 and reverses sign every half
period: the flips are ``2 K(m) / |lambda|`` apart.

Energy
------
:func:`rigid_body_energy` evaluates the translational, rotational and gravitational potential
energy of one body along a trajectory, with the conventions of the scene description and of the
reference solver: velocity of the centre of mass in world axes, angular velocity in body axes,
inertia about the centre of mass in body axes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import IntEnum

import numpy as np

from clearbench.scenarios.analytic.common import as_times, require_finite, require_positive

__all__ = [
    "PolhodeAxis",
    "RigidBodyEnergy",
    "TorqueFreePolhode",
    "pendulum_angle",
    "pendulum_angular_velocity",
    "pendulum_energy",
    "pendulum_period",
    "physical_pendulum_frequency",
    "rigid_body_energy",
    "simple_pendulum_frequency",
    "torque_free_angular_velocity",
    "torque_free_invariants",
    "torque_free_period",
    "torque_free_polhode",
]

# ---------------------------------------------------------------------------------------------
# Pendulum
# ---------------------------------------------------------------------------------------------


def physical_pendulum_frequency(
    mass: float, com_distance: float, inertia_about_pivot: float, g: float
) -> float:
    """Small-oscillation angular frequency ``omega0 = sqrt(m g d / I_p)`` [rad / time].

    Parameters
    ----------
    mass : float
        Mass m [mass], > 0.
    com_distance : float
        Distance d from the joint axis to the centre of mass [length], > 0.
    inertia_about_pivot : float
        Moment of inertia I_p about the joint axis [mass * length^2], >= m d^2.
    g : float
        Magnitude of gravity [length / time^2], > 0.
    """
    mass = require_positive("mass", mass)
    com_distance = require_positive("com_distance", com_distance)
    inertia = require_positive("inertia_about_pivot", inertia_about_pivot)
    # Parallel-axis theorem: I_p = I_com + m d^2 >= m d^2 (tolerate round-off of the sum).
    if inertia < mass * com_distance**2 * (1.0 - 1e-12):
        raise ValueError(
            f"inertia_about_pivot = {inertia_about_pivot!r}: must be >= mass * com_distance^2 "
            f"= {mass * com_distance**2!r} (parallel-axis theorem)"
        )
    return math.sqrt(mass * require_positive("g", g) * com_distance / inertia)


def simple_pendulum_frequency(length: float, g: float) -> float:
    """Small-oscillation angular frequency of a point mass on a massless rod, ``sqrt(g / L)``.

    Parameters
    ----------
    length : float
        Rod length L [length], > 0.
    g : float
        Magnitude of gravity [length / time^2], > 0.
    """
    return math.sqrt(require_positive("g", g) / require_positive("length", length))


def _check_pendulum(theta0: float, natural_frequency: float) -> tuple[float, float]:
    theta0 = require_finite("theta0", theta0)
    if abs(theta0) >= math.pi:
        raise ValueError(f"theta0 = {theta0!r}: |theta0| must be < pi (pi is the unstable top)")
    return theta0, require_positive("natural_frequency", natural_frequency)


def pendulum_period(theta0: float, natural_frequency: float) -> float:
    """Exact period ``4 K(sin^2(theta0 / 2)) / omega0`` of the pendulum released at ``theta0``.

    Parameters
    ----------
    theta0 : float
        Release angle from the downward vertical [rad], |theta0| < pi.
    natural_frequency : float
        omega0 from :func:`physical_pendulum_frequency` or :func:`simple_pendulum_frequency`
        [rad / time].

    Returns
    -------
    float
        Period [time]; tends to ``2 pi / omega0`` as theta0 -> 0.
    """
    theta0, omega0 = _check_pendulum(theta0, natural_frequency)
    # K(m) through ellipkm1(1 - m): 1 - m = cos^2(theta0/2) keeps its relative precision near
    # the top, where forming m = sin^2(theta0/2) first would lose it (K ~ ln(4 / sqrt(1 - m))).
    from scipy.special import ellipkm1  # on use: scipy.special is slow to import
    return 4.0 * float(ellipkm1(math.cos(0.5 * theta0) ** 2)) / omega0


def _pendulum_jacobi(t, theta0: float, natural_frequency: float):
    theta0, omega0 = _check_pendulum(theta0, natural_frequency)
    times = as_times(t, non_negative=False)
    modulus = math.sin(0.5 * theta0)  # signed k; only k^2 enters ellipj
    from scipy.special import ellipj  # on use: scipy.special is slow to import
    sn, cn, dn, _ = ellipj(omega0 * times, modulus**2)
    return modulus, math.cos(0.5 * theta0), omega0, sn, cn, dn


def pendulum_angle(t, theta0: float, natural_frequency: float) -> np.ndarray:
    """Exact angle of the pendulum released from rest, ``2 asin(k cn(u) / dn(u))``, u = omega0 t.

    Parameters
    ----------
    t : array_like, any shape
        Times since the release [time] (negative times give the motion before it).
    theta0 : float
        Release angle from the downward vertical [rad], |theta0| < pi.
    natural_frequency : float
        omega0 [rad / time].

    Returns
    -------
    ndarray, same shape as ``t``
        Angle from the downward vertical [rad].
    """
    modulus, _, _, _, cn, dn = _pendulum_jacobi(t, theta0, natural_frequency)
    return 2.0 * np.arcsin(np.clip(modulus * cn / dn, -1.0, 1.0))


def pendulum_angular_velocity(t, theta0: float, natural_frequency: float) -> np.ndarray:
    """Exact angular velocity, ``-2 k k' omega0 sn(u) / dn(u)`` with ``k' = cos(theta0 / 2)``.

    Parameters
    ----------
    t, theta0, natural_frequency
        As in :func:`pendulum_angle`.

    Returns
    -------
    ndarray, same shape as ``t``
        d theta / dt [rad / time].
    """
    modulus, complement, omega0, sn, _, dn = _pendulum_jacobi(t, theta0, natural_frequency)
    return -2.0 * modulus * complement * omega0 * sn / dn


def pendulum_energy(
    theta,
    theta_dot,
    mass: float,
    com_distance: float,
    inertia_about_pivot: float,
    g: float,
) -> np.ndarray:
    """Mechanical energy ``I_p theta'^2 / 2 + m g d (1 - cos theta)`` (zero hanging at rest).

    Parameters
    ----------
    theta : array_like, any shape
        Angle from the downward vertical [rad].
    theta_dot : array_like, broadcastable with ``theta``
        Angular velocity [rad / time].
    mass, com_distance, inertia_about_pivot, g : float
        As in :func:`physical_pendulum_frequency`.

    Returns
    -------
    ndarray, broadcast shape
        Energy [mass * length^2 / time^2]; constant ``m g d (1 - cos theta0)`` along the exact
        motion.
    """
    physical_pendulum_frequency(mass, com_distance, inertia_about_pivot, g)  # validates
    theta = np.asarray(theta, dtype=float)
    theta_dot = np.asarray(theta_dot, dtype=float)
    potential = 2.0 * mass * g * com_distance * np.sin(0.5 * theta) ** 2  # 1 - cos = 2 sin^2
    return 0.5 * inertia_about_pivot * theta_dot**2 + potential


# ---------------------------------------------------------------------------------------------
# Torque-free rigid body
# ---------------------------------------------------------------------------------------------


def _check_principal(principal_moments) -> np.ndarray:
    moments = np.asarray(principal_moments, dtype=float)
    if moments.shape != (3,) or not np.all(np.isfinite(moments)):
        raise ValueError(f"principal_moments = {principal_moments!r}: must be 3 finite numbers")
    if not (0.0 < moments[0] < moments[1] < moments[2]):
        raise ValueError(
            f"principal_moments = {principal_moments!r}: need 0 < I1 < I2 < I3 "
            "(order the body axes by increasing inertia; equal moments have a simpler solution)"
        )
    if moments[0] + moments[1] < moments[2] * (1.0 - 1e-12):
        raise ValueError(
            f"principal_moments = {principal_moments!r}: violate the triangle inequality "
            "I1 + I2 >= I3 that every mass distribution satisfies"
        )
    return moments


def torque_free_invariants(principal_moments, omega_body) -> tuple[np.ndarray, np.ndarray]:
    """Rotational kinetic energy and angular-momentum norm of a body in principal axes.

    Parameters
    ----------
    principal_moments : array_like, shape (3,)
        Principal moments of inertia about the centre of mass [mass * length^2], positive.
    omega_body : array_like, shape (..., 3)
        Angular velocity in the principal body axes [rad / time].

    Returns
    -------
    kinetic_energy : ndarray, shape (...)
        ``1/2 sum I_i w_i^2`` [mass * length^2 / time^2].
    angular_momentum_norm : ndarray, shape (...)
        ``sqrt(sum I_i^2 w_i^2)`` [mass * length^2 / time].
    """
    moments = np.asarray(principal_moments, dtype=float)
    if moments.shape != (3,) or not np.all(moments > 0.0):
        raise ValueError(f"principal_moments = {principal_moments!r}: must be 3 positive numbers")
    omega = np.asarray(omega_body, dtype=float)
    if omega.shape[-1:] != (3,):
        raise ValueError(f"omega_body: shape {omega.shape} must end with 3")
    kinetic = 0.5 * np.sum(moments * omega**2, axis=-1)
    momentum = np.sqrt(np.sum((moments * omega) ** 2, axis=-1))
    return kinetic, momentum


class PolhodeAxis(IntEnum):
    """Which principal axis the polhode encircles (the value is the axis index)."""

    MINOR = 0  #: axis 1 (smallest inertia), when |L|^2 < 2 T I2
    MAJOR = 2  #: axis 3 (largest inertia), when |L|^2 >= 2 T I2


@dataclass(frozen=True)
class TorqueFreePolhode:
    """Parameters of the exact torque-free solution ``w(t)`` (see the module docstring).

    Attributes
    ----------
    principal_moments : tuple of 3 floats
        I1 < I2 < I3 [mass * length^2].
    encircled_axis : PolhodeAxis
        The principal axis the polhode encircles.
    amplitudes : tuple of 3 floats
        Signed amplitudes (A1, A2, A3) [rad / time]; the component multiplying ``dn`` carries
        the (constant) sign of that component, the others are >= 0.
    rate : float
        lambda, signed, in ``u = lambda t + u0`` [1 / time].
    parameter : float
        Elliptic parameter m = k^2 in [0, 1] (scipy's convention).
    phase : float
        u0 [dimensionless].
    steady : bool
        True when the initial angular velocity is a steady rotation that the formula cannot
        phase (zero, or exactly about the intermediate axis); w(t) is then constant.
    """

    principal_moments: tuple[float, float, float]
    encircled_axis: PolhodeAxis
    amplitudes: tuple[float, float, float]
    rate: float
    parameter: float
    phase: float
    steady: bool

    @property
    def period(self) -> float:
        """Period of the body angular velocity, ``4 K(m) / |lambda|`` [time] (inf if m = 1)."""
        if self.steady or self.rate == 0.0:
            return math.inf
        from scipy.special import ellipk  # on use: scipy.special is slow to import
        return 4.0 * float(ellipk(self.parameter)) / abs(self.rate)


def torque_free_polhode(principal_moments, omega0) -> TorqueFreePolhode:
    """Parameters of the exact solution of Euler's equations from the body rate ``omega0``.

    Parameters
    ----------
    principal_moments : array_like, shape (3,)
        Principal moments of inertia I1 < I2 < I3 [mass * length^2].
    omega0 : array_like, shape (3,)
        Initial angular velocity in the principal body axes [rad / time].

    Returns
    -------
    TorqueFreePolhode
    """
    moments = _check_principal(principal_moments)
    omega = np.asarray(omega0, dtype=float)
    if omega.shape != (3,) or not np.all(np.isfinite(omega)):
        raise ValueError(f"omega0 = {omega0!r}: must be 3 finite numbers")
    i1, i2, i3 = moments
    w1, w2, w3 = omega
    # Reduced invariants, written as sums of non-negative terms (no cancellation):
    above_minor = i2 * (i2 - i1) * w2**2 + i3 * (i3 - i1) * w3**2  # |L|^2 - 2 T I1 >= 0
    below_major = i1 * (i3 - i1) * w1**2 + i2 * (i3 - i2) * w2**2  # 2 T I3 - |L|^2 >= 0
    separatrix = i3 * (i3 - i2) * w3**2 - i1 * (i2 - i1) * w1**2  # |L|^2 - 2 T I2
    product = i1 * i2 * i3
    moments_tuple = (float(i1), float(i2), float(i3))
    if (w1 == 0.0 and w3 == 0.0) or not np.any(omega):
        return TorqueFreePolhode(
            moments_tuple,
            PolhodeAxis.MAJOR,
            (float(w1), float(w2), float(w3)),
            0.0,
            1.0,
            0.0,
            True,
        )
    if separatrix >= 0.0:
        a1 = math.sqrt(below_major / (i1 * (i3 - i1)))
        a2 = math.sqrt(below_major / (i2 * (i3 - i2)))
        a3 = math.sqrt(above_minor / (i3 * (i3 - i1)))
        rate = math.copysign(math.sqrt((i3 - i2) * above_minor / product), w3)
        parameter = (i2 - i1) * below_major / ((i3 - i2) * above_minor)
        # cn(u0) = w1 / A1 and sn(u0) = w2 / A2: the amplitude (angle) of u0.
        amplitude_angle = math.atan2(w2 * a1, w1 * a2)
        axis, amplitudes = PolhodeAxis.MAJOR, (a1, a2, math.copysign(a3, w3))
    else:
        a1 = math.sqrt(below_major / (i1 * (i3 - i1)))
        a2 = math.sqrt(above_minor / (i2 * (i2 - i1)))
        a3 = math.sqrt(above_minor / (i3 * (i3 - i1)))
        rate = math.copysign(math.sqrt((i2 - i1) * below_major / product), w1)
        parameter = (i3 - i2) * above_minor / ((i2 - i1) * below_major)
        amplitude_angle = math.atan2(w2 * a3, w3 * a2)
        axis, amplitudes = PolhodeAxis.MINOR, (math.copysign(a1, w1), a2, a3)
    parameter = min(max(parameter, 0.0), 1.0)
    from scipy.special import ellipkinc  # on use: scipy.special is slow to import
    phase = float(ellipkinc(amplitude_angle, parameter))
    return TorqueFreePolhode(
        moments_tuple, axis, amplitudes, rate, parameter, phase, not math.isfinite(phase)
    )


def torque_free_angular_velocity(t, principal_moments, omega0) -> np.ndarray:
    """Exact body angular velocity of a torque-free rigid body, through Jacobi functions.

    Parameters
    ----------
    t : array_like, shape (...)
        Times [time] (any sign; t = 0 is where ``omega0`` is given).
    principal_moments : array_like, shape (3,)
        Principal moments of inertia I1 < I2 < I3 [mass * length^2].
    omega0 : array_like, shape (3,)
        Initial angular velocity in the principal body axes [rad / time].

    Returns
    -------
    ndarray, shape (..., 3)
        Angular velocity in the principal body axes [rad / time].
    """
    polhode = torque_free_polhode(principal_moments, omega0)
    times = as_times(t, non_negative=False)
    if polhode.steady:
        return np.broadcast_to(np.asarray(polhode.amplitudes), (*times.shape, 3)).copy()
    from scipy.special import ellipj  # on use: scipy.special is slow to import
    sn, cn, dn, _ = ellipj(polhode.rate * times + polhode.phase, polhode.parameter)
    a1, a2, a3 = polhode.amplitudes
    if polhode.encircled_axis == PolhodeAxis.MAJOR:
        return np.stack((a1 * cn, a2 * sn, a3 * dn), axis=-1)
    return np.stack((a1 * dn, a2 * sn, a3 * cn), axis=-1)


def torque_free_period(principal_moments, omega0) -> float:
    """Period of the body angular velocity, ``4 K(m) / |lambda|`` [time].

    For rotation near the intermediate axis the component w2 reverses sign (the body flips)
    every half period, ``2 K(m) / |lambda|``. Infinite on the separatrix.

    Parameters
    ----------
    principal_moments, omega0 : array_like, shape (3,)
        As in :func:`torque_free_angular_velocity`.
    """
    return torque_free_polhode(principal_moments, omega0).period


# ---------------------------------------------------------------------------------------------
# Energy of a rigid body along a trajectory
# ---------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class RigidBodyEnergy:
    """Energy parts of one rigid body over a trajectory, each of shape (T,) (or the batch shape).

    Attributes
    ----------
    translational : ndarray
        ``m |v|^2 / 2`` [mass * length^2 / time^2].
    rotational : ndarray
        ``w . I w / 2`` with w and I in body axes [mass * length^2 / time^2].
    potential : ndarray
        ``m g z`` with z the height of the centre of mass along -gravity
        [mass * length^2 / time^2].
    """

    translational: np.ndarray
    rotational: np.ndarray
    potential: np.ndarray

    @property
    def kinetic(self) -> np.ndarray:
        """Translational + rotational kinetic energy."""
        return self.translational + self.rotational

    @property
    def total(self) -> np.ndarray:
        """Kinetic + potential energy."""
        return self.kinetic + self.potential


def rigid_body_energy(
    mass: float, inertia_body, velocity_world, omega_body, height, g: float
) -> RigidBodyEnergy:
    """Kinetic and gravitational potential energy of one rigid body along a trajectory.

    Parameters
    ----------
    mass : float
        Mass [mass], > 0.
    inertia_body : array_like, shape (3, 3) or (T, 3, 3)
        Inertia tensor about the centre of mass in body axes [mass * length^2].
    velocity_world : array_like, shape (T, 3)
        Velocity of the centre of mass in world axes [length / time].
    omega_body : array_like, shape (T, 3)
        Angular velocity in body axes [rad / time].
    height : array_like, shape (T,)
        Height of the centre of mass along the direction opposite to gravity, from any fixed
        datum [length].
    g : float
        Magnitude of gravity [length / time^2], >= 0.

    Returns
    -------
    RigidBodyEnergy
        Translational, rotational and potential parts, each of shape (T,).
    """
    mass = require_positive("mass", mass)
    g = float(g)
    if not (math.isfinite(g) and g >= 0.0):
        raise ValueError(f"g = {g!r}: must be finite and >= 0")
    inertia = np.asarray(inertia_body, dtype=float)
    velocity = np.asarray(velocity_world, dtype=float)
    omega = np.asarray(omega_body, dtype=float)
    if inertia.shape[-2:] != (3, 3):
        raise ValueError(f"inertia_body: shape {inertia.shape} must end with (3, 3)")
    if velocity.shape[-1:] != (3,) or omega.shape[-1:] != (3,):
        raise ValueError(
            f"velocity_world {velocity.shape} and omega_body {omega.shape} must end with 3"
        )
    translational = 0.5 * mass * np.sum(velocity**2, axis=-1)
    rotational = 0.5 * np.einsum("...i,...ij,...j->...", omega, inertia, omega)
    potential = mass * g * np.asarray(height, dtype=float)
    return RigidBodyEnergy(translational, rotational, potential)
