"""Ring (circle or arc) against the lateral surface of a cylinder: the ring angle of the point
nearest (or farthest from) a line, shared with the ring inside a bore (:mod:`.bores`). A ring
against a face is :mod:`.ring_faces`."""

from __future__ import annotations

import math

import numpy as np

from clearbench.kernels.gaps.codes import TWO_PI
from clearbench.kernels.gaps.staging import stage_contact
from clearbench.kernels.gaps.vectors import (
    add,
    any_perpendicular,
    axpy,
    column_of,
    dot,
    norm,
    scaled,
    sub,
)
from clearbench.kernels.jit import njit

#: Second/first harmonic ratio 2 r2 / r1 below which the ring-cylinder angle function has a
#: single minimum inside |x| <= asin(ratio), on which it is convex (see _ring_angle).
_RING_FAST_PATH_RATIO = 0.4
#: A Newton step on the ring angle below this (rad) leaves an error of order its square.
_NEWTON_FINAL_STEP = 1e-9


@njit(cache=True, inline="always")
def arc_angle_in_range(angle, start_angle, span):
    """True if ``angle`` lies in [start_angle, start_angle + span] modulo 2 pi."""
    return (angle - start_angle) % TWO_PI <= span


@njit(cache=True, inline="always")
def _ring_derivatives(theta, a1, b1, a2, b2):
    """First and second derivatives of f(theta) = a1 cos + b1 sin + a2 cos 2 + b2 sin 2."""
    c, s = math.cos(theta), math.sin(theta)
    c2, s2 = c * c - s * s, 2.0 * s * c
    first = -a1 * s + b1 * c - 2.0 * a2 * s2 + 2.0 * b2 * c2
    second = -a1 * c - b1 * s - 4.0 * a2 * c2 - 4.0 * b2 * s2
    return first, second


@njit(cache=True)
def ring_axis_distance(theta, centre_offset, e1, e2, ring_radius, axis):
    """Distance from the ring point at ``theta`` to the cylinder axis, and the perpendicular
    vector from the axis to the point."""
    c, s = math.cos(theta), math.sin(theta)
    relative = add(centre_offset, add(scaled(e1, ring_radius * c), scaled(e2, ring_radius * s)))
    perpendicular = axpy(-dot(relative, axis), axis, relative)
    return norm(perpendicular), perpendicular


@njit(cache=True)
def _ring_newton_bracketed(theta_centre, half_width, a1, b1, a2, b2):
    """The single root of f' in [theta_centre - half_width, theta_centre + half_width], where f'
    is increasing: Newton steps kept inside a shrinking bracket (bisection when a step leaves
    it). Newton converges quadratically on this bracket (f'' > 0 there, and |f'''| is at most a
    few times f''), so once a Newton step is below _NEWTON_FINAL_STEP the next iterate is exact
    to round-off and is returned."""
    low = theta_centre - half_width
    high = theta_centre + half_width
    theta = theta_centre
    for _ in range(60):
        first, second = _ring_derivatives(theta, a1, b1, a2, b2)
        if first == 0.0:
            return theta
        if first > 0.0:
            high = theta
        else:
            low = theta
        candidate = theta - first / second if second > 0.0 else 0.5 * (low + high)
        newton_step = low < candidate < high
        if not newton_step:
            candidate = 0.5 * (low + high)
        elif abs(candidate - theta) <= _NEWTON_FINAL_STEP:
            return candidate
        theta = candidate
        if high - low <= 4e-16 * (1.0 + abs(theta)):
            return theta
    return theta


@njit(cache=True)
def _ring_critical_angles(a1, b1, a2, b2):
    """All stationary angles of f(theta) = a1 cos + b1 sin + a2 cos 2 + b2 sin 2.

    With z = exp(i theta), f'(theta) = Re(C1 z + C2 z^2), C1 = b1 + i a1, C2 = 2 (b2 + i a2);
    on |z| = 1 its zeros are the unit-modulus roots of C2 z^4 + C1 z^3 + conj(C1) z +
    conj(C2). The angles of all four roots are returned, each polished by Newton steps on f'
    (roots off the unit circle give harmless extra candidates)."""
    c1 = complex(b1, a1)
    c2 = complex(2.0 * b2, 2.0 * a2)
    coefficients = np.empty(5, dtype=np.complex128)
    coefficients[0] = c2
    coefficients[1] = c1
    coefficients[2] = 0.0
    coefficients[3] = c1.conjugate()
    coefficients[4] = c2.conjugate()
    roots = np.roots(coefficients)
    angles = np.empty(roots.shape[0])
    for k in range(roots.shape[0]):
        theta = math.atan2(roots[k].imag, roots[k].real)
        for _ in range(4):
            first, second = _ring_derivatives(theta, a1, b1, a2, b2)
            if second == 0.0:
                break
            step = -first / second
            if abs(step) > 0.1:
                break
            theta += step
        angles[k] = theta
    return angles


