"""Numba contact kernels: signed gaps, contact points and frames for pairs of shapes.

The conventions (normal from A toward B, signed gap, contact frame, what each pair returns) are
documented in :mod:`clearbench.scenarios.geometry`, which is the public entry point; this module
holds the compiled kernels and the shape codes they dispatch on. Only :func:`pair_contacts` and
:func:`pair_contact_slots` (every candidate in a fixed slot, for an engine with one interaction
per candidate: the Siconos worker) are meant to be called from outside.

Implementation notes. :func:`pair_contacts` converts its inputs to tuples once, so the kernels
below take tuples and scalars (no array arguments, hence no reference counting in the hot
path). A kernel stages each contact it finds in the ``out_frame`` slot of that contact (row 0:
normal, row 1: point on A, row [2, 0]: gap) and returns the count; :func:`pair_contacts` then
expands the staged contacts into gaps, both points (``p_B = p_A + g n``) and frames, and mirrors
them when the pair was computed in the other order.
"""

from __future__ import annotations

import math

import numpy as np

from clearbench.kernels.frames import frame_tangent
from clearbench.kernels.jit import njit

# Shape codes (module constants, compiled in as literals).
SPHERE = 0
BOX = 1
CAPSULE = 2
CYLINDER = 3
PLANE = 4
CIRCLE = 5
ARC = 6
RECTANGLE = 7
DISC = 8
BORE = 9
SHAPE_KIND_NAMES = ("sphere", "box", "capsule", "cylinder", "plane", "circle", "arc",
                    "rectangle", "disc", "bore")
NUMBER_OF_KINDS = len(SHAPE_KIND_NAMES)

#: Length of the packed parameter vector of every shape.
PARAMETER_COUNT = 8
#: Upper bound of the contacts one pair can return (box corners, box clipping, cylinder rims).
MAX_CONTACTS_PER_PAIR = 8

#: Pairs implemented with the first kind on body A; the reversed order is handled by swapping.
CANONICAL_PAIRS = (
    (PLANE, SPHERE),
    (PLANE, BOX),
    (PLANE, CAPSULE),
    (PLANE, CYLINDER),
    (PLANE, CIRCLE),
    (PLANE, ARC),
    (SPHERE, SPHERE),
    (BOX, SPHERE),
    (CAPSULE, SPHERE),
    (CYLINDER, SPHERE),
    (BOX, BOX),
    (CAPSULE, CAPSULE),
    (CIRCLE, CYLINDER),
    (ARC, CYLINDER),
    (RECTANGLE, SPHERE),
    (RECTANGLE, CYLINDER),
    (RECTANGLE, CIRCLE),
    (RECTANGLE, ARC),
    (DISC, SPHERE),
    (DISC, CYLINDER),
    (DISC, CIRCLE),
    (DISC, ARC),
    (CIRCLE, BORE),
    (ARC, BORE),
    (CYLINDER, BORE),
)

_CANONICAL = np.zeros((NUMBER_OF_KINDS, NUMBER_OF_KINDS), dtype=np.bool_)
for _a, _b in CANONICAL_PAIRS:
    _CANONICAL[_a, _b] = True
#: SUPPORTED[kind_a, kind_b] is True when pair_contacts handles that ordered pair.
SUPPORTED = _CANONICAL | _CANONICAL.T
SUPPORTED.setflags(write=False)
_CANONICAL.setflags(write=False)

_TWO_PI = 2.0 * math.pi

#: Second/first harmonic ratio 2 r2 / r1 below which the ring-cylinder angle function has a
#: single minimum inside |x| <= asin(ratio), on which it is convex (see _ring_angle).
_RING_FAST_PATH_RATIO = 0.4
#: A Newton step on the ring angle below this (rad) leaves an error of order its square.
_NEWTON_FINAL_STEP = 1e-9
#: |a x b| below which two capsule axes are treated as parallel (two contacts on the overlap).
_PARALLEL_SINE = 1e-6
#: Edge-edge axes with |a_i x b_j| below this are skipped in the box-box separating-axis test.
_EDGE_AXIS_MIN_SINE = 1e-6
#: Relative preference (in units of the boxes' size) of face contacts over edge contacts, and of
#: reference faces on A over faces on B, so near-ties do not flip from step to step.
_BOX_FACE_BIAS = 1e-6


# ------------------------------------------------------------------------------------------------
# Small helpers on 3-tuples; rotations are tuples of 3 rows
# ------------------------------------------------------------------------------------------------


@njit(cache=True, inline="always")
def _column(rotation, j):
    return (rotation[0][j], rotation[1][j], rotation[2][j])


@njit(cache=True, inline="always")
def _add(a, b):
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


@njit(cache=True, inline="always")
def _sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


@njit(cache=True, inline="always")
def _scale(a, s):
    return (a[0] * s, a[1] * s, a[2] * s)


@njit(cache=True, inline="always")
def _axpy(s, a, b):
    """b + s a"""
    return (b[0] + s * a[0], b[1] + s * a[1], b[2] + s * a[2])


@njit(cache=True, inline="always")
def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@njit(cache=True, inline="always")
def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


@njit(cache=True, inline="always")
def _norm(a):
    return math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])


@njit(cache=True, inline="always")
def _rotate(rotation, local):
    """rotation @ local"""
    return (_dot(rotation[0], local), _dot(rotation[1], local), _dot(rotation[2], local))


@njit(cache=True, inline="always")
def _to_world(position, rotation, local):
    """position + rotation @ local"""
    return _add(position, _rotate(rotation, local))


@njit(cache=True, inline="always")
def _to_local(position, rotation, world):
    """rotation.T @ (world - position)"""
    d = _sub(world, position)
    return (
        rotation[0][0] * d[0] + rotation[1][0] * d[1] + rotation[2][0] * d[2],
        rotation[0][1] * d[0] + rotation[1][1] * d[1] + rotation[2][1] * d[2],
        rotation[0][2] * d[0] + rotation[1][2] * d[1] + rotation[2][2] * d[2],
    )


@njit(cache=True, inline="always")
def _clamp(value, low, high):
    return min(max(value, low), high)


@njit(cache=True)
def _any_perpendicular(axis):
    """A unit vector perpendicular to the unit vector ``axis`` (deterministic)."""
    if abs(axis[0]) < 0.6:
        other = (1.0, 0.0, 0.0)
    else:
        other = (0.0, 1.0, 0.0)
    v = _cross(axis, other)
    return _scale(v, 1.0 / _norm(v))


@njit(cache=True, inline="always")
def _stage(stage, index, gap, point_a, normal):
    """Stage one contact in ``stage[index]`` (the out_frame slot): normal, point on A, gap."""
    for i in range(3):
        stage[index, 0, i] = normal[i]
        stage[index, 1, i] = point_a[i]
    stage[index, 2, 0] = gap


# ------------------------------------------------------------------------------------------------
# Plane (A) against X (B). The plane's material is below its shape-frame z = 0; m = its +z axis.
# ------------------------------------------------------------------------------------------------


@njit(cache=True, inline="always")
def _plane_point(plane_position, normal, point, radius, index, stage):
    """Contact of ``point`` swept by ``radius`` (a sphere; 0 for a bare point)."""
    height = _dot(_sub(point, plane_position), normal)
    _stage(stage, index, height - radius, _axpy(-height, normal, point), normal)


@njit(cache=True)
def _plane_sphere(plane_position, plane_rotation, centre, radius, stage):
    _plane_point(plane_position, _column(plane_rotation, 2), centre, radius, 0, stage)
    return 1


