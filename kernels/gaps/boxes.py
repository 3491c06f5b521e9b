"""Box against box: the separating-axis choice of the contact feature, then face clipping
(Sutherland-Hodgman) or one edge-edge contact; separated, the boxes' distance.

Face clipping keeps the incident face's points over the reference face's rectangle, and their
heights above it are distances only there: two separated boxes whose nearest points lie past the
rectangle's bound (an incident edge over the reference face's edge) would read the height of a
farther point (0.52 where they are 0.44 apart, ``tools.pair_survey box box``). Separated, the
smallest candidate gap is the boxes' distance: where the clipped or edge candidates stand
higher, the nearest points replace them."""

from __future__ import annotations

import numpy as np

from clearbench.kernels.gaps.segments import segment_parameters
from clearbench.kernels.gaps.staging import stage_contact
from clearbench.kernels.gaps.vectors import (
    add,
    axpy,
    clamp,
    column_of,
    cross,
    dot,
    norm,
    scaled,
    sub,
    to_local,
    to_world,
)
from clearbench.kernels.jit import njit

#: Edge-edge axes with |a_i x b_j| below this are skipped in the box-box separating-axis test.
_EDGE_AXIS_MIN_SINE = 1e-6
#: The clipped or edge candidates stand for two separated boxes while their smallest gap is
#: within this fraction of the boxes' size of the distance: 1e-9 is far above the round-off of
#: a height (1e-16 relative), far below any gap a metric resolves.
_DISTANCE_TIE = 1e-9
#: Relative preference (in units of the boxes' size) of face contacts over edge contacts, and of
#: reference faces on A over faces on B, so near-ties do not flip from step to step.
_BOX_FACE_BIAS = 1e-6


@njit(cache=True, inline="always")
def _box_radius_along(rotation, half_extents, direction):
    """Half-width of a box along the unit ``direction``."""
    return (
        half_extents[0] * abs(dot(column_of(rotation, 0), direction))
        + half_extents[1] * abs(dot(column_of(rotation, 1), direction))
        + half_extents[2] * abs(dot(column_of(rotation, 2), direction))
    )


@njit(cache=True, inline="always")
def _clip_polygon(polygon, count, scratch, axis, sign, limit):
    """Sutherland-Hodgman: keep the part of ``polygon[:count]`` (rows (a, b, depth)) where
    ``sign * polygon[:, axis] <= limit``; the result is written back into ``polygon``."""
    out_count = 0
    for i in range(count):
        j = (i + 1) % count
        value_i = sign * polygon[i, axis] - limit
        value_j = sign * polygon[j, axis] - limit
        if value_i <= 0.0:
            for k in range(3):
                scratch[out_count, k] = polygon[i, k]
            out_count += 1
        if (value_i < 0.0 < value_j) or (value_j < 0.0 < value_i):
            fraction = value_i / (value_i - value_j)
            for k in range(3):
                scratch[out_count, k] = polygon[i, k] + fraction * (polygon[j, k] - polygon[i, k])
            out_count += 1
    for i in range(out_count):
        for k in range(3):
            polygon[i, k] = scratch[i, k]
    return out_count


@njit(cache=True)
def _box_face_contacts(reference_is_a, ref_position, ref_rotation, ref_half, face_axis,
                       inc_position, inc_rotation, inc_half, stage, polygon, scratch):
    """Clip the incident box's face most opposed to the reference face against the reference
    face's rectangle; every clipped vertex is a candidate with gap = its depth along the face
    normal (negative below the face). ``polygon`` and ``scratch`` are (>= 8, 3) work arrays."""
    u = column_of(ref_rotation, face_axis)
    if dot(u, sub(inc_position, ref_position)) < 0.0:
        u = scaled(u, -1.0)
    face_centre = axpy(ref_half[face_axis], u, ref_position)
    i1 = (face_axis + 1) % 3
    i2 = (face_axis + 2) % 3
    t1 = column_of(ref_rotation, i1)
    t2 = column_of(ref_rotation, i2)
    # Incident face: the face of the other box whose outward normal is most opposed to u.
    best = 0
    best_value = abs(dot(column_of(inc_rotation, 0), u))
    for k in range(1, 3):
        value = abs(dot(column_of(inc_rotation, k), u))
        if value > best_value:
            best, best_value = k, value
    incident_axis = column_of(inc_rotation, best)
    outward = -1.0 if dot(incident_axis, u) > 0.0 else 1.0
    incident_centre = axpy(outward * inc_half[best], incident_axis, inc_position)
    j1 = (best + 1) % 3
    j2 = (best + 2) % 3
    v1 = scaled(column_of(inc_rotation, j1), inc_half[j1])
    v2 = scaled(column_of(inc_rotation, j2), inc_half[j2])
    for k in range(4):
        s1 = 1.0 if k == 0 or k == 3 else -1.0
        s2 = 1.0 if k < 2 else -1.0
        relative = sub(add(incident_centre, add(scaled(v1, s1), scaled(v2, s2))), face_centre)
        polygon[k, 0] = dot(relative, t1)
        polygon[k, 1] = dot(relative, t2)
        polygon[k, 2] = dot(relative, u)
    count = 4
    count = _clip_polygon(polygon, count, scratch, 0, 1.0, ref_half[i1])
    if count > 0:
        count = _clip_polygon(polygon, count, scratch, 0, -1.0, ref_half[i1])
    if count > 0:
        count = _clip_polygon(polygon, count, scratch, 1, 1.0, ref_half[i2])
    if count > 0:
        count = _clip_polygon(polygon, count, scratch, 1, -1.0, ref_half[i2])
    for k in range(count):
        on_face = add(face_centre, add(scaled(t1, polygon[k, 0]), scaled(t2, polygon[k, 1])))
        depth = polygon[k, 2]
        if reference_is_a:
            stage_contact(stage, k, depth, on_face, u)
        else:
            stage_contact(stage, k, depth, axpy(depth, u, on_face), scaled(u, -1.0))
    return count


