"""The solid around a bore and a cylinder's solid, the signed distance of a point to each, and a
ring's point nearest either.

A bore's solid, in the bore's own frame (axis z, angles from x toward y): the material outside
the hole, radius <= rho <= radius + depth (depth 0: unbounded outward), within the bore's angles
[start, start + span] (span >= 2 pi: all of them) and |z| <= half_length. It is the product of
an annular sector of the (x, y) plane and the interval |z| <= half_length, so its signed
distance combines theirs as a disc face's solid does (:func:`.face_solids.product_distance`).

A cylinder's solid, in its frame (axis z): the disc rho <= radius times |z| <= half_length,
a product in the same way.

:func:`ring_solid_minimum` finds the ring (or arc) point of smallest signed distance to either
solid. :mod:`.bores` uses it where its closed form (the ring point farthest from the axis)
is not that point: the farthest point outside the bore's angles or beyond its ends, or deeper
in the solid than the distance to a nearer boundary (an end face, a cut face, the back);
:mod:`.ring_cylinders` where the ring point nearest the cylinder's axis is not: past the
cylinder's end, or deeper than the distance to an end face.
"""

from __future__ import annotations

import math

import numpy as np

from clearbench.kernels.gaps.codes import TWO_PI
from clearbench.kernels.gaps.face_solids import product_distance, through_thickness
from clearbench.kernels.gaps.rings import arc_angle_in_range
from clearbench.kernels.jit import njit

#: Ring angles sampled before the refinement: 64 over a whole ring (0.1 rad apart), enough to
#: put the smallest sample in the basin of the smallest minimum for rings nearly coaxial with
#: the bore (the function has at most a few minima, each wider than that spacing).
RING_SAMPLES = 64
#: Golden-section steps of the refinement: they shrink the bracket (two sample spacings, at
#: most 0.2 rad) by 0.618 each, to 0.2 * 0.618^60 = 6e-14 rad, so the gap is exact to
#: radius x 6e-14 at a kink and to round-off at a smooth minimum.
GOLDEN_STEPS = 60
_GOLDEN = 0.5 * (math.sqrt(5.0) - 1.0)
#: Sampled local minima refined at most, the smallest sample's first: two basins can hold
#: nearly equal minima (an arc across a partial bore's cut: 0.067346 and 0.067350 in basins
#: 0.7 rad apart), which the smallest sample alone does not tell apart.
REFINED_BASINS = 3
#: The solids of :func:`ring_solid_minimum`.
BORE_SOLID, CYLINDER_SOLID = 0, 1


@njit(cache=True, inline="always")
def _cut_face(x, y, angle, radius, depth):
    """Distance [L] from (x, y) to the cut face of the sector at ``angle`` (the segment from
    radius to radius + depth along that angle; depth 0: the ray from radius), and the unit
    vector from its closest point to (x, y) (0, 0 when on it)."""
    c, s = math.cos(angle), math.sin(angle)
    along = max(x * c + y * s, radius)
    if depth > 0.0:
        along = min(along, radius + depth)
    dx, dy = x - along * c, y - along * s
    distance = math.hypot(dx, dy)
    if distance > 0.0:
        return distance, dx / distance, dy / distance
    return 0.0, 0.0, 0.0


@njit(cache=True)
def _sector_distance(radius, start_angle, span, depth, x, y):
    """Signed distance [L] from (x, y) to the annular sector of the bore's cross-section
    (module docstring) and its unit gradient: > 0 outside, < 0 inside (the outward normal of
    the nearest boundary: the inner or outer arc on ties)."""
    radial = math.hypot(x, y)
    if radial > 0.0:
        u_x, u_y = x / radial, y / radial
    else:
        u_x, u_y = 1.0, 0.0
    # The annulus alone: its thickness measured from the bore's surface outward (the face's
    # thickness below its top plane); side +1 toward the surface, -1 toward the back.
    annulus, toward_surface = through_thickness(radius - radial, depth)
    side = -toward_surface
    if span >= TWO_PI:
        return annulus, side * u_x, side * u_y
    end_angle = start_angle + span
    within = arc_angle_in_range(math.atan2(y, x), start_angle, span)
    start_distance, start_x, start_y = _cut_face(x, y, start_angle, radius, depth)
    end_distance, end_x, end_y = _cut_face(x, y, end_angle, radius, depth)
    if not within:
        # Outside the angles, the closest point is on a cut face (an arc's nearest point to a
        # point outside its angles is one of its ends, which are the cut faces' ends).
        if start_distance <= end_distance:
            return start_distance, start_x, start_y
        return end_distance, end_x, end_y
    if annulus > 0.0:
        # Inside the angles, off the annulus: the arc at the point's own angle is nearest (a
        # cut face's points lie within the annulus's radii: no nearer than it).
        return annulus, side * u_x, side * u_y
    # Inside: minus the distance to the nearest boundary.
    if -annulus <= start_distance and -annulus <= end_distance:
        return annulus, side * u_x, side * u_y
    if start_distance <= end_distance:
        if start_distance > 0.0:
            return -start_distance, -start_x, -start_y
        return 0.0, math.sin(start_angle), -math.cos(start_angle)
    if end_distance > 0.0:
        return -end_distance, -end_x, -end_y
    return 0.0, -math.sin(end_angle), math.cos(end_angle)