@njit(cache=True)
def _plane_box(plane_position, plane_rotation, box_position, box_rotation, half_extents,
               stage):
    normal = _column(plane_rotation, 2)
    for index in range(8):
        sx = 1.0 if index & 4 else -1.0
        sy = 1.0 if index & 2 else -1.0
        sz = 1.0 if index & 1 else -1.0
        local = (sx * half_extents[0], sy * half_extents[1], sz * half_extents[2])
        corner = _to_world(box_position, box_rotation, local)
        _plane_point(plane_position, normal, corner, 0.0, index, stage)
    return 8


@njit(cache=True)
def _plane_capsule(plane_position, plane_rotation, position, rotation, radius, half_length,
                   stage):
    normal = _column(plane_rotation, 2)
    axis = _column(rotation, 2)
    _plane_point(plane_position, normal, _axpy(-half_length, axis, position), radius, 0, stage)
    _plane_point(plane_position, normal, _axpy(half_length, axis, position), radius, 1, stage)
    return 2


@njit(cache=True)
def _lowest_direction(normal, rotation):
    """Unit vector in the shape's xy-plane most opposed to ``normal`` (the shape's x axis when
    that plane is parallel to the contact plane), and ``z x lowest``, 90 degrees further."""
    axis = _column(rotation, 2)
    down = _axpy(-_dot(normal, axis), axis, normal)
    length = _norm(down)
    if length > 0.0:
        lowest = _scale(down, -1.0 / length)
    else:
        lowest = _column(rotation, 0)
    return lowest, _cross(axis, lowest)


@njit(cache=True)
def _plane_cylinder(plane_position, plane_rotation, position, rotation, radius, half_length,
                    stage):
    """Eight rim candidates: on each end rim the lowest point and the points 90, 180 and 270
    degrees further round. Indices 0 and 1 are the two lowest rim points (the support of a
    lying cylinder); a standing cylinder gets 4 points on its bottom rim."""
    normal = _column(plane_rotation, 2)
    axis = _column(rotation, 2)
    lowest, quarter = _lowest_direction(normal, rotation)
    for index in range(8):
        end = -half_length if index % 2 == 0 else half_length
        turn = index // 2  # 0, 1, 2, 3 quarter turns from the lowest point
        if turn == 0:
            offset = _scale(lowest, radius)
        elif turn == 1:
            offset = _scale(quarter, radius)
        elif turn == 2:
            offset = _scale(lowest, -radius)
        else:
            offset = _scale(quarter, -radius)
        point = _add(_axpy(end, axis, position), offset)
        _plane_point(plane_position, normal, point, 0.0, index, stage)
    return 8


@njit(cache=True, inline="always")
def _arc_angle_in_range(angle, start_angle, span):
    """True if ``angle`` lies in [start_angle, start_angle + span] modulo 2 pi."""
    return (angle - start_angle) % _TWO_PI <= span


@njit(cache=True)
def _plane_ring(plane_position, plane_rotation, position, rotation, radius, start_angle, span,
                is_arc, stage):
    """Lowest point of a circle (or an arc of it) with respect to the plane normal."""
    normal = _column(plane_rotation, 2)
    e1 = _column(rotation, 0)
    e2 = _column(rotation, 1)
    # height(theta) - height(centre) = radius (cos(theta) e1.m + sin(theta) e2.m)
    c1 = _dot(e1, normal)
    c2 = _dot(e2, normal)
    if c1 == 0.0 and c2 == 0.0:
        # Ring parallel to the plane: every point is lowest; take angle 0 (circle) or the middle
        # of the arc.
        angle = start_angle + 0.5 * span if is_arc else 0.0
    else:
        angle = math.atan2(-c2, -c1)
        if is_arc and not _arc_angle_in_range(angle, start_angle, span):
            end_angle = start_angle + span
            height_start = c1 * math.cos(start_angle) + c2 * math.sin(start_angle)
            height_end = c1 * math.cos(end_angle) + c2 * math.sin(end_angle)
            angle = start_angle if height_start <= height_end else end_angle
    offset = _add(_scale(e1, radius * math.cos(angle)), _scale(e2, radius * math.sin(angle)))
    _plane_point(plane_position, normal, _add(position, offset), 0.0, 0, stage)
    return 1


# ------------------------------------------------------------------------------------------------
# Sphere (B) against sphere, box, capsule, cylinder (A)
# ------------------------------------------------------------------------------------------------


@njit(cache=True)
def _sphere_sphere(centre_a, radius_a, centre_b, radius_b, stage):
    d = _sub(centre_b, centre_a)
    distance = _norm(d)
    if distance > 0.0:
        normal = _scale(d, 1.0 / distance)
    else:
        normal = (0.0, 0.0, 1.0)  # concentric: any direction is a closest direction
    _stage(stage, 0, distance - radius_a - radius_b, _axpy(radius_a, normal, centre_a), normal)
    return 1


@njit(cache=True)
def _box_sphere(box_position, box_rotation, h, centre, radius, stage):
    local = _to_local(box_position, box_rotation, centre)
    closest = (_clamp(local[0], -h[0], h[0]), _clamp(local[1], -h[1], h[1]),
               _clamp(local[2], -h[2], h[2]))
    offset = _sub(local, closest)
    distance = _norm(offset)
    if distance > 0.0:
        normal_local = _scale(offset, 1.0 / distance)
        surface_local = closest
        signed = distance
    else:
        # Centre inside (or on) the box: leave through the nearest face.
        best = 0
        best_depth = h[0] - abs(local[0])
        for i in range(1, 3):
            depth = h[i] - abs(local[i])
            if depth < best_depth:
                best, best_depth = i, depth
        side = 1.0 if local[best] >= 0.0 else -1.0
        if best == 0:
            normal_local = (side, 0.0, 0.0)
            surface_local = (side * h[0], local[1], local[2])
        elif best == 1:
            normal_local = (0.0, side, 0.0)
            surface_local = (local[0], side * h[1], local[2])
        else:
            normal_local = (0.0, 0.0, side)
            surface_local = (local[0], local[1], side * h[2])
        signed = -best_depth
    _stage(stage, 0, signed - radius, _to_world(box_position, box_rotation, surface_local),
           _rotate(box_rotation, normal_local))
    return 1


@njit(cache=True)
def _capsule_sphere(position, rotation, capsule_radius, half_length, centre, radius, stage):
    axis = _column(rotation, 2)
    t = _clamp(_dot(_sub(centre, position), axis), -half_length, half_length)
    on_axis = _axpy(t, axis, position)
    offset = _sub(centre, on_axis)
    distance = _norm(offset)
    if distance > 0.0:
        normal = _scale(offset, 1.0 / distance)
    else:
        normal = _column(rotation, 0)
    _stage(stage, 0, distance - capsule_radius - radius, _axpy(capsule_radius, normal, on_axis),
           normal)
    return 1