@njit(cache=True)
def box_box(position_a, rotation_a, half_a, position_b, rotation_b, half_b, stage, polygon,
            scratch):
    """Separating-axis choice of the contact feature, then face clipping or edge-edge."""
    d = sub(position_b, position_a)
    scale = max(half_a[0], half_a[1], half_a[2]) + max(half_b[0], half_b[1], half_b[2])
    bias = _BOX_FACE_BIAS * scale
    # Face axes of A and of B: separation = |d.u| - (radius of A + radius of B) along u.
    best_a, best_a_axis = -np.inf, 0
    best_b, best_b_axis = -np.inf, 0
    for i in range(3):
        u = column_of(rotation_a, i)
        separation = abs(dot(d, u)) - half_a[i] - _box_radius_along(rotation_b, half_b, u)
        if separation > best_a:
            best_a, best_a_axis = separation, i
        u = column_of(rotation_b, i)
        separation = abs(dot(d, u)) - half_b[i] - _box_radius_along(rotation_a, half_a, u)
        if separation > best_b:
            best_b, best_b_axis = separation, i
    best_face = max(best_a, best_b)
    # Edge-edge axes a_i x b_j.
    best_edge = -np.inf
    edge_i, edge_j = 0, 0
    for i in range(3):
        for j in range(3):
            axis = cross(column_of(rotation_a, i), column_of(rotation_b, j))
            length = norm(axis)
            if length < _EDGE_AXIS_MIN_SINE:
                continue
            axis = scaled(axis, 1.0 / length)
            separation = (
                abs(dot(d, axis))
                - _box_radius_along(rotation_a, half_a, axis)
                - _box_radius_along(rotation_b, half_b, axis)
            )
            if separation > best_edge:
                best_edge, edge_i, edge_j = separation, i, j
    if best_edge > best_face + bias:
        count = _box_edge_contact(position_a, rotation_a, half_a, edge_i, position_b, rotation_b,
                                  half_b, edge_j, stage)
    elif best_a >= best_b - bias:
        count = _box_face_contacts(True, position_a, rotation_a, half_a, best_a_axis,
                                   position_b, rotation_b, half_b, stage, polygon, scratch)
    else:
        count = _box_face_contacts(False, position_b, rotation_b, half_b, best_b_axis,
                                   position_a, rotation_a, half_a, stage, polygon, scratch)
    if max(best_face, best_edge) <= 0.0:
        return count  # no separating axis: the boxes overlap or touch
    smallest = np.inf
    for k in range(count):
        smallest = min(smallest, stage[k, 2, 0])
    distance, point_a, point_b = box_box_distance(position_a, rotation_a, half_a, position_b,
                                                  rotation_b, half_b)
    if distance < smallest - _DISTANCE_TIE * scale:
        stage_contact(stage, 0, distance, point_a, scaled(sub(point_b, point_a), 1.0 / distance))
        return 1
    return count


@njit(cache=True, inline="always")
def _nearest_in_box(point, position, rotation, half):
    """The point of the box's solid nearest ``point`` (3,)."""
    local = to_local(position, rotation, point)
    return to_world(position, rotation, (clamp(local[0], -half[0], half[0]),
                                         clamp(local[1], -half[1], half[1]),
                                         clamp(local[2], -half[2], half[2])))


@njit(cache=True, inline="always")
def _corner(position, rotation, half, signs):
    """The box's point at local (signs[k] half[k]) (signs: 3 of +-1 for a corner; a component
    0 gives the middle of an edge along that axis)."""
    return to_world(position, rotation, (signs[0] * half[0], signs[1] * half[1],
                                         signs[2] * half[2]))


