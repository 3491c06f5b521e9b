"""A bare ring (circle or arc) at a face's edge: the contact as the ring against the edge
line, along their common normal.

Outside the solid, the gap of a ring point is its distance to the solid
(:func:`~.face_solids.face_solid_distance`); at the ring's closest point beyond the face's bound
that is its distance to the edge, and the normal is the direction from the edge to that point.
As the gap goes to zero that direction is the difference of two nearly equal points, fixed by
the angle minimisation's tolerance rather than by the geometry; at or just inside the solid the
solid's normal is that of the nearest face. A hoop pivoting over an edge, its centre line on the
edge to round-off, was so pushed along the top face's normal or the side face's, off its centre,
and spun (measured on ``hoop-off-edge`` without friction: 1.9 rad/s of spin, a path 25 % off the
closed form).

A local minimum of the ring's gap within :data:`EDGE_BAND` of the radius from an edge (outside,
or inside at most that deep) is an edge contact: the ring point nearest the edge line
(:func:`~.rings.ring_angle`, to round-off), the normal the common normal of the ring and the
edge (ring tangent x edge direction, turned out of the solid), the gap the signed distance along
it. Gap and normal are then continuous as the ring passes over the edge, and the normal is
exact however small the gap. Deeper inside, the nearest face's depth and normal are kept (a
ring with a contact offset, a torus, keeps a continuous normal by the offset instead while its
penetration stays below it: :mod:`.ring_faces`).

Edges: a rectangle's (top or bottom face with a side face: a line along the other side's axis;
two side faces: a vertical line); a disc's rim, taken as its tangent line at the rim point
nearest the ring point (exact within the band). A plane has no edge. Face frame throughout (the
solid's, material below z = 0).
"""

from __future__ import annotations

import math

from clearbench.kernels.gaps.codes import DISC, PLANE, TWO_PI
from clearbench.kernels.gaps.face_solids import through_thickness
from clearbench.kernels.gaps.rings import ring_angle, ring_axis_distance
from clearbench.kernels.gaps.vectors import add, cross, dot, norm, scaled, sub
from clearbench.kernels.jit import njit

#: A minimum within EDGE_BAND * radius of an edge line (beyond its own distance to the solid)
#: is an edge contact: its point's distance to the edge is then of the order of the angle's
#: minimisation tolerance (1e-9 rad), whose direction is no normal. Inside the solid, only a
#: minimum at most this deep: there the common normal's separation exceeds the deepest point's
#: depth below its nearest face by up to sqrt(2) - 1 of it, so that the gap stays the deepest
#: point's depth to 0.5e-8 of the radius (the instrument's agreement, within 1e-8 m on shapes
#: up to 2 m: tests/test_kernel_against_instrument.py).
EDGE_BAND = 1e-8
#: |ring tangent x edge direction| below this, the ring runs along the edge: no common
#: normal, the minimum keeps the solid's normal; and the cosine slack of the check that the
#: separation of a ring apart from the edge lies along the common normal.
_PARALLEL = 1e-6
#: Reach along a disc's rim tangent line, relative to the rim's radius, within which the line
#: stands for the rim: the rim departs from it by reach^2 / 2 = 5e-9 of the radius, below the
#: instrument's agreement (1e-8 m on shapes up to 2 m).
_RIM_REACH = 1e-4
#: Face codes of a face solid's boundary (axis of the face's outward normal, with its side).
_FACE_X, _FACE_Y, _FACE_Z, _FACE_RIM = 0, 1, 2, 3
#: The unset point and normal of a candidate that is no edge contact.
_NONE = (0.0, 0.0, 0.0)


@njit(cache=True, inline="always")
def ring_point(centre, e1, e2, radius, theta):
    """Point of the ring's centre line at ``theta`` (the frame ``centre``, ``e1``, ``e2`` are
    in)."""
    return add(centre, add(scaled(e1, radius * math.cos(theta)),
                           scaled(e2, radius * math.sin(theta))))


@njit(cache=True)
def _edge_line(kind, size_1, size_2, depth, face_a, side_a, face_b, side_b, near):
    """(point, direction, outward) of the edge between two boundary faces (face frame): a point
    of its line, its unit direction, and the sum of the two faces' outward normals; for a
    disc's rim, its tangent line at the rim point nearest ``near``."""
    if face_b == _FACE_Z:
        face_a, side_a, face_b, side_b = face_b, side_b, face_a, side_a
    if face_a == _FACE_Z:
        level = 0.0 if side_a > 0.0 else -depth
        if kind == DISC:
            radial = math.hypot(near[0], near[1])
            u_x, u_y = (near[0] / radial, near[1] / radial) if radial > 0.0 else (1.0, 0.0)
            return (size_1 * u_x, size_1 * u_y, level), (-u_y, u_x, 0.0), (u_x, u_y, side_a)
        if face_b == _FACE_X:
            return ((side_b * size_1, 0.0, level), (0.0, 1.0, 0.0), (side_b, 0.0, side_a))
        return (0.0, side_b * size_2, level), (1.0, 0.0, 0.0), (0.0, side_b, side_a)
    side_x, side_y = (side_a, side_b) if face_a == _FACE_X else (side_b, side_a)
    return ((side_x * size_1, side_y * size_2, 0.0), (0.0, 0.0, 1.0), (side_x, side_y, 0.0))