@njit(cache=True)
def _cylinder_sphere(position, rotation, cylinder_radius, half_length, centre, radius, stage):
    """Sphere against the SOLID finite cylinder (lateral surface and flat ends)."""
    local = _to_local(position, rotation, centre)
    radial = math.hypot(local[0], local[1])
    if radial > 0.0:
        radial_direction = (local[0] / radial, local[1] / radial, 0.0)
    else:
        radial_direction = (1.0, 0.0, 0.0)
    if radial > cylinder_radius or abs(local[2]) > half_length:
        r = min(radial, cylinder_radius)
        closest = (radial_direction[0] * r, radial_direction[1] * r,
                   _clamp(local[2], -half_length, half_length))
        offset = _sub(local, closest)
        distance = _norm(offset)
        normal_local = _scale(offset, 1.0 / distance)
        surface_local = closest
        signed = distance
    else:
        radial_depth = cylinder_radius - radial
        axial_depth = half_length - abs(local[2])
        if radial_depth < axial_depth:
            normal_local = radial_direction
            surface_local = (radial_direction[0] * cylinder_radius,
                             radial_direction[1] * cylinder_radius, local[2])
            signed = -radial_depth
        else:
            side = 1.0 if local[2] >= 0.0 else -1.0
            normal_local = (0.0, 0.0, side)
            surface_local = (local[0], local[1], side * half_length)
            signed = -axial_depth
    _stage(stage, 0, signed - radius, _to_world(position, rotation, surface_local),
           _rotate(rotation, normal_local))
    return 1


# ------------------------------------------------------------------------------------------------
# Segments (capsules) and boxes
# ------------------------------------------------------------------------------------------------


@njit(cache=True)
def _segment_parameters(centre_a, axis_a, half_a, centre_b, axis_b, half_b):
    """Parameters (s, t) of the closest points ``centre_a + s axis_a`` and
    ``centre_b + t axis_b`` of two segments (unit axes, |s| <= half_a, |t| <= half_b).

    Ericson, Real-Time Collision Detection, 5.1.9. Parallel axes give the point of A nearest
    the middle of the overlap (one of the closest pairs)."""
    r = _sub(centre_a, centre_b)
    b = _dot(axis_a, axis_b)
    c = _dot(axis_a, r)
    f = _dot(axis_b, r)
    denominator = 1.0 - b * b
    if denominator > 1e-14:
        s = _clamp((b * f - c) / denominator, -half_a, half_a)
    else:
        # Parallel: middle of the overlap of B's projection onto A (clamped to A).
        low = max(-half_a, -c - half_b * abs(b))
        high = min(half_a, -c + half_b * abs(b))
        s = _clamp(0.5 * (low + high), -half_a, half_a)
    t = b * s + f
    if t < -half_b:
        t = -half_b
        s = _clamp(b * t - c, -half_a, half_a)
    elif t > half_b:
        t = half_b
        s = _clamp(b * t - c, -half_a, half_a)
    return s, t


@njit(cache=True, inline="always")
def _swept_points(point_a, radius_a, point_b, radius_b, fallback_normal, index, stage):
    """Contact between two points swept by radii (spheres on segment points)."""
    d = _sub(point_b, point_a)
    distance = _norm(d)
    if distance > 0.0:
        normal = _scale(d, 1.0 / distance)
    else:
        normal = fallback_normal
    _stage(stage, index, distance - radius_a - radius_b, _axpy(radius_a, normal, point_a),
           normal)


@njit(cache=True)
def _capsule_capsule(position_a, rotation_a, radius_a, half_a, position_b, rotation_b, radius_b,
                     half_b, stage):
    """One contact at the closest points of the two axes; two (at the ends of the overlap) when
    the axes are parallel within _PARALLEL_SINE, where the closest set is a segment."""
    axis_a = _column(rotation_a, 2)
    axis_b = _column(rotation_b, 2)
    fallback = _any_perpendicular(axis_a)
    if _norm(_cross(axis_a, axis_b)) < _PARALLEL_SINE:
        b = _dot(axis_a, axis_b)
        c = _dot(axis_a, _sub(position_a, position_b))
        low = max(-half_a, -c - half_b * abs(b))
        high = min(half_a, -c + half_b * abs(b))
        if low < high:
            for index in range(2):
                s = low if index == 0 else high
                point_a = _axpy(s, axis_a, position_a)
                t = _clamp(_dot(_sub(point_a, position_b), axis_b), -half_b, half_b)
                _swept_points(point_a, radius_a, _axpy(t, axis_b, position_b), radius_b,
                              fallback, index, stage)
            return 2
    s, t = _segment_parameters(position_a, axis_a, half_a, position_b, axis_b, half_b)
    _swept_points(_axpy(s, axis_a, position_a), radius_a, _axpy(t, axis_b, position_b),
                  radius_b, fallback, 0, stage)
    return 1