@njit(cache=True)
def box_box_distance(position_a, rotation_a, half_a, position_b, rotation_b, half_b):
    """(distance [L], point on A (3,), point on B (3,)) of two boxes that do not overlap.

    Two disjoint convex polyhedra have a nearest pair with a vertex of one (against the other's
    solid) or with both points on edges (a face-face or edge-face nearest set is a polygon or
    segment whose ends are vertices or edge crossings), so the smallest over the 16 vertices
    against the other box and the 144 edge pairs is the distance."""
    best = np.inf
    best_a = (position_a[0], position_a[1], position_a[2])
    best_b = (position_b[0], position_b[1], position_b[2])
    for corner_index in range(8):
        signs = (1.0 if corner_index & 1 else -1.0, 1.0 if corner_index & 2 else -1.0,
                 1.0 if corner_index & 4 else -1.0)
        vertex = _corner(position_a, rotation_a, half_a, signs)
        nearest = _nearest_in_box(vertex, position_b, rotation_b, half_b)
        distance = norm(sub(nearest, vertex))
        if distance < best:
            best, best_a, best_b = distance, vertex, nearest
        vertex = _corner(position_b, rotation_b, half_b, signs)
        nearest = _nearest_in_box(vertex, position_a, rotation_a, half_a)
        distance = norm(sub(nearest, vertex))
        if distance < best:
            best, best_a, best_b = distance, nearest, vertex
    for edge_a in range(12):
        axis_a = edge_a // 4
        centre_a = _corner(position_a, rotation_a, half_a, _edge_signs(edge_a))
        direction_a = column_of(rotation_a, axis_a)
        for edge_b in range(12):
            axis_b = edge_b // 4
            centre_b = _corner(position_b, rotation_b, half_b, _edge_signs(edge_b))
            direction_b = column_of(rotation_b, axis_b)
            s, t = segment_parameters(centre_a, direction_a, half_a[axis_a], centre_b,
                                      direction_b, half_b[axis_b])
            point_a = axpy(s, direction_a, centre_a)
            point_b = axpy(t, direction_b, centre_b)
            distance = norm(sub(point_b, point_a))
            if distance < best:
                best, best_a, best_b = distance, point_a, point_b
    return best, best_a, best_b


@njit(cache=True, inline="always")
def _edge_signs(edge):
    """The :func:`_corner` signs of edge ``edge`` (0-11), the middle of the edge: 0 along axis
    edge // 4, the other two axes' signs from edge % 4."""
    axis = edge // 4
    first = 1.0 if edge & 1 else -1.0
    second = 1.0 if edge & 2 else -1.0
    if axis == 0:
        return (0.0, first, second)
    if axis == 1:
        return (second, 0.0, first)
    return (first, second, 0.0)


@njit(cache=True)
def _box_edge_contact(position_a, rotation_a, half_a, edge_i, position_b, rotation_b, half_b,
                      edge_j, stage):
    """One contact between edge ``edge_i`` direction of A and ``edge_j`` of B (the supporting
    edges along the separating axis a_i x b_j)."""
    d = sub(position_b, position_a)
    axis = cross(column_of(rotation_a, edge_i), column_of(rotation_b, edge_j))
    axis = scaled(axis, 1.0 / norm(axis))
    if dot(axis, d) < 0.0:
        axis = scaled(axis, -1.0)
    # Supporting edges: A's edge furthest along +axis, B's furthest along -axis.
    centre_a = position_a
    centre_b = position_b
    for k in range(3):
        if k != edge_i:
            column = column_of(rotation_a, k)
            side = 1.0 if dot(column, axis) > 0.0 else -1.0
            centre_a = axpy(side * half_a[k], column, centre_a)
        if k != edge_j:
            column = column_of(rotation_b, k)
            side = -1.0 if dot(column, axis) > 0.0 else 1.0
            centre_b = axpy(side * half_b[k], column, centre_b)
    direction_a = column_of(rotation_a, edge_i)
    direction_b = column_of(rotation_b, edge_j)
    s, t = segment_parameters(centre_a, direction_a, half_a[edge_i], centre_b, direction_b,
                              half_b[edge_j])
    point_a = axpy(s, direction_a, centre_a)
    point_b = axpy(t, direction_b, centre_b)
    offset = sub(point_b, point_a)
    along = dot(offset, axis)
    distance = norm(offset)
    if along > 0.0 and distance > 0.0:
        # Separated: the true distance between the two edges, along their closest points.
        stage_contact(stage, 0, distance, point_a, scaled(offset, 1.0 / distance))
    else:
        # Touching or penetrating: gap along the separating axis. If an edge end clamped the
        # closest points, A's point moves by half of the tangential offset (and B's, being
        # p_A + gap * axis, by the other half).
        tangential = axpy(-along, axis, offset)
        stage_contact(stage, 0, along, axpy(0.5, tangential, point_a), axis)
    return 1