@njit(cache=True)
def bore_solid_distance(radius, half_length, start_angle, span, depth, local):
    """Signed distance [L] from the bore-frame point ``local`` (3-tuple) to the bore's solid
    (module docstring) and its unit gradient (bore frame): > 0 outside (the direction from the
    solid's closest point), < 0 inside (the outward normal of the nearest boundary: the
    cross-section's on ties with an end face). ``half_length`` inf: no ends.

    Parameters
    ----------
    radius, half_length, depth : float
        The bore's radius, half length and depth (0: unbounded outward) [L].
    start_angle, span : float
        The bore's angles [rad]; span >= 2 pi: a full bore.
    local : tuple of 3 floats
        The point in the bore's frame [L].
    """
    x, y, z = local
    across, g_x, g_y = _sector_distance(radius, start_angle, span, depth, x, y)
    return product_distance(across, (g_x, g_y, 0.0), abs(z) - half_length,
                            (0.0, 0.0, 1.0 if z >= 0.0 else -1.0))


@njit(cache=True)
def cylinder_solid_distance(radius, half_length, local):
    """Signed distance [L] from the cylinder-frame point ``local`` (3-tuple) to the cylinder's
    solid (module docstring) and its unit gradient (cylinder frame), as
    :func:`bore_solid_distance` (a point on the axis takes the frame's x as its radial
    direction)."""
    x, y, z = local
    rho = math.hypot(x, y)
    radial = (x / rho, y / rho, 0.0) if rho > 0.0 else (1.0, 0.0, 0.0)
    return product_distance(rho - radius, radial, abs(z) - half_length,
                            (0.0, 0.0, 1.0 if z >= 0.0 else -1.0))


@njit(cache=True, inline="always")
def _solid_distance(solid, radius, half_length, start_angle, span, depth, local):
    """:func:`cylinder_solid_distance` for ``CYLINDER_SOLID`` (angles and depth unused), else
    :func:`bore_solid_distance`."""
    if solid == CYLINDER_SOLID:
        return cylinder_solid_distance(radius, half_length, local)
    return bore_solid_distance(radius, half_length, start_angle, span, depth, local)


@njit(cache=True, inline="always")
def _ring_local_point(centre, e1, e2, ring_radius, theta):
    c, s = math.cos(theta), math.sin(theta)
    return (centre[0] + ring_radius * (c * e1[0] + s * e2[0]),
            centre[1] + ring_radius * (c * e1[1] + s * e2[1]),
            centre[2] + ring_radius * (c * e1[2] + s * e2[2]))


@njit(cache=True)
def _ring_distance(solid, centre, e1, e2, ring_radius, theta, radius, half_length, start_angle,
                   span, depth):
    point = _ring_local_point(centre, e1, e2, ring_radius, theta)
    distance, _ = _solid_distance(solid, radius, half_length, start_angle, span, depth, point)
    return distance


@njit(cache=True, inline="always")
def _is_sampled_minimum(values, k, is_arc):
    """True if sample ``k`` is no larger than its neighbours (a ring's samples wrap around; an
    arc's end has one neighbour)."""
    count = values.size
    if is_arc:
        left = values[k - 1] if k > 0 else np.inf
        right = values[k + 1] if k < count - 1 else np.inf
    else:
        left = values[(k - 1) % count]
        right = values[(k + 1) % count]
    return values[k] <= left and values[k] <= right