@njit(cache=True, inline="always")
def _box_radius_along(rotation, half_extents, direction):
    """Half-width of a box along the unit ``direction``."""
    return (
        half_extents[0] * abs(_dot(_column(rotation, 0), direction))
        + half_extents[1] * abs(_dot(_column(rotation, 1), direction))
        + half_extents[2] * abs(_dot(_column(rotation, 2), direction))
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
    u = _column(ref_rotation, face_axis)
    if _dot(u, _sub(inc_position, ref_position)) < 0.0:
        u = _scale(u, -1.0)
    face_centre = _axpy(ref_half[face_axis], u, ref_position)
    i1 = (face_axis + 1) % 3
    i2 = (face_axis + 2) % 3
    t1 = _column(ref_rotation, i1)
    t2 = _column(ref_rotation, i2)
    # Incident face: the face of the other box whose outward normal is most opposed to u.
    best = 0
    best_value = abs(_dot(_column(inc_rotation, 0), u))
    for k in range(1, 3):
        value = abs(_dot(_column(inc_rotation, k), u))
        if value > best_value:
            best, best_value = k, value
    incident_axis = _column(inc_rotation, best)
    outward = -1.0 if _dot(incident_axis, u) > 0.0 else 1.0
    incident_centre = _axpy(outward * inc_half[best], incident_axis, inc_position)
    j1 = (best + 1) % 3
    j2 = (best + 2) % 3
    v1 = _scale(_column(inc_rotation, j1), inc_half[j1])
    v2 = _scale(_column(inc_rotation, j2), inc_half[j2])
    for k in range(4):
        s1 = 1.0 if k == 0 or k == 3 else -1.0
        s2 = 1.0 if k < 2 else -1.0
        relative = _sub(_add(incident_centre, _add(_scale(v1, s1), _scale(v2, s2))), face_centre)
        polygon[k, 0] = _dot(relative, t1)
        polygon[k, 1] = _dot(relative, t2)
        polygon[k, 2] = _dot(relative, u)
    count = 4
    count = _clip_polygon(polygon, count, scratch, 0, 1.0, ref_half[i1])
    if count > 0:
        count = _clip_polygon(polygon, count, scratch, 0, -1.0, ref_half[i1])
    if count > 0:
        count = _clip_polygon(polygon, count, scratch, 1, 1.0, ref_half[i2])
    if count > 0:
        count = _clip_polygon(polygon, count, scratch, 1, -1.0, ref_half[i2])
    for k in range(count):
        on_face = _add(face_centre, _add(_scale(t1, polygon[k, 0]), _scale(t2, polygon[k, 1])))
        depth = polygon[k, 2]
        if reference_is_a:
            _stage(stage, k, depth, on_face, u)
        else:
            _stage(stage, k, depth, _axpy(depth, u, on_face), _scale(u, -1.0))
    return count


@njit(cache=True)
def _box_box(position_a, rotation_a, half_a, position_b, rotation_b, half_b, stage, polygon,
             scratch):
    """Separating-axis choice of the contact feature, then face clipping or edge-edge."""
    d = _sub(position_b, position_a)
    scale = max(half_a[0], half_a[1], half_a[2]) + max(half_b[0], half_b[1], half_b[2])
    bias = _BOX_FACE_BIAS * scale
    # Face axes of A and of B: separation = |d.u| - (radius of A + radius of B) along u.
    best_a, best_a_axis = -np.inf, 0
    best_b, best_b_axis = -np.inf, 0
    for i in range(3):
        u = _column(rotation_a, i)
        separation = abs(_dot(d, u)) - half_a[i] - _box_radius_along(rotation_b, half_b, u)
        if separation > best_a:
            best_a, best_a_axis = separation, i
        u = _column(rotation_b, i)
        separation = abs(_dot(d, u)) - half_b[i] - _box_radius_along(rotation_a, half_a, u)
        if separation > best_b:
            best_b, best_b_axis = separation, i
    best_face = max(best_a, best_b)
    # Edge-edge axes a_i x b_j.
    best_edge = -np.inf
    edge_i, edge_j = 0, 0
    for i in range(3):
        for j in range(3):
            axis = _cross(_column(rotation_a, i), _column(rotation_b, j))
            length = _norm(axis)
            if length < _EDGE_AXIS_MIN_SINE:
                continue
            axis = _scale(axis, 1.0 / length)
            separation = (
                abs(_dot(d, axis))
                - _box_radius_along(rotation_a, half_a, axis)
                - _box_radius_along(rotation_b, half_b, axis)
            )
            if separation > best_edge:
                best_edge, edge_i, edge_j = separation, i, j
    if best_edge > best_face + bias:
        return _box_edge_contact(position_a, rotation_a, half_a, edge_i, position_b, rotation_b,
                                 half_b, edge_j, stage)
    if best_a >= best_b - bias:
        return _box_face_contacts(True, position_a, rotation_a, half_a, best_a_axis, position_b,
                                  rotation_b, half_b, stage, polygon, scratch)
    return _box_face_contacts(False, position_b, rotation_b, half_b, best_b_axis, position_a,
                              rotation_a, half_a, stage, polygon, scratch)


@njit(cache=True)
def _box_edge_contact(position_a, rotation_a, half_a, edge_i, position_b, rotation_b, half_b,
                      edge_j, stage):
    """One contact between edge ``edge_i`` direction of A and ``edge_j`` of B (the supporting
    edges along the separating axis a_i x b_j)."""
    d = _sub(position_b, position_a)
    axis = _cross(_column(rotation_a, edge_i), _column(rotation_b, edge_j))
    axis = _scale(axis, 1.0 / _norm(axis))
    if _dot(axis, d) < 0.0:
        axis = _scale(axis, -1.0)
    # Supporting edges: A's edge furthest along +axis, B's furthest along -axis.
    centre_a = position_a
    centre_b = position_b
    for k in range(3):
        if k != edge_i:
            column = _column(rotation_a, k)
            side = 1.0 if _dot(column, axis) > 0.0 else -1.0
            centre_a = _axpy(side * half_a[k], column, centre_a)
        if k != edge_j:
            column = _column(rotation_b, k)
            side = -1.0 if _dot(column, axis) > 0.0 else 1.0
            centre_b = _axpy(side * half_b[k], column, centre_b)
    direction_a = _column(rotation_a, edge_i)
    direction_b = _column(rotation_b, edge_j)
    s, t = _segment_parameters(centre_a, direction_a, half_a[edge_i], centre_b, direction_b,
                               half_b[edge_j])
    point_a = _axpy(s, direction_a, centre_a)
    point_b = _axpy(t, direction_b, centre_b)
    offset = _sub(point_b, point_a)
    along = _dot(offset, axis)
    distance = _norm(offset)
    if along > 0.0 and distance > 0.0:
        # Separated: the true distance between the two edges, along their closest points.
        _stage(stage, 0, distance, point_a, _scale(offset, 1.0 / distance))
    else:
        # Touching or penetrating: gap along the separating axis. If an edge end clamped the
        # closest points, A's point moves by half of the tangential offset (and B's, being
        # p_A + gap * axis, by the other half).
        tangential = _axpy(-along, axis, offset)
        _stage(stage, 0, along, _axpy(0.5, tangential, point_a), axis)
    return 1


# ------------------------------------------------------------------------------------------------
# Ring (circle or arc, A) against the lateral surface of a cylinder (B)
# ------------------------------------------------------------------------------------------------


@njit(cache=True, inline="always")
def _ring_derivatives(theta, a1, b1, a2, b2):
    """First and second derivatives of f(theta) = a1 cos + b1 sin + a2 cos 2 + b2 sin 2."""
    c, s = math.cos(theta), math.sin(theta)
    c2, s2 = c * c - s * s, 2.0 * s * c
    first = -a1 * s + b1 * c - 2.0 * a2 * s2 + 2.0 * b2 * c2
    second = -a1 * c - b1 * s - 4.0 * a2 * c2 - 4.0 * b2 * s2
    return first, second


@njit(cache=True)
def _ring_axis_distance(theta, centre_offset, e1, e2, ring_radius, axis):
    """Distance from the ring point at ``theta`` to the cylinder axis, and the perpendicular
    vector from the axis to the point."""
    c, s = math.cos(theta), math.sin(theta)
    relative = _add(centre_offset, _add(_scale(e1, ring_radius * c), _scale(e2, ring_radius * s)))
    perpendicular = _axpy(-_dot(relative, axis), axis, relative)
    return _norm(perpendicular), perpendicular


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
def _ring_angle(centre_offset, e1, e2, ring_radius, axis, start_angle, span, is_arc, sign):
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
    s = _axpy(-_dot(centre_offset, axis), axis, centre_offset)
    a1 = sign * 2.0 * ring_radius * _dot(s, e1)
    b1 = sign * 2.0 * ring_radius * _dot(s, e2)
    beta1 = _dot(e1, axis)
    beta2 = _dot(e2, axis)
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
        if not is_arc or _arc_angle_in_range(theta, start_angle, span):
            return theta
        # f has one minimum and one maximum on the circle: off the minimum, the best point of
        # an arc is one of its ends.
    else:
        angles = _ring_critical_angles(a1, b1, a2, b2)
        for k in range(angles.shape[0]):
            if is_arc and not _arc_angle_in_range(angles[k], start_angle, span):
                continue
            distance, _ = _ring_axis_distance(angles[k], centre_offset, e1, e2, ring_radius, axis)
            if sign * distance < best_distance:
                best_angle, best_distance = angles[k], sign * distance
        if not is_arc:
            return best_angle
    for theta in (start_angle, start_angle + span):
        distance, _ = _ring_axis_distance(theta, centre_offset, e1, e2, ring_radius, axis)
        if sign * distance < best_distance:
            best_angle, best_distance = theta, sign * distance
    return best_angle


@njit(cache=True)
def _ring_cylinder(ring_position, ring_rotation, ring_radius, start_angle, span, is_arc,
                   cylinder_position, cylinder_rotation, cylinder_radius, stage):
    """Ring (A) against the lateral surface of the cylinder (B), taken as infinitely long.

    gap = min over ring points of (distance to the cylinder axis) - cylinder radius. The same
    formula covers the journal inside the bore (INTERNAL: axis inside the ring; gap =
    R_ring - R_cyl - e for parallel axes at eccentricity e) and the ring outside a pin
    (EXTERNAL: gap = e - R_ring - R_cyl). The normal points from the ring point toward the
    axis (from A into B), perpendicular to the axis.
    """
    axis = _column(cylinder_rotation, 2)
    e1 = _column(ring_rotation, 0)
    e2 = _column(ring_rotation, 1)
    centre_offset = _sub(ring_position, cylinder_position)
    theta = _ring_angle(centre_offset, e1, e2, ring_radius, axis, start_angle, span, is_arc,
                        1.0)
    distance, perpendicular = _ring_axis_distance(theta, centre_offset, e1, e2, ring_radius,
                                                  axis)
    if distance > 0.0:
        inward = _scale(perpendicular, -1.0 / distance)
    else:
        inward = _any_perpendicular(axis)
    c, s = math.cos(theta), math.sin(theta)
    ring_point = _add(ring_position, _add(_scale(e1, ring_radius * c),
                                          _scale(e2, ring_radius * s)))
    _stage(stage, 0, distance - cylinder_radius, ring_point, inward)
    return 1


# ------------------------------------------------------------------------------------------------
# Bounded plane faces (rectangle, disc, A) against X (B): the plane kernels, then the candidates
# whose point on the face lies outside its boundary are dropped.
# ------------------------------------------------------------------------------------------------


@njit(cache=True, inline="always")
def _copy_staged(stage, source, target):
    """Move the staged contact of slot ``source`` to slot ``target`` (compaction)."""
    for i in range(3):
        for j in range(3):
            stage[target, i, j] = stage[source, i, j]


@njit(cache=True, inline="always")
def _inside_face(plane_position, plane_rotation, half_x, half_y, radius, depth, stage, k):
    """True if the staged contact ``k`` lies in the face: its point on A (row 1 of the stage)
    within |x| <= half_x and |y| <= half_y (rectangle, radius < 0) or x^2 + y^2 <= radius^2
    (disc) in the face's frame, and its gap not below -depth (depth 0: no bound)."""
    if not _within_depth(depth, stage, k):
        return False
    point = (stage[k, 1, 0], stage[k, 1, 1], stage[k, 1, 2])
    local = _to_local(plane_position, plane_rotation, point)
    if radius >= 0.0:
        return local[0] * local[0] + local[1] * local[1] <= radius * radius
    return abs(local[0]) <= half_x and abs(local[1]) <= half_y


@njit(cache=True)
def _keep_inside_face(plane_position, plane_rotation, half_x, half_y, radius, depth, count,
                      stage):
    """Keep the staged contacts that lie in the face (:func:`_inside_face`). Returns the
    number kept (compacted to the front, order preserved)."""
    kept = 0
    for k in range(count):
        if _inside_face(plane_position, plane_rotation, half_x, half_y, radius, depth, stage,
                        k):
            if kept != k:
                _copy_staged(stage, k, kept)
            kept += 1
    return kept


# ------------------------------------------------------------------------------------------------
# Ring (circle or arc) or journal (cylinder) INSIDE a bore (A = ring or journal, B = bore)
# ------------------------------------------------------------------------------------------------


@njit(cache=True, inline="always")
def _bore_angle_in_range(bore_position, bore_rotation, point, start_angle, span):
    """True if the radial direction of ``point`` from the bore axis lies in the bore's angles."""
    local = _to_local(bore_position, bore_rotation, point)
    if span >= _TWO_PI:
        return True
    return _arc_angle_in_range(math.atan2(local[1], local[0]), start_angle, span)


@njit(cache=True)
def _ring_in_bore(ring_position, ring_rotation, ring_radius, start_angle, span, is_arc,
                  bore_position, bore_rotation, bore_radius, bore_half_length, bore_start,
                  bore_span, check_axial, index, stage):
    """Ring (A) inside the bore (B): gap = bore radius - largest distance of a ring point from
    the bore axis; the normal points from that ring point radially outward (from A into B).
    The contact is staged at ``index`` in every case and kept only if its point on the bore
    lies within the bore's angles (and, with ``check_axial``, within |z| <= half_length).
    Returns 1 if kept, else 0 (a compacting caller then reuses the slot).
    """
    axis = _column(bore_rotation, 2)
    e1 = _column(ring_rotation, 0)
    e2 = _column(ring_rotation, 1)
    centre_offset = _sub(ring_position, bore_position)
    theta = _ring_angle(centre_offset, e1, e2, ring_radius, axis, start_angle, span, is_arc,
                        -1.0)
    distance, perpendicular = _ring_axis_distance(theta, centre_offset, e1, e2, ring_radius,
                                                  axis)
    if distance > 0.0:
        outward = _scale(perpendicular, 1.0 / distance)
    else:
        outward = _any_perpendicular(axis)
    c, s = math.cos(theta), math.sin(theta)
    ring_point = _add(ring_position, _add(_scale(e1, ring_radius * c),
                                          _scale(e2, ring_radius * s)))
    gap = bore_radius - distance
    _stage(stage, index, gap, ring_point, outward)
    on_bore = _axpy(gap, outward, ring_point)
    if check_axial and abs(_dot(_sub(on_bore, bore_position), axis)) > bore_half_length:
        return 0
    if not _bore_angle_in_range(bore_position, bore_rotation, on_bore, bore_start, bore_span):
        return 0
    return 1


@njit(cache=True, inline="always")
def _cylinder_end_in_bore(end, direction, centre, reach, journal_position, journal_rotation,
                          journal_radius, journal_half_length, bore_position, bore_rotation,
                          bore_radius, bore_half_length, bore_start, bore_span, index, stage):
    """The candidate at the ``end`` (-1: the bore's -z side, +1: its +z side) of the axial
    overlap of a journal (A) and a bore (B), staged at ``index``; True if kept. An end inside
    the bore is the journal's end rim (ring in the bore, dropped outside the bore's angles); an
    end where the journal runs beyond the bore is the bore's end rim against the journal's
    lateral surface (always kept)."""
    axis_b = _column(bore_rotation, 2)
    if end * (centre + end * reach) > bore_half_length:
        # The journal runs beyond this end of the bore: the bore's end rim.
        rim_position = _axpy(end * bore_half_length, axis_b, bore_position)
        is_arc = bore_span < _TWO_PI
        _ring_cylinder(rim_position, bore_rotation, bore_radius, bore_start, bore_span, is_arc,
                       journal_position, journal_rotation, journal_radius, stage[index:])
        # Mirror into (A = journal, B = bore): normal from the journal outward.
        gap = stage[index, 2, 0]
        normal = (-stage[index, 0, 0], -stage[index, 0, 1], -stage[index, 0, 2])
        rim_point = (stage[index, 1, 0], stage[index, 1, 1], stage[index, 1, 2])
        _stage(stage, index, gap, _axpy(-gap, normal, rim_point), normal)
        return True
    rim_position = _axpy(direction * end * journal_half_length, _column(journal_rotation, 2),
                         journal_position)
    return _ring_in_bore(rim_position, journal_rotation, journal_radius, 0.0, _TWO_PI, False,
                         bore_position, bore_rotation, bore_radius, bore_half_length,
                         bore_start, bore_span, False, index, stage) == 1


@njit(cache=True)
def _cylinder_in_bore(journal_position, journal_rotation, journal_radius, journal_half_length,
                      bore_position, bore_rotation, bore_radius, bore_half_length, bore_start,
                      bore_span, stage):
    """Journal cylinder (A) inside the bore (B): one candidate at each end of their axial
    overlap, where the radial gap of two nearly coaxial cylinders is smallest (it is concave
    along the axis), in slot 0 (the bore's -z side) and slot 1 (its +z side)
    (:func:`_cylinder_end_in_bore`). Returns (slots, kept_0, kept_1): no overlap gives no slot
    (nothing staged)."""
    axis_b = _column(bore_rotation, 2)
    axis_j = _column(journal_rotation, 2)
    direction = 1.0 if _dot(axis_j, axis_b) >= 0.0 else -1.0
    centre = _dot(_sub(journal_position, bore_position), axis_b)
    reach = journal_half_length * abs(_dot(axis_j, axis_b))
    if centre - reach > bore_half_length or centre + reach < -bore_half_length:
        return 0, False, False
    kept_0 = _cylinder_end_in_bore(-1.0, direction, centre, reach, journal_position,
                                   journal_rotation, journal_radius, journal_half_length,
                                   bore_position, bore_rotation, bore_radius, bore_half_length,
                                   bore_start, bore_span, 0, stage)
    kept_1 = _cylinder_end_in_bore(1.0, direction, centre, reach, journal_position,
                                   journal_rotation, journal_radius, journal_half_length,
                                   bore_position, bore_rotation, bore_radius, bore_half_length,
                                   bore_start, bore_span, 1, stage)
    return 2, kept_0, kept_1


@njit(cache=True, inline="always")
def _bore_slots(kind_a, params_a, position_a, rotation_a, params_b, position_b, rotation_b,
                stage):
    """A circle, arc or journal (A) inside a bore (B): (slots, kept_0, kept_1), every slot
    staged (:func:`_ring_in_bore`, :func:`_cylinder_in_bore`); slots -1 for any other A. A
    slot whose gap is below -depth (``params_b[4]`` > 0) is not kept: A is behind the bore's
    solid, not in it."""
    bore_span = params_b[3] - params_b[2]
    if kind_a == CIRCLE:
        kept = _ring_in_bore(position_a, rotation_a, params_a[0], 0.0, _TWO_PI, False,
                             position_b, rotation_b, params_b[0], params_b[1], params_b[2],
                             bore_span, True, 0, stage)
        return 1, kept == 1 and _within_depth(params_b[4], stage, 0), False
    if kind_a == ARC:
        kept = _ring_in_bore(position_a, rotation_a, params_a[0], params_a[1],
                             params_a[2] - params_a[1], True, position_b, rotation_b,
                             params_b[0], params_b[1], params_b[2], bore_span, True, 0, stage)
        return 1, kept == 1 and _within_depth(params_b[4], stage, 0), False
    if kind_a == CYLINDER:
        slots, kept_0, kept_1 = _cylinder_in_bore(
            position_a, rotation_a, params_a[0], params_a[1], position_b, rotation_b,
            params_b[0], params_b[1], params_b[2], bore_span, stage)
        return (slots, kept_0 and _within_depth(params_b[4], stage, 0),
                kept_1 and slots == 2 and _within_depth(params_b[4], stage, 1))
    return -1, False, False


@njit(cache=True, inline="always")
def _within_depth(depth, stage, k):
    """False if the staged contact ``k`` lies deeper than ``depth`` (> 0; 0: no bound)."""
    return not (depth > 0.0 and stage[k, 2, 0] < -depth)


@njit(cache=True, inline="always")
def _compact_bore_slots(slots, kept_0, kept_1, stage):
    """Number of kept contacts of :func:`_bore_slots`, moved to the front (-1 stays -1)."""
    if slots < 0:
        return -1
    if kept_0:
        return 2 if slots == 2 and kept_1 else 1
    if slots == 2 and kept_1:
        _copy_staged(stage, 1, 0)
        return 1
    return 0


# ------------------------------------------------------------------------------------------------
# Dispatch
# ------------------------------------------------------------------------------------------------


@njit(cache=True, inline="always")
def _face_candidates(plane_position, plane_rotation, kind_b, params_b, position_b, rotation_b,
                     stage):
    """Candidates of a bounded face's plane (A) against X (B) before the face's bounds apply;
    -1 for an X no bounded face is paired with."""
    if kind_b == SPHERE:
        return _plane_sphere(plane_position, plane_rotation, position_b, params_b[0], stage)
    if kind_b == CYLINDER:
        return _plane_cylinder(plane_position, plane_rotation, position_b, rotation_b,
                               params_b[0], params_b[1], stage)
    if kind_b == CIRCLE:
        return _plane_ring(plane_position, plane_rotation, position_b, rotation_b, params_b[0],
                           0.0, _TWO_PI, False, stage)
    if kind_b == ARC:
        return _plane_ring(plane_position, plane_rotation, position_b, rotation_b, params_b[0],
                           params_b[1], params_b[2] - params_b[1], True, stage)
    return -1


@njit(cache=True, inline="always")
def _face_bounds(kind, params):
    """(radius, depth) of a bounded face: a disc's radius, -1 for a rectangle; depth 0: no
    bound."""
    radius = params[0] if kind == DISC else -1.0
    depth = params[1] if kind == DISC else params[2]
    return radius, depth


@njit(cache=True, inline="always")
def _canonical_contacts(kind_a, params_a, position_a, rotation_a, kind_b, params_b, position_b,
                        rotation_b, stage, work_1, work_2):
    """Contacts of a pair listed in CANONICAL_PAIRS in this order; -1 for any other pair.
    Inputs are tuples (params 8, position 3, rotation 3 rows of 3)."""
    if kind_a == PLANE:
        if kind_b == SPHERE:
            return _plane_sphere(position_a, rotation_a, position_b, params_b[0], stage)
        if kind_b == BOX:
            return _plane_box(position_a, rotation_a, position_b, rotation_b, params_b, stage)
        if kind_b == CAPSULE:
            return _plane_capsule(position_a, rotation_a, position_b, rotation_b, params_b[0],
                                  params_b[1], stage)
        if kind_b == CYLINDER:
            return _plane_cylinder(position_a, rotation_a, position_b, rotation_b, params_b[0],
                                   params_b[1], stage)
        if kind_b == CIRCLE:
            return _plane_ring(position_a, rotation_a, position_b, rotation_b, params_b[0], 0.0,
                               _TWO_PI, False, stage)
        if kind_b == ARC:
            return _plane_ring(position_a, rotation_a, position_b, rotation_b, params_b[0],
                               params_b[1], params_b[2] - params_b[1], True, stage)
        return -1
    if kind_a == RECTANGLE or kind_a == DISC:
        count = _face_candidates(position_a, rotation_a, kind_b, params_b, position_b,
                                 rotation_b, stage)
        if count < 0:
            return -1
        radius, depth = _face_bounds(kind_a, params_a)
        return _keep_inside_face(position_a, rotation_a, params_a[0], params_a[1], radius,
                                 depth, count, stage)
    if kind_b == SPHERE:
        if kind_a == SPHERE:
            return _sphere_sphere(position_a, params_a[0], position_b, params_b[0], stage)
        if kind_a == BOX:
            return _box_sphere(position_a, rotation_a, params_a, position_b, params_b[0], stage)
        if kind_a == CAPSULE:
            return _capsule_sphere(position_a, rotation_a, params_a[0], params_a[1], position_b,
                                   params_b[0], stage)
        if kind_a == CYLINDER:
            return _cylinder_sphere(position_a, rotation_a, params_a[0], params_a[1],
                                    position_b, params_b[0], stage)
        return -1
    if kind_a == BOX and kind_b == BOX:
        return _box_box(position_a, rotation_a, params_a, position_b, rotation_b, params_b,
                        stage, work_1, work_2)
    if kind_a == CAPSULE and kind_b == CAPSULE:
        return _capsule_capsule(position_a, rotation_a, params_a[0], params_a[1], position_b,
                                rotation_b, params_b[0], params_b[1], stage)
    if kind_b == BORE:
        slots, kept_0, kept_1 = _bore_slots(kind_a, params_a, position_a, rotation_a, params_b,
                                            position_b, rotation_b, stage)
        return _compact_bore_slots(slots, kept_0, kept_1, stage)
    if kind_b == CYLINDER:
        if kind_a == CIRCLE:
            return _ring_cylinder(position_a, rotation_a, params_a[0], 0.0, _TWO_PI, False,
                                  position_b, rotation_b, params_b[0], stage)
        if kind_a == ARC:
            return _ring_cylinder(position_a, rotation_a, params_a[0], params_a[1],
                                  params_a[2] - params_a[1], True, position_b, rotation_b,
                                  params_b[0], stage)
    return -1


@njit(cache=True)
def _placement_precedes(params_a, position_a, rotation_a, params_b, position_b, rotation_b):
    """Strict lexicographic order on (parameters, position, rotation) tuples: used to run
    same-kind pairs in one canonical order so that swapping A and B mirrors the result
    exactly."""
    for i in range(PARAMETER_COUNT):
        if params_a[i] != params_b[i]:
            return params_a[i] < params_b[i]
    for i in range(3):
        if position_a[i] != position_b[i]:
            return position_a[i] < position_b[i]
    for i in range(3):
        for j in range(3):
            if rotation_a[i][j] != rotation_b[i][j]:
                return rotation_a[i][j] < rotation_b[i][j]
    return False


@njit(cache=True, inline="always")
def _as_tuples(params, position, rotation):
    return (
        (params[0], params[1], params[2], params[3], params[4], params[5], params[6], params[7]),
        (position[0], position[1], position[2]),
        (
            (rotation[0, 0], rotation[0, 1], rotation[0, 2]),
            (rotation[1, 0], rotation[1, 1], rotation[1, 2]),
            (rotation[2, 0], rotation[2, 1], rotation[2, 2]),
        ),
    )


@njit(cache=True, inline="always")
def _computed_in_swapped_order(kind_a, par_a, pos_a, rot_a, kind_b, par_b, pos_b, rot_b):
    """True if the pair is computed as (B, A) and mirrored: B's kind comes first in
    CANONICAL_PAIRS, or, for two shapes of one kind, B precedes A in :func:`_placement_precedes`
    (so that swapping A and B mirrors the result exactly)."""
    if kind_a == kind_b:
        return _placement_precedes(par_b, pos_b, rot_b, par_a, pos_a, rot_a)
    return not _CANONICAL[kind_a, kind_b]


@njit(cache=True, inline="always")
def _expand_staged(count, swap, out_gap, out_point_a, out_point_b, out_frame):
    """Turn the ``count`` contacts staged in ``out_frame`` (row 0: normal, row 1: point on A,
    row [2, 0]: gap, of the computed order) into gaps, both points and frames, mirrored when
    the pair was computed as (B, A)."""
    previous_normal = (np.nan, np.nan, np.nan)
    tangent = (0.0, 0.0, 0.0)
    for k in range(count):
        normal = (out_frame[k, 0, 0], out_frame[k, 0, 1], out_frame[k, 0, 2])
        # Kernel normals are unit to a few ulp (rotation columns, d / |d|): one more
        # normalisation brings them to ~1 ulp, so the frames are orthonormal to ~1 ulp.
        normal = _scale(normal, 1.0 / _norm(normal))
        first = (out_frame[k, 1, 0], out_frame[k, 1, 1], out_frame[k, 1, 2])
        gap = out_frame[k, 2, 0]
        second = _axpy(gap, normal, first)  # p_B = p_A + g n of the computed order
        if swap:
            normal = _scale(normal, -1.0)
            first, second = second, first
        if normal != previous_normal:
            tangent = frame_tangent(normal[0], normal[1], normal[2])
            previous_normal = normal
        out_gap[k] = gap
        for i in range(3):
            out_point_a[k, i] = first[i]
            out_point_b[k, i] = second[i]
            out_frame[k, 0, i] = normal[i]
            out_frame[k, 1, i] = tangent[i]
        bitangent = _cross(normal, tangent)
        for i in range(3):
            out_frame[k, 2, i] = bitangent[i]


@njit(cache=True)
def _pair_contacts_tuples(kind_a, par_a, pos_a, rot_a, kind_b, par_b, pos_b, rot_b, out_gap,
                          out_point_a, out_point_b, out_frame):
    """pair_contacts on tuple inputs (params 8, position 3, rotation 3 rows of 3)."""
    swap = _computed_in_swapped_order(kind_a, par_a, pos_a, rot_a, kind_b, par_b, pos_b, rot_b)
    # out_point_a / out_point_b serve as work arrays (box clipping) before they are written.
    if swap:
        count = _canonical_contacts(kind_b, par_b, pos_b, rot_b, kind_a, par_a, pos_a, rot_a,
                                    out_frame, out_point_a, out_point_b)
    else:
        count = _canonical_contacts(kind_a, par_a, pos_a, rot_a, kind_b, par_b, pos_b, rot_b,
                                    out_frame, out_point_a, out_point_b)
    if count < 0:
        raise ValueError("pair_contacts: unsupported pair of shape kinds (check SUPPORTED)")
    _expand_staged(count, swap, out_gap, out_point_a, out_point_b, out_frame)
    return count


@njit(cache=True, inline="always")
def pair_contacts(kind_a, params_a, position_a, rotation_a, kind_b, params_b, position_b,
                  rotation_b, out_gap, out_point_a, out_point_b, out_frame):
    """Candidate contacts between shape A and shape B, written into the ``out_*`` arrays.

    Parameters
    ----------
    kind_a, kind_b : int
        Shape codes (SPHERE, BOX, CAPSULE, CYLINDER, PLANE, CIRCLE, ARC).
    params_a, params_b : ndarray (PARAMETER_COUNT,)
        Packed parameters (see ``geometry.pack_shape_parameters``), in length units
        (arc angles in rad).
    position_a, position_b : ndarray (3,)
        World position of each shape's own frame origin.
    rotation_a, rotation_b : ndarray (3, 3)
        World rotation of each shape's own frame (columns = shape axes in world), orthonormal
        to round-off.
    out_gap : ndarray (K,)
        Signed gaps g = (p_B - p_A) . n, K >= MAX_CONTACTS_PER_PAIR.
    out_point_a, out_point_b : ndarray (K, 3)
        Contact points on A's and on B's surface (world).
    out_frame : ndarray (K, 3, 3)
        Contact frames, rows (n, t1, t2), n pointing from A toward B.

    Returns
    -------
    int
        Number of contacts written (0 <= count <= MAX_CONTACTS_PER_PAIR).

    Raises
    ------
    ValueError
        For a pair of kinds that is not supported (check ``SUPPORTED`` first).
    """
    if not (0 <= kind_a < NUMBER_OF_KINDS and 0 <= kind_b < NUMBER_OF_KINDS):
        raise ValueError("pair_contacts: unknown shape code")
    par_a, pos_a, rot_a = _as_tuples(params_a, position_a, rotation_a)
    par_b, pos_b, rot_b = _as_tuples(params_b, position_b, rotation_b)
    return _pair_contacts_tuples(kind_a, par_a, pos_a, rot_a, kind_b, par_b, pos_b, rot_b,
                                 out_gap, out_point_a, out_point_b, out_frame)


# ------------------------------------------------------------------------------------------------
# Every candidate in a fixed slot, dropped or not (an engine with one interaction per candidate)
# ------------------------------------------------------------------------------------------------


@njit(cache=True)
def _canonical_slots(kind_a, params_a, position_a, rotation_a, kind_b, params_b, position_b,
                     rotation_b, stage, work_1, work_2, out_kept):
    """:func:`_canonical_contacts` without compaction: every candidate of a bounded face or a
    bore stays in its slot and ``out_kept`` flags the ones the bounds keep. Returns the number
    of slots (-1 for a pair not in CANONICAL_PAIRS)."""
    if kind_a == RECTANGLE or kind_a == DISC:
        slots = _face_candidates(position_a, rotation_a, kind_b, params_b, position_b,
                                 rotation_b, stage)
        radius, depth = _face_bounds(kind_a, params_a)
        for k in range(slots):
            out_kept[k] = _inside_face(position_a, rotation_a, params_a[0], params_a[1], radius,
                                       depth, stage, k)
        return slots
    if kind_b == BORE:
        slots, kept_0, kept_1 = _bore_slots(kind_a, params_a, position_a, rotation_a, params_b,
                                            position_b, rotation_b, stage)
        if slots == 0:
            # A journal beside the bore (no axial overlap): two empty slots, each given the
            # journal's centre, a gap 0 and a normal across the bore axis.
            normal = _any_perpendicular(_column(rotation_b, 2))
            for k in range(2):
                _stage(stage, k, 0.0, position_a, normal)
            slots = 2
        out_kept[0] = kept_0
        if slots == 2:
            out_kept[1] = kept_1
        return slots
    slots = _canonical_contacts(kind_a, params_a, position_a, rotation_a, kind_b, params_b,
                                position_b, rotation_b, stage, work_1, work_2)
    for k in range(slots):
        out_kept[k] = True
    return slots


@njit(cache=True)
def pair_contact_slots(kind_a, params_a, position_a, rotation_a, kind_b, params_b, position_b,
                       rotation_b, out_gap, out_point_a, out_point_b, out_frame, out_kept):
    """:func:`pair_contacts` with every candidate in a fixed slot, dropped or not.

    A bounded face (rectangle, disc) drops the candidates off the face or deeper than its
    depth, a bore those outside its angles or length; :func:`pair_contacts` compacts the kept
    ones to the front. Here slot k is always the same candidate of the kernel (an engine with
    one interaction per candidate follows it from step to step) and ``out_kept[k]`` says
    whether the bounds keep it; the kept slots, in order, are :func:`pair_contacts`'s output.
    A dropped slot holds the kernel's candidate before the bound applied; a journal with no
    axial overlap with its bore fills its two slots with its centre, a gap 0 and a normal
    across the bore axis. Pairs that drop nothing fill every slot with a kept candidate.

    Parameters
    ----------
    kind_a, params_a, position_a, rotation_a, kind_b, params_b, position_b, rotation_b
        As :func:`pair_contacts`.
    out_gap, out_point_a, out_point_b, out_frame
        As :func:`pair_contacts` (K >= MAX_CONTACTS_PER_PAIR rows).
    out_kept : ndarray (K,) bool
        True for a slot the bounds keep.

    Returns
    -------
    int
        Number of slots written: fixed for each pair of kinds, except box-box and
        capsule-capsule, whose count of candidates changes with the configuration.
    """
    if not (0 <= kind_a < NUMBER_OF_KINDS and 0 <= kind_b < NUMBER_OF_KINDS):
        raise ValueError("pair_contact_slots: unknown shape code")
    par_a, pos_a, rot_a = _as_tuples(params_a, position_a, rotation_a)
    par_b, pos_b, rot_b = _as_tuples(params_b, position_b, rotation_b)
    swap = _computed_in_swapped_order(kind_a, par_a, pos_a, rot_a, kind_b, par_b, pos_b, rot_b)
    if swap:
        slots = _canonical_slots(kind_b, par_b, pos_b, rot_b, kind_a, par_a, pos_a, rot_a,
                                 out_frame, out_point_a, out_point_b, out_kept)
    else:
        slots = _canonical_slots(kind_a, par_a, pos_a, rot_a, kind_b, par_b, pos_b, rot_b,
                                 out_frame, out_point_a, out_point_b, out_kept)
    if slots < 0:
        raise ValueError("pair_contact_slots: unsupported pair of shape kinds (check SUPPORTED)")
    _expand_staged(slots, swap, out_gap, out_point_a, out_point_b, out_frame)
    return slots


# ------------------------------------------------------------------------------------------------
# A ring that must enclose a journal: the sign of its gap beyond the ring (measurement side)
# ------------------------------------------------------------------------------------------------


def axis_crosses_inside_ring(ring_position, ring_rotation, ring_radius, start_angle, span,
                             axis_point, axis_direction) -> bool:
    """True when the line through ``axis_point`` along ``axis_direction`` (the journal axis)
    crosses the plane of the ring inside its circle: the journal is in the bore.

    An arc (``span`` < 2 pi) also counts the crossing as inside when it lies beyond the circle
    at an angle the arc does not cover (the journal left through the opening, not through the
    material). A line parallel to the ring's plane is inside when its distance from the ring's
    centre is below the radius.

    Parameters
    ----------
    ring_position : array_like (3,)
        World centre of the ring [L].
    ring_rotation : array_like (3, 3)
        World rotation of the ring's frame (columns: x, y in the ring's plane, z its normal).
    ring_radius : float
        [L].
    start_angle, span : float
        The arc's first angle and angular extent [rad] (a full circle: 0, 2 pi).
    axis_point, axis_direction : array_like (3,)
        A point of the journal axis [L] and its direction (any length > 0).
    """
    rotation = np.asarray(ring_rotation, dtype=float)
    normal = rotation[:, 2]
    direction = np.asarray(axis_direction, dtype=float)
    offset = np.asarray(axis_point, dtype=float) - np.asarray(ring_position, dtype=float)
    along = float(direction @ normal)
    if abs(along) <= 1e-12 * float(np.linalg.norm(direction)):
        unit = direction / np.linalg.norm(direction)
        return bool(np.linalg.norm(offset - (offset @ unit) * unit) < ring_radius)
    crossing = offset - (float(offset @ normal) / along) * direction
    local = rotation.T @ crossing
    if math.hypot(local[0], local[1]) < ring_radius:
        return True
    if span >= _TWO_PI:
        return False
    return (math.atan2(local[1], local[0]) - start_angle) % _TWO_PI > span


def enclosing_ring_gap(gap: float, cylinder_radius: float, inside: bool) -> float:
    """Signed gap of a ring that must enclose a journal [L], from the ring-cylinder gap
    ``gap`` (nearest ring point's distance from the axis minus the cylinder radius,
    :func:`_ring_cylinder`) and whether the axis crosses inside the ring
    (:func:`axis_crosses_inside_ring`).

    Inside, the gap is unchanged (parallel axes at eccentricity e: R_ring - R_cyl - e). Beyond
    the ring the nearest ring point is on the far side of the axis and the unsigned gap grows
    with the distance again (e - R_ring - R_cyl), a journal out of its bore reading as
    separated; counted through the wall the distance is negative: -(gap + R_cyl) - R_cyl, i.e.
    R_ring - R_cyl - e again, continuous where the axis crosses the ring (distance 0) and
    decreasing without bound as the journal moves away.
    """
    return gap if inside else -gap - 2.0 * cylinder_radius
