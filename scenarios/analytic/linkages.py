"""Analytic reference for the slider–crank with ideal joints and a crank at constant speed.

Unit-agnostic: lengths and times in any consistent system, angles in radians.

Geometry (in the plane of the mechanism): the crank pivots about the origin; the crank angle
``phi = phi0 + omega t`` is measured from the +x axis, counter-clockwise; the crank pin is at
``l1 (cos phi, sin phi)``. The slider moves on the line ``y = offset`` parallel to x, on the
+x side of the pivot, and the connecting rod of length ``l2`` joins the crank pin to the slider.
The rod angle ``psi`` is the direction of the vector from the crank pin to the slider, measured
from +x counter-clockwise:

    sin(psi) = (offset - l1 sin(phi)) / l2,   cos(psi) > 0,
    x = l1 cos(phi) + l2 cos(psi).

The linkage turns fully (the crank can rotate through 360 degrees) when ``l2 > l1 + |offset|``,
which is required. The slider's dead centres are ``sqrt((l2 + l1)^2 - offset^2)`` (outer) and
``sqrt((l2 - l1)^2 - offset^2)`` (inner).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from clearbench.scenarios.analytic.common import as_times, require_finite, require_positive

__all__ = ["SliderCrankMotion", "slider_crank_dead_centres", "slider_crank_motion"]


@dataclass(frozen=True)
class SliderCrankMotion:
    """Closed-form motion of the slider–crank; every array has the shape of the time samples.

    Attributes
    ----------
    crank_angle : ndarray
        phi [rad].
    slider_position : ndarray
        x, along the slider line from the foot of the perpendicular through the crank pivot
        [length].
    slider_velocity : ndarray
        dx/dt [length / time].
    slider_acceleration : ndarray
        d^2x/dt^2 [length / time^2].
    rod_angle : ndarray
        psi, direction of crank pin -> slider from +x, in (-pi/2, pi/2) [rad].
    rod_angular_velocity : ndarray
        dpsi/dt [rad / time].
    rod_angular_acceleration : ndarray
        d^2psi/dt^2 [rad / time^2].
    """

    crank_angle: np.ndarray
    slider_position: np.ndarray
    slider_velocity: np.ndarray
    slider_acceleration: np.ndarray
    rod_angle: np.ndarray
    rod_angular_velocity: np.ndarray
    rod_angular_acceleration: np.ndarray


def _check_linkage(crank_length: float, rod_length: float, offset: float):
    crank_length = require_positive("crank_length", crank_length)
    rod_length = require_positive("rod_length", rod_length)
    offset = require_finite("offset", offset)
    if rod_length <= crank_length + abs(offset):
        raise ValueError(
            f"rod_length = {rod_length!r}: must exceed crank_length + |offset| = "
            f"{crank_length + abs(offset)!r} for the crank to turn fully"
        )
    return crank_length, rod_length, offset


def slider_crank_dead_centres(
    crank_length: float, rod_length: float, offset: float = 0.0
) -> tuple[float, float]:
    """Inner and outer dead-centre positions of the slider.

    Parameters
    ----------
    crank_length : float
        Crank length l1 (pivot to crank pin) [length], > 0.
    rod_length : float
        Connecting-rod length l2 (crank pin to slider pin) [length], > l1 + |offset|.
    offset : float
        Distance of the slider line from the crank pivot, signed along +y [length].

    Returns
    -------
    (float, float)
        ``(sqrt((l2 - l1)^2 - e^2), sqrt((l2 + l1)^2 - e^2))`` [length]; the stroke is their
        difference (2 l1 when e = 0).
    """
    l1, l2, e = _check_linkage(crank_length, rod_length, offset)
    return math.sqrt((l2 - l1) ** 2 - e**2), math.sqrt((l2 + l1) ** 2 - e**2)


def slider_crank_motion(
    t,
    crank_length: float,
    rod_length: float,
    crank_speed: float,
    *,
    offset: float = 0.0,
    crank_angle0: float = 0.0,
) -> SliderCrankMotion:
    """Slider and rod motion of a slider–crank whose crank turns at constant angular velocity.

    With ``phi = phi0 + omega t`` and psi the rod angle (module docstring):

    * ``psi' = -l1 omega cos(phi) / (l2 cos(psi))``
    * ``psi'' = (l1 omega^2 sin(phi) + l2 psi'^2 sin(psi)) / (l2 cos(psi))``
    * ``x' = -l1 omega sin(phi - psi) / cos(psi)``
    * ``x'' = -l1 omega^2 cos(phi) - l2 (psi'^2 cos(psi) + psi'' sin(psi))``

    Parameters
    ----------
    t : array_like, any shape
        Times [time] (any sign).
    crank_length : float
        Crank length l1 [length], > 0.
    rod_length : float
        Connecting-rod length l2 [length], > l1 + |offset|.
    crank_speed : float
        Crank angular velocity omega [rad / time] (signed, counter-clockwise positive).
    offset : float
        Signed distance of the slider line from the crank pivot along +y [length].
    crank_angle0 : float
        Crank angle at t = 0 [rad].

    Returns
    -------
    SliderCrankMotion
        Positions, velocities and accelerations, each of the shape of ``t``.
    """
    l1, l2, e = _check_linkage(crank_length, rod_length, offset)
    omega = require_finite("crank_speed", crank_speed)
    phi0 = require_finite("crank_angle0", crank_angle0)
    times = as_times(t, non_negative=False)
    phi = phi0 + omega * times
    sin_phi, cos_phi = np.sin(phi), np.cos(phi)
    sin_psi = (e - l1 * sin_phi) / l2
    cos_psi = np.sqrt(1.0 - sin_psi**2)  # > 0 since l2 > l1 + |e|
    psi = np.arctan2(sin_psi, cos_psi)
    psi_dot = -l1 * omega * cos_phi / (l2 * cos_psi)
    psi_ddot = (l1 * omega**2 * sin_phi + l2 * psi_dot**2 * sin_psi) / (l2 * cos_psi)
    position = l1 * cos_phi + l2 * cos_psi
    velocity = -l1 * omega * (sin_phi * cos_psi - cos_phi * sin_psi) / cos_psi
    acceleration = -l1 * omega**2 * cos_phi - l2 * (psi_dot**2 * cos_psi + psi_ddot * sin_psi)
    return SliderCrankMotion(phi, position, velocity, acceleration, psi, psi_dot, psi_ddot)