@njit(cache=True)
def _golden_section(solid, centre, e1, e2, ring_radius, first, extent, is_arc, spacing, k,
                    sampled, radius, half_length, start_angle, span, depth):
    """(angle [rad], distance [L]): the smallest of sample ``k`` (value ``sampled``) and the
    golden-section search's last two points between its neighbours (an arc's bracket clipped to
    the arc)."""
    low = first + (k - 1) * spacing
    high = first + (k + 1) * spacing
    if is_arc:
        low = max(low, first)
        high = min(high, first + extent)
    inner = high - _GOLDEN * (high - low)
    outer = low + _GOLDEN * (high - low)
    f_inner = _ring_distance(solid, centre, e1, e2, ring_radius, inner, radius, half_length,
                             start_angle, span, depth)
    f_outer = _ring_distance(solid, centre, e1, e2, ring_radius, outer, radius, half_length,
                             start_angle, span, depth)
    for _ in range(GOLDEN_STEPS):
        if f_inner <= f_outer:
            high, outer, f_outer = outer, inner, f_inner
            inner = high - _GOLDEN * (high - low)
            f_inner = _ring_distance(solid, centre, e1, e2, ring_radius, inner, radius,
                                     half_length, start_angle, span, depth)
        else:
            low, inner, f_inner = inner, outer, f_outer
            outer = low + _GOLDEN * (high - low)
            f_outer = _ring_distance(solid, centre, e1, e2, ring_radius, outer, radius,
                                     half_length, start_angle, span, depth)
    theta = first + k * spacing
    best = sampled
    for candidate, value in ((inner, f_inner), (outer, f_outer)):
        if value < best:
            theta, best = candidate, value
    return theta, best


@njit(cache=True)
def ring_solid_minimum(solid, centre, e1, e2, ring_radius, ring_start, ring_span, is_arc, radius,
                       half_length, start_angle, span, depth):
    """The ring (arc) point of smallest signed distance to the solid (``BORE_SOLID`` or
    ``CYLINDER_SOLID``), everything in the solid's frame: (angle [rad], distance [L], point
    (3-tuple) [L], gradient (3-tuple)).

    The distance is sampled at RING_SAMPLES angles over the ring (the arc, ends included) and
    minimised by golden-section search (GOLDEN_STEPS) between the neighbours of the best sample
    and of the next REFINED_BASINS - 1 sampled local minima; the smallest result is kept.

    Parameters
    ----------
    centre, e1, e2 : tuple of 3 floats
        The ring's centre [L] and its in-plane axes (unit) in the bore's frame.
    ring_radius, ring_start, ring_span : float
        The ring's radius [L]; an arc's first angle and span [rad] (``is_arc``).
    radius, half_length, start_angle, span, depth : float
        The bore (:func:`bore_solid_distance`); a cylinder's radius and half length (the
        angles and depth unused).
    """
    first = ring_start if is_arc else 0.0
    extent = ring_span if is_arc else TWO_PI
    count = RING_SAMPLES if not is_arc else max(2, int(RING_SAMPLES * extent / TWO_PI) + 1)
    spacing = extent / count if not is_arc else extent / (count - 1)
    values = np.empty(count)
    best_k = 0
    for k in range(count):
        values[k] = _ring_distance(solid, centre, e1, e2, ring_radius, first + k * spacing,
                                   radius, half_length, start_angle, span, depth)
        if values[k] < values[best_k]:
            best_k = k
    theta, best = _golden_section(solid, centre, e1, e2, ring_radius, first, extent, is_arc,
                                  spacing, best_k, values[best_k], radius, half_length,
                                  start_angle, span, depth)
    # The next sampled local minima, smallest first (a ring, periodic; an arc's ends count).
    refined = np.zeros(count, dtype=np.bool_)
    refined[best_k] = True
    for _ in range(REFINED_BASINS - 1):
        next_k = -1
        for k in range(count):
            if refined[k] or not _is_sampled_minimum(values, k, is_arc):
                continue
            if next_k < 0 or values[k] < values[next_k]:
                next_k = k
        if next_k < 0:
            break
        refined[next_k] = True
        angle, value = _golden_section(solid, centre, e1, e2, ring_radius, first, extent,
                                       is_arc, spacing, next_k, values[next_k], radius,
                                       half_length, start_angle, span, depth)
        if value < best:
            theta, best = angle, value
    point = _ring_local_point(centre, e1, e2, ring_radius, theta)
    distance, gradient = _solid_distance(solid, radius, half_length, start_angle, span, depth,
                                         point)
    return theta, distance, point, gradient


@njit(cache=True)
def radial_exit_is_nearest(gap, local, radius, half_length, start_angle, span, depth):
    """True if a point at radial ``gap`` [L] (< 0: that deep beyond the bore's surface) at the
    bore-frame point ``local`` leaves the solid no nearer through an end face, the back or a cut
    face: the radial depth is then its signed distance. ``half_length`` inf: no ends."""
    if gap >= 0.0:
        return True
    deepest = -gap
    if half_length - abs(local[2]) < deepest:
        return False
    if depth > 0.0 and depth + gap < deepest:
        return False
    if span >= TWO_PI:
        return True
    start_distance, _, _ = _cut_face(local[0], local[1], start_angle, radius, depth)
    end_distance, _, _ = _cut_face(local[0], local[1], start_angle + span, radius, depth)
    return start_distance >= deepest and end_distance >= deepest