@njit(cache=True)
def _nearest_edge_faces(kind, size_1, size_2, depth, point):
    """The two boundary faces nearest ``point`` (face frame), as (face, side) pairs: those of
    the two largest box coordinates (their edge is the solid's edge nearest the point), and
    the point's distance to that edge's line [L]."""
    x, y, z = point
    q_z, side_z = through_thickness(z, depth)
    if kind == DISC:
        q_r = math.hypot(x, y) - size_1
        return _FACE_Z, side_z, _FACE_RIM, 1.0, math.hypot(q_r, q_z)
    q_x, side_x = abs(x) - size_1, 1.0 if x >= 0.0 else -1.0
    q_y, side_y = abs(y) - size_2, 1.0 if y >= 0.0 else -1.0
    if q_z <= q_x and q_z <= q_y:
        return _FACE_X, side_x, _FACE_Y, side_y, math.hypot(q_x, q_y)
    if q_y <= q_x:
        return _FACE_Z, side_z, _FACE_X, side_x, math.hypot(q_x, q_z)
    return _FACE_Z, side_z, _FACE_Y, side_y, math.hypot(q_y, q_z)


@njit(cache=True)
def _within_edge(kind, size_1, size_2, depth, edge_point, direction, along):
    """True if the point ``along`` [L] from ``edge_point`` on the edge line (of
    :func:`_edge_line`) lies on the edge itself: within the rectangle's side, above the
    solid's bottom for a vertical edge, and for a disc's rim close enough to the tangent point
    that the tangent line is the rim (:data:`_RIM_REACH`)."""
    if kind == DISC:
        return abs(along) <= _RIM_REACH * size_1
    position = edge_point[0] + along * direction[0], edge_point[1] + along * direction[1], \
        edge_point[2] + along * direction[2]
    if direction[2] != 0.0:
        return position[2] <= 0.0 and (depth <= 0.0 or position[2] >= -depth)
    if direction[1] != 0.0:
        return abs(position[1]) <= size_2
    return abs(position[0]) <= size_1


@njit(cache=True)
def edge_continuation(theta, value, centre, e1, e2, radius, kind, size_1, size_2, depth,
                      spacing, low_limit, high_limit):
    """The ring against a face's edge, for the local minimum at ``theta`` of the ring's gap
    (value ``value`` [L]) when it is an edge contact (module docstring).

    ``spacing`` [rad]: the minima search's sample spacing; ``low_limit``, ``high_limit``: an
    arc's ends (+-inf for a circle). Returns (is_edge, gap [L], point on the edge, unit normal
    out of the solid), face frame; ``is_edge`` False (the other values unset) where the
    minimum is not at an edge.
    """
    if kind == PLANE:
        return False, 0.0, _NONE, _NONE
    near = ring_point(centre, e1, e2, radius, theta)
    to_edge = _nearest_edge_faces(kind, size_1, size_2, depth, near)[4]
    band = EDGE_BAND * radius
    if value < 0.0:
        # Inside: the deepest point of an arc cut off the edge lies on the edge's bisector,
        # sqrt(2) times its depth from the edge.
        if value < -band or to_edge > math.sqrt(2.0) * -value + band:
            return False, 0.0, _NONE, _NONE
    elif to_edge > value + band:
        return False, 0.0, _NONE, _NONE
    return ring_edge_contact(theta, centre, e1, e2, radius, kind, size_1, size_2, depth,
                             max(theta - spacing, low_limit), min(theta + spacing, high_limit))


@njit(cache=True)
def ring_edge_contact(theta, centre, e1, e2, radius, kind, size_1, size_2, depth, low, high):
    """The ring against the line of the solid's edge nearest its point at ``theta``, along
    their common normal, when the ring's point nearest that line lies within (low, high)
    [rad] and on the edge itself (module docstring). Returns (is_edge, gap [L], point on the
    edge, unit normal out of the solid), face frame; ``is_edge`` False (the other values
    unset) otherwise: no edge (a plane), the ring's nearest point outside the window, the ring
    along the edge, apart from it off their common normal, or past the edge's ends.
    """
    if kind == PLANE:
        return False, 0.0, _NONE, _NONE
    near = ring_point(centre, e1, e2, radius, theta)
    face_a, side_a, face_b, side_b, _ = _nearest_edge_faces(kind, size_1, size_2, depth, near)
    edge_point, direction, outward = _edge_line(kind, size_1, size_2, depth, face_a, side_a,
                                                face_b, side_b, near)
    offset = sub(centre, edge_point)
    angle = ring_angle(offset, e1, e2, radius, direction, low, high - low, True, 1.0)
    angle = low + (angle - low) % TWO_PI  # ring_angle's angle is modulo 2 pi
    if not low < angle < high:
        # The ring's nearest point to the line is not within the window: the ring does not
        # pass the edge there (a ring around a disc's rim in its plane).
        return False, 0.0, _NONE, _NONE
    tangent = add(scaled(e1, -math.sin(angle)), scaled(e2, math.cos(angle)))
    normal = cross(tangent, direction)
    length = norm(normal)
    if not length > _PARALLEL:
        return False, 0.0, _NONE, _NONE
    normal = scaled(normal, (1.0 if dot(normal, outward) >= 0.0 else -1.0) / length)
    distance, perpendicular = ring_axis_distance(angle, offset, e1, e2, radius, direction)
    if (distance > EDGE_BAND * radius
            and abs(dot(perpendicular, normal)) < (1.0 - _PARALLEL) * distance):
        # Apart, the ring and the line are not joined along their common normal (the nearest
        # point is no interior critical point of the distance): not an edge contact.
        return False, 0.0, _NONE, _NONE
    on_ring = ring_point(centre, e1, e2, radius, angle)
    along = dot(sub(on_ring, edge_point), direction)
    if not _within_edge(kind, size_1, size_2, depth, edge_point, direction, along):
        return False, 0.0, _NONE, _NONE
    gap = dot(sub(on_ring, edge_point), normal)
    return True, gap, sub(on_ring, scaled(normal, gap)), normal