@njit(cache=True)
def ring_angle(centre_offset, e1, e2, ring_radius, axis, start_angle, span, is_arc, sign):
    """Angle of the ring (arc) point nearest the cylinder axis (``sign`` = 1), or farthest from
    it (``sign`` = -1: a ring inside a bore).

    The farthest point is the nearest one for -f: every coefficient and every distance
    comparison below is multiplied by ``sign``.

    The squared distance of the ring point c + rho (cos t e1 + sin t e2) to the axis line is,
    up to a constant, the trigonometric polynomial f = a1 cos t + b1 sin t + a2 cos 2t +
    b2 sin 2t with a1 = 2 rho s.e1, b1 = 2 rho s.e2 (s = perpendicular offset of the ring
    centre from the axis: the projected eccentricity), a2 = -rho^2 (beta1^2 - beta2^2) / 2,
    b2 = -rho^2 beta1 beta2 (beta_i = e_i . axis: the tilt). Parallel axes give a2 = b2 = 0 and
    the closed form t = atan2(-b1, -a1). When 2 r2 / r1 <= 0.4 (r_k the harmonic amplitudes),
    f has one minimum, within asin(2 r2 / r1) of that closed form, where f is convex: bracketed
    Newton from the closed form. Otherwise (small eccentricity against large tilt; two minima
    are possible) every stationary point is found from a quartic and the best is kept.
    """
    s = axpy(-dot(centre_offset, axis), axis, centre_offset)
    a1 = sign * 2.0 * ring_radius * dot(s, e1)
    b1 = sign * 2.0 * ring_radius * dot(s, e2)
    beta1 = dot(e1, axis)
    beta2 = dot(e2, axis)
    rho_squared = ring_radius * ring_radius
    a2 = -sign * 0.5 * rho_squared * (beta1 * beta1 - beta2 * beta2)
    b2 = -sign * rho_squared * beta1 * beta2
    r1 = math.hypot(a1, b1)
    r2 = math.hypot(a2, b2)
    if r1 == 0.0 and r2 == 0.0:
        # Concentric, parallel: every point is at the same distance.
        return start_angle if is_arc else 0.0
    best_angle = 0.0
    best_distance = np.inf
    if 2.0 * r2 <= _RING_FAST_PATH_RATIO * r1:
        half_width = math.asin(2.0 * r2 / r1)
        theta = _ring_newton_bracketed(math.atan2(-b1, -a1), half_width, a1, b1, a2, b2)
        if not is_arc or arc_angle_in_range(theta, start_angle, span):
            return theta
        # f has one minimum and one maximum on the circle: off the minimum, the best point of
        # an arc is one of its ends.
    else:
        angles = _ring_critical_angles(a1, b1, a2, b2)
        for k in range(angles.shape[0]):
            if is_arc and not arc_angle_in_range(angles[k], start_angle, span):
                continue
            distance, _ = ring_axis_distance(angles[k], centre_offset, e1, e2, ring_radius, axis)
            if sign * distance < best_distance:
                best_angle, best_distance = angles[k], sign * distance
        if not is_arc:
            return best_angle
    for theta in (start_angle, start_angle + span):
        distance, _ = ring_axis_distance(theta, centre_offset, e1, e2, ring_radius, axis)
        if sign * distance < best_distance:
            best_angle, best_distance = theta, sign * distance
    return best_angle


@njit(cache=True)
def ring_cylinder(ring_position, ring_rotation, ring_radius, start_angle, span, is_arc,
                  cylinder_position, cylinder_rotation, cylinder_radius, stage):
    """Ring (A) against the lateral surface of the cylinder (B), taken as infinitely long.

    gap = min over ring points of (distance to the cylinder axis) - cylinder radius. The same
    formula covers the journal inside the bore (INTERNAL: axis inside the ring; gap =
    R_ring - R_cyl - e for parallel axes at eccentricity e) and the ring outside a pin
    (EXTERNAL: gap = e - R_ring - R_cyl). The normal points from the ring point toward the
    axis (from A into B), perpendicular to the axis.
    """
    axis = column_of(cylinder_rotation, 2)
    e1 = column_of(ring_rotation, 0)
    e2 = column_of(ring_rotation, 1)
    centre_offset = sub(ring_position, cylinder_position)
    theta = ring_angle(centre_offset, e1, e2, ring_radius, axis, start_angle, span, is_arc,
                       1.0)
    distance, perpendicular = ring_axis_distance(theta, centre_offset, e1, e2, ring_radius,
                                                 axis)
    if distance > 0.0:
        inward = scaled(perpendicular, -1.0 / distance)
    else:
        inward = any_perpendicular(axis)
    c, s = math.cos(theta), math.sin(theta)
    ring_point = add(ring_position, add(scaled(e1, ring_radius * c),
                                          scaled(e2, ring_radius * s)))
    stage_contact(stage, 0, distance - cylinder_radius, ring_point, inward)
    return 1
