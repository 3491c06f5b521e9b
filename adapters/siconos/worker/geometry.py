"""Contact geometry for the Siconos worker: plain Python/numpy, no numba, no clearbench import.

The Siconos worker runs under Debian's /usr/bin/python3 (numpy 1.24, no numba), so it cannot
import :mod:`clearbench.scenarios.geometry`. This module mirrors that module's formulas operation
by operation for the pairs the worker supports, so that Siconos sees the same gaps, contact
points and contact frames as the reference solver and the metrics (``tests/
test_siconos_geometry.py`` checks the agreement to 1e-12 on random configurations).

Conventions (those of :mod:`clearbench.scenarios.geometry`)
-----------------------------------------------------------
- The normal ``n`` points FROM shape A TOWARD shape B; ``p_A``, ``p_B`` are the contact points on
  each surface (world) and the signed gap is ``g = (p_B - p_A) . n`` (negative: penetration).
- Contact frame rows ``(n, t1, t2)``, right-handed, a function of ``n`` alone (the pole
  construction of ``geometry_frames``: pole ``(2, 3, 6)/7``, ``e1 = (3, -2, 0)/sqrt(13)``).
- Offsets are NOT applied here. Lengths in the scene's unit, angles in radians, float64.
- Placements: every shape is given by the world position of its own frame origin (3,) and the
  world rotation matrix (3, 3) of its frame (columns = shape axes in world).

Supported pairs (either order; K = number of candidates, fixed for each pair):

=================  ===  =======================================================================
plane-sphere        1   centre height minus radius
plane-box           8   every corner
plane-capsule       2   the two end spheres
plane-cylinder      8   four rim points on each end rim (indices 0, 1: the two lowest)
plane-circle        1   lowest point of the circle
plane-arc           1   lowest point of the arc (or its lower end)
sphere-sphere       1   centre distance minus radii
box-sphere          1   closest point of the solid box
capsule-sphere      1   closest point of the axis segment
cylinder-sphere     1   closest point of the solid cylinder
circle-cylinder     1   ring against the (infinitely long) lateral surface of a journal
arc-cylinder        1   the same, restricted to the arc
rectangle-X         as  plane-X for X = sphere (1), cylinder (8), circle (1), arc (1); a
disc-X              ..  candidate whose point is off the face, or deeper than its depth, is
                        dropped
circle-bore         1   ring point farthest from the bore axis; dropped outside the bore's
arc-bore            1   angles or beyond its length
cylinder-bore       2   one per end of the axial overlap (slot 0 at the bore's -z side);
                        dropped when there is no overlap or outside the bore's angles
=================  ===  =======================================================================

K is the number of SLOTS (one Siconos interaction each): :func:`pair_contact_slots` keeps every
candidate in its slot and flags the dropped ones (the shared geometry compacts the kept ones,
which :func:`pair_contacts` reproduces for the agreement tests).

Box-box and capsule-capsule are not ported: their candidates come from clipping or from a
parallel-axes test, with no fixed slot a Siconos interaction could follow.
"""

import math

import numpy as np

#: Shape kinds (the ``kind`` strings of the scene description).
SPHERE, BOX, CAPSULE, CYLINDER, PLANE, CIRCLE, ARC, RECTANGLE, DISC, BORE = (
    "sphere", "box", "capsule", "cylinder", "plane", "circle", "arc", "rectangle", "disc",
    "bore")
#: Every shape kind the worker knows (packed parameters: see pair_contact_slots).
SHAPE_KINDS = (SPHERE, BOX, CAPSULE, CYLINDER, PLANE, CIRCLE, ARC, RECTANGLE, DISC, BORE)

#: Canonical pairs (kind on A, kind on B) -> number of candidates; reversed orders are mirrored.
CANONICAL_PAIRS = {
    (PLANE, SPHERE): 1,
    (PLANE, BOX): 8,
    (PLANE, CAPSULE): 2,
    (PLANE, CYLINDER): 8,
    (PLANE, CIRCLE): 1,
    (PLANE, ARC): 1,
    (SPHERE, SPHERE): 1,
    (BOX, SPHERE): 1,
    (CAPSULE, SPHERE): 1,
    (CYLINDER, SPHERE): 1,
    (CIRCLE, CYLINDER): 1,
    (ARC, CYLINDER): 1,
    (RECTANGLE, SPHERE): 1,
    (RECTANGLE, CYLINDER): 8,
    (RECTANGLE, CIRCLE): 1,
    (RECTANGLE, ARC): 1,
    (DISC, SPHERE): 1,
    (DISC, CYLINDER): 8,
    (DISC, CIRCLE): 1,
    (DISC, ARC): 1,
    (CIRCLE, BORE): 1,
    (ARC, BORE): 1,
    (CYLINDER, BORE): 2,
}
#: Gap [L] the worker hands Siconos for a dropped slot (a candidate off a bounded face, deeper
#: than its depth, outside a bore's angles or length): far beyond any activation threshold
#: (y + h/2 y' <= ~1e-10 of the smallest feature), so the interaction stays inactive until the
#: candidate comes back; finite, so Siconos's norms of the outputs stay finite.
DROPPED_GAP = 1e12
#: Shape kinds whose pairs can drop candidates (a bounded face, a bore).
DROPPING_KINDS = (RECTANGLE, DISC, BORE)

#: Why the pairs of the shared geometry that are not ported here are missing.
NOT_PORTED = {
    (BOX, BOX): "box-box contacts come from clipping: their number changes with the "
                "configuration, which a fixed set of Siconos interactions cannot follow",
    (CAPSULE, CAPSULE): "capsule-capsule gives one or two contacts depending on whether the "
                        "axes are parallel; not ported to the Siconos worker",
}

_TWO_PI = 2.0 * math.pi
_RING_FAST_PATH_RATIO = 0.4
_NEWTON_FINAL_STEP = 1e-9

_POLE = (2.0 / 7.0, 3.0 / 7.0, 6.0 / 7.0)
_E1 = (3.0 / math.sqrt(13.0), -2.0 / math.sqrt(13.0), 0.0)


def candidate_count(kind_a, kind_b):
    """Number of candidate slots of the pair (either order; one Siconos interaction each), or
    None if not supported here."""
    if (kind_a, kind_b) in CANONICAL_PAIRS:
        return CANONICAL_PAIRS[(kind_a, kind_b)]
    return CANONICAL_PAIRS.get((kind_b, kind_a))


def drops_candidates(kind_a, kind_b):
    """True if the pair (either order) can leave candidate slots empty."""
    return kind_a in DROPPING_KINDS or kind_b in DROPPING_KINDS


def unsupported_reason(kind_a, kind_b):
    """Why the pair is not supported here ('' when it is)."""
    if candidate_count(kind_a, kind_b) is not None:
        return ""
    key = (kind_a, kind_b) if (kind_a, kind_b) in NOT_PORTED else (kind_b, kind_a)
    return NOT_PORTED.get(key, f"no contact geometry for {kind_a}-{kind_b}")


# ---------------------------------------------------------------------------- quaternions
def quat_to_matrix(q):
    """Rotation matrix (3, 3) of the unit quaternion q = (w, x, y, z) (same formula as
    ``scenarios.quaternion.quat_to_matrix``)."""
    w, x, y, z = float(q[0]), float(q[1]), float(q[2]), float(q[3])
    xx, yy, zz = x * x, y * y, z * z
    xy, xz, yz = x * y, x * z, y * z
    wx, wy, wz = w * x, w * y, w * z
    return np.array([
        [1.0 - 2.0 * (yy + zz), 2.0 * (xy - wz), 2.0 * (xz + wy)],
        [2.0 * (xy + wz), 1.0 - 2.0 * (xx + zz), 2.0 * (yz - wx)],
        [2.0 * (xz - wy), 2.0 * (yz + wx), 1.0 - 2.0 * (xx + yy)],
    ])


def quat_multiply(p, q):
    """Hamilton product p * q of (w, x, y, z) quaternions, (4,)."""
    pw, px, py, pz = p
    qw, qx, qy, qz = q
    return np.array([
        pw * qw - px * qx - py * qy - pz * qz,
        pw * qx + px * qw + py * qz - pz * qy,
        pw * qy - px * qz + py * qw + pz * qx,
        pw * qz + px * qy - py * qx + pz * qw,
    ])


def quat_normalize(q):
    q = np.asarray(q, dtype=float)
    return q / math.sqrt(float(q @ q))


# ---------------------------------------------------------------------------- frames
def frame_tangent(nx, ny, nz):
    """First tangent t1 of the contact frame of the unit normal (nx, ny, nz) (3-tuple)."""
    px, py, pz = _POLE
    ex, ey, ez = _E1
    vx = py * nz - pz * ny
    vy = pz * nx - px * nz
    vz = px * ny - py * nx
    c = px * nx + py * ny + pz * nz
    v_squared = vx * vx + vy * vy + vz * vz
    cx = vy * ez - vz * ey
    cy = vz * ex - vx * ez
    cz = vx * ey - vy * ex
    v_dot_e1 = vx * ex + vy * ey + vz * ez
    if c >= 0.0:
        factor = 1.0 / (1.0 + c)
    elif v_squared > 0.0:
        factor = (1.0 - c) / v_squared
    else:
        return -ex, -ey, -ez
    tx = ex + cx + (vx * v_dot_e1 - ex * v_squared) * factor
    ty = ey + cy + (vy * v_dot_e1 - ey * v_squared) * factor
    tz = ez + cz + (vz * v_dot_e1 - ez * v_squared) * factor
    along = tx * nx + ty * ny + tz * nz
    tx, ty, tz = tx - along * nx, ty - along * ny, tz - along * nz
    inverse_norm = 1.0 / math.sqrt(tx * tx + ty * ty + tz * tz)
    return tx * inverse_norm, ty * inverse_norm, tz * inverse_norm


def contact_frame(normal):
    """Frame (3, 3), rows (n, t1, t2), of a normal (3,) (normalised here)."""
    nx, ny, nz = (float(v) for v in normal)
    inverse_norm = 1.0 / math.sqrt(nx * nx + ny * ny + nz * nz)
    nx, ny, nz = nx * inverse_norm, ny * inverse_norm, nz * inverse_norm
    tx, ty, tz = frame_tangent(nx, ny, nz)
    return np.array([[nx, ny, nz], [tx, ty, tz],
                     [ny * tz - nz * ty, nz * tx - nx * tz, nx * ty - ny * tx]])


# ---------------------------------------------------------------------------- 3-tuples
def _column(rotation, j):
    return (rotation[0][j], rotation[1][j], rotation[2][j])


def _add(a, b):
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def _sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def _scale(a, s):
    return (a[0] * s, a[1] * s, a[2] * s)


def _axpy(s, a, b):
    return (b[0] + s * a[0], b[1] + s * a[1], b[2] + s * a[2])


def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _norm(a):
    return math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])


def _rotate(rotation, local):
    return (_dot(rotation[0], local), _dot(rotation[1], local), _dot(rotation[2], local))


def _to_world(position, rotation, local):
    return _add(position, _rotate(rotation, local))


def _to_local(position, rotation, world):
    d = _sub(world, position)
    return (
        rotation[0][0] * d[0] + rotation[1][0] * d[1] + rotation[2][0] * d[2],
        rotation[0][1] * d[0] + rotation[1][1] * d[1] + rotation[2][1] * d[2],
        rotation[0][2] * d[0] + rotation[1][2] * d[1] + rotation[2][2] * d[2],
    )


def _clamp(value, low, high):
    return min(max(value, low), high)


def _any_perpendicular(axis):
    other = (1.0, 0.0, 0.0) if abs(axis[0]) < 0.6 else (0.0, 1.0, 0.0)
    v = _cross(axis, other)
    return _scale(v, 1.0 / _norm(v))


# ---------------------------------------------------------------------------- kernels
# Each kernel returns a list of staged contacts (normal, point on A, gap) in canonical order.
def _plane_point(plane_position, normal, point, radius):
    height = _dot(_sub(point, plane_position), normal)
    return (normal, _axpy(-height, normal, point), height - radius)


def _plane_sphere(plane_position, plane_rotation, centre, radius):
    return [_plane_point(plane_position, _column(plane_rotation, 2), centre, radius)]


def _plane_box(plane_position, plane_rotation, box_position, box_rotation, half_extents):
    normal = _column(plane_rotation, 2)
    out = []
    for index in range(8):
        sx = 1.0 if index & 4 else -1.0
        sy = 1.0 if index & 2 else -1.0
        sz = 1.0 if index & 1 else -1.0
        local = (sx * half_extents[0], sy * half_extents[1], sz * half_extents[2])
        corner = _to_world(box_position, box_rotation, local)
        out.append(_plane_point(plane_position, normal, corner, 0.0))
    return out


def _plane_capsule(plane_position, plane_rotation, position, rotation, radius, half_length):
    normal = _column(plane_rotation, 2)
    axis = _column(rotation, 2)
    return [_plane_point(plane_position, normal, _axpy(-half_length, axis, position), radius),
            _plane_point(plane_position, normal, _axpy(half_length, axis, position), radius)]


def _lowest_direction(normal, rotation):
    axis = _column(rotation, 2)
    down = _axpy(-_dot(normal, axis), axis, normal)
    length = _norm(down)
    lowest = _scale(down, -1.0 / length) if length > 0.0 else _column(rotation, 0)
    return lowest, _cross(axis, lowest)


def _plane_cylinder(plane_position, plane_rotation, position, rotation, radius, half_length):
    normal = _column(plane_rotation, 2)
    axis = _column(rotation, 2)
    lowest, quarter = _lowest_direction(normal, rotation)
    out = []
    for index in range(8):
        end = -half_length if index % 2 == 0 else half_length
        turn = index // 2
        if turn == 0:
            offset = _scale(lowest, radius)
        elif turn == 1:
            offset = _scale(quarter, radius)
        elif turn == 2:
            offset = _scale(lowest, -radius)
        else:
            offset = _scale(quarter, -radius)
        point = _add(_axpy(end, axis, position), offset)
        out.append(_plane_point(plane_position, normal, point, 0.0))
    return out


def _arc_angle_in_range(angle, start_angle, span):
    return (angle - start_angle) % _TWO_PI <= span


def _plane_ring(plane_position, plane_rotation, position, rotation, radius, start_angle, span,
                is_arc):
    normal = _column(plane_rotation, 2)
    e1 = _column(rotation, 0)
    e2 = _column(rotation, 1)
    c1 = _dot(e1, normal)
    c2 = _dot(e2, normal)
    if c1 == 0.0 and c2 == 0.0:
        angle = start_angle + 0.5 * span if is_arc else 0.0
    else:
        angle = math.atan2(-c2, -c1)
        if is_arc and not _arc_angle_in_range(angle, start_angle, span):
            end_angle = start_angle + span
            height_start = c1 * math.cos(start_angle) + c2 * math.sin(start_angle)
            height_end = c1 * math.cos(end_angle) + c2 * math.sin(end_angle)
            angle = start_angle if height_start <= height_end else end_angle
    offset = _add(_scale(e1, radius * math.cos(angle)), _scale(e2, radius * math.sin(angle)))
    return [_plane_point(plane_position, normal, _add(position, offset), 0.0)]


def _sphere_sphere(centre_a, radius_a, centre_b, radius_b):
    d = _sub(centre_b, centre_a)
    distance = _norm(d)
    normal = _scale(d, 1.0 / distance) if distance > 0.0 else (0.0, 0.0, 1.0)
    return [(normal, _axpy(radius_a, normal, centre_a), distance - radius_a - radius_b)]


def _box_sphere(box_position, box_rotation, h, centre, radius):
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
    return [(_rotate(box_rotation, normal_local),
             _to_world(box_position, box_rotation, surface_local), signed - radius)]


def _capsule_sphere(position, rotation, capsule_radius, half_length, centre, radius):
    axis = _column(rotation, 2)
    t = _clamp(_dot(_sub(centre, position), axis), -half_length, half_length)
    on_axis = _axpy(t, axis, position)
    offset = _sub(centre, on_axis)
    distance = _norm(offset)
    normal = _scale(offset, 1.0 / distance) if distance > 0.0 else _column(rotation, 0)
    return [(normal, _axpy(capsule_radius, normal, on_axis),
             distance - capsule_radius - radius)]


def _cylinder_sphere(position, rotation, cylinder_radius, half_length, centre, radius):
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
    return [(_rotate(rotation, normal_local), _to_world(position, rotation, surface_local),
             signed - radius)]


def _ring_derivatives(theta, a1, b1, a2, b2):
    c, s = math.cos(theta), math.sin(theta)
    c2, s2 = c * c - s * s, 2.0 * s * c
    first = -a1 * s + b1 * c - 2.0 * a2 * s2 + 2.0 * b2 * c2
    second = -a1 * c - b1 * s - 4.0 * a2 * c2 - 4.0 * b2 * s2
    return first, second


def _ring_axis_distance(theta, centre_offset, e1, e2, ring_radius, axis):
    c, s = math.cos(theta), math.sin(theta)
    relative = _add(centre_offset, _add(_scale(e1, ring_radius * c), _scale(e2, ring_radius * s)))
    perpendicular = _axpy(-_dot(relative, axis), axis, relative)
    return _norm(perpendicular), perpendicular


def _ring_newton_bracketed(theta_centre, half_width, a1, b1, a2, b2):
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


def _ring_critical_angles(a1, b1, a2, b2):
    c1 = complex(b1, a1)
    c2 = complex(2.0 * b2, 2.0 * a2)
    roots = np.roots(np.array([c2, c1, 0.0, c1.conjugate(), c2.conjugate()],
                              dtype=np.complex128))
    angles = []
    for root in roots:
        theta = math.atan2(root.imag, root.real)
        for _ in range(4):
            first, second = _ring_derivatives(theta, a1, b1, a2, b2)
            if second == 0.0:
                break
            step = -first / second
            if abs(step) > 0.1:
                break
            theta += step
        angles.append(theta)
    return angles


def _ring_angle(centre_offset, e1, e2, ring_radius, axis, start_angle, span, is_arc, sign):
    """Angle of the ring point nearest the axis (sign 1) or farthest from it (sign -1: a ring
    inside a bore); every coefficient and distance comparison is multiplied by ``sign``."""
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
        return start_angle if is_arc else 0.0
    best_angle = 0.0
    best_distance = math.inf
    if 2.0 * r2 <= _RING_FAST_PATH_RATIO * r1:
        half_width = math.asin(2.0 * r2 / r1)
        theta = _ring_newton_bracketed(math.atan2(-b1, -a1), half_width, a1, b1, a2, b2)
        if not is_arc or _arc_angle_in_range(theta, start_angle, span):
            return theta
    else:
        for angle in _ring_critical_angles(a1, b1, a2, b2):
            if is_arc and not _arc_angle_in_range(angle, start_angle, span):
                continue
            distance, _ = _ring_axis_distance(angle, centre_offset, e1, e2, ring_radius, axis)
            if sign * distance < best_distance:
                best_angle, best_distance = angle, sign * distance
        if not is_arc:
            return best_angle
    for theta in (start_angle, start_angle + span):
        distance, _ = _ring_axis_distance(theta, centre_offset, e1, e2, ring_radius, axis)
        if sign * distance < best_distance:
            best_angle, best_distance = theta, sign * distance
    return best_angle


def _ring_cylinder(ring_position, ring_rotation, ring_radius, start_angle, span, is_arc,
                   cylinder_position, cylinder_rotation, cylinder_radius):
    axis = _column(cylinder_rotation, 2)
    e1 = _column(ring_rotation, 0)
    e2 = _column(ring_rotation, 1)
    centre_offset = _sub(ring_position, cylinder_position)
    theta = _ring_angle(centre_offset, e1, e2, ring_radius, axis, start_angle, span, is_arc,
                        1.0)
    distance, perpendicular = _ring_axis_distance(theta, centre_offset, e1, e2, ring_radius,
                                                  axis)
    inward = _scale(perpendicular, -1.0 / distance) if distance > 0.0 \
        else _any_perpendicular(axis)
    c, s = math.cos(theta), math.sin(theta)
    ring_point = _add(ring_position, _add(_scale(e1, ring_radius * c),
                                          _scale(e2, ring_radius * s)))
    return [(inward, ring_point, distance - cylinder_radius)]


# ---------------------------------------------------------------------------- bounded faces
def _keep_inside_face(plane_position, plane_rotation, half_x, half_y, radius, depth, staged):
    """Per staged contact: True if its point on the face lies inside it (|x| <= half_x and
    |y| <= half_y for a rectangle, radius < 0; x^2 + y^2 <= radius^2 for a disc) and its gap
    is not below -depth (depth 0: no bound). The slots are kept in place (no compaction)."""
    kept = []
    for _, point, gap in staged:
        if depth > 0.0 and gap < -depth:
            kept.append(False)
            continue
        local = _to_local(plane_position, plane_rotation, point)
        if radius >= 0.0:
            inside = local[0] * local[0] + local[1] * local[1] <= radius * radius
        else:
            inside = abs(local[0]) <= half_x and abs(local[1]) <= half_y
        kept.append(inside)
    return kept


# ---------------------------------------------------------------------------- bores
def _bore_angle_in_range(bore_position, bore_rotation, point, start_angle, span):
    local = _to_local(bore_position, bore_rotation, point)
    if span >= _TWO_PI:
        return True
    return _arc_angle_in_range(math.atan2(local[1], local[0]), start_angle, span)


def _ring_in_bore(ring_position, ring_rotation, ring_radius, start_angle, span, is_arc,
                  bore_position, bore_rotation, bore_radius, bore_half_length, bore_start,
                  bore_span, check_axial):
    """Ring (A) inside the bore (B): (staged contact, kept). Not kept when the point on the
    bore is outside the bore's angles (or, with ``check_axial``, beyond |z| > half_length)."""
    axis = _column(bore_rotation, 2)
    e1 = _column(ring_rotation, 0)
    e2 = _column(ring_rotation, 1)
    centre_offset = _sub(ring_position, bore_position)
    theta = _ring_angle(centre_offset, e1, e2, ring_radius, axis, start_angle, span, is_arc,
                        -1.0)
    distance, perpendicular = _ring_axis_distance(theta, centre_offset, e1, e2, ring_radius,
                                                  axis)
    outward = _scale(perpendicular, 1.0 / distance) if distance > 0.0 \
        else _any_perpendicular(axis)
    c, s = math.cos(theta), math.sin(theta)
    ring_point = _add(ring_position, _add(_scale(e1, ring_radius * c),
                                          _scale(e2, ring_radius * s)))
    gap = bore_radius - distance
    staged = (outward, ring_point, gap)
    on_bore = _axpy(gap, outward, ring_point)
    if check_axial and abs(_dot(_sub(on_bore, bore_position), axis)) > bore_half_length:
        return staged, False
    if not _bore_angle_in_range(bore_position, bore_rotation, on_bore, bore_start, bore_span):
        return staged, False
    return staged, True


def _cylinder_in_bore(journal_position, journal_rotation, journal_radius, journal_half_length,
                      bore_position, bore_rotation, bore_radius, bore_half_length, bore_start,
                      bore_span):
    """Journal (A) inside the bore (B): two slots, one per end of the axial overlap (slot 0 at
    the bore's -z side, slot 1 at its +z side); (staged contacts, kept flags)."""
    axis_b = _column(bore_rotation, 2)
    axis_j = _column(journal_rotation, 2)
    direction = 1.0 if _dot(axis_j, axis_b) >= 0.0 else -1.0
    centre = _dot(_sub(journal_position, bore_position), axis_b)
    reach = journal_half_length * abs(_dot(axis_j, axis_b))
    if centre - reach > bore_half_length or centre + reach < -bore_half_length:
        # No axial overlap: two empty slots (a placeholder frame for their Jacobians).
        placeholder = (_any_perpendicular(axis_b), journal_position, 0.0)
        return [placeholder, placeholder], [False, False]
    staged, kept = [], []
    for end in (-1.0, 1.0):
        if end * (centre + end * reach) > bore_half_length:
            rim_position = _axpy(end * bore_half_length, axis_b, bore_position)
            is_arc = bore_span < _TWO_PI
            normal, rim_point, gap = _ring_cylinder(
                rim_position, bore_rotation, bore_radius, bore_start, bore_span, is_arc,
                journal_position, journal_rotation, journal_radius)[0]
            normal = (-normal[0], -normal[1], -normal[2])
            staged.append((normal, _axpy(-gap, normal, rim_point), gap))
            kept.append(True)
        else:
            rim_position = _axpy(direction * end * journal_half_length, axis_j,
                                 journal_position)
            contact, inside = _ring_in_bore(
                rim_position, journal_rotation, journal_radius, 0.0, _TWO_PI, False,
                bore_position, bore_rotation, bore_radius, bore_half_length, bore_start,
                bore_span, False)
            staged.append(contact)
            kept.append(inside)
    return staged, kept


# ---------------------------------------------------------------------------- dispatch
def _canonical(kind_a, pa, pos_a, rot_a, kind_b, pb, pos_b, rot_b):
    """Staged contacts of a canonical pair (inputs as tuples) and the kept flag of each slot."""
    if kind_a in (RECTANGLE, DISC):
        radius = pa[0] if kind_a == DISC else -1.0
        depth = pa[1] if kind_a == DISC else pa[2]
        if kind_b not in (SPHERE, CYLINDER, CIRCLE, ARC):
            raise ValueError(f"unsupported pair {kind_a}-{kind_b}")
        staged = _canonical(PLANE, (), pos_a, rot_a, kind_b, pb, pos_b, rot_b)[0]
        return staged, _keep_inside_face(pos_a, rot_a, pa[0], pa[1], radius, depth, staged)
    if kind_b == BORE:
        bore_span = pb[3] - pb[2]
        if kind_a == CIRCLE:
            contact, kept = _ring_in_bore(pos_a, rot_a, pa[0], 0.0, _TWO_PI, False, pos_b,
                                          rot_b, pb[0], pb[1], pb[2], bore_span, True)
            return [contact], [kept]
        if kind_a == ARC:
            contact, kept = _ring_in_bore(pos_a, rot_a, pa[0], pa[1], pa[2] - pa[1], True,
                                          pos_b, rot_b, pb[0], pb[1], pb[2], bore_span, True)
            return [contact], [kept]
        if kind_a == CYLINDER:
            return _cylinder_in_bore(pos_a, rot_a, pa[0], pa[1], pos_b, rot_b, pb[0], pb[1],
                                     pb[2], bore_span)
        raise ValueError(f"unsupported pair {kind_a}-{kind_b}")
    staged = _unbounded(kind_a, pa, pos_a, rot_a, kind_b, pb, pos_b, rot_b)
    return staged, [True] * len(staged)


def _unbounded(kind_a, pa, pos_a, rot_a, kind_b, pb, pos_b, rot_b):
    """Staged contacts of a canonical pair whose candidates are all kept."""
    if kind_a == PLANE:
        if kind_b == SPHERE:
            return _plane_sphere(pos_a, rot_a, pos_b, pb[0])
        if kind_b == BOX:
            return _plane_box(pos_a, rot_a, pos_b, rot_b, pb)
        if kind_b == CAPSULE:
            return _plane_capsule(pos_a, rot_a, pos_b, rot_b, pb[0], pb[1])
        if kind_b == CYLINDER:
            return _plane_cylinder(pos_a, rot_a, pos_b, rot_b, pb[0], pb[1])
        if kind_b == CIRCLE:
            return _plane_ring(pos_a, rot_a, pos_b, rot_b, pb[0], 0.0, _TWO_PI, False)
        if kind_b == ARC:
            return _plane_ring(pos_a, rot_a, pos_b, rot_b, pb[0], pb[1], pb[2] - pb[1], True)
    elif kind_b == SPHERE:
        if kind_a == SPHERE:
            return _sphere_sphere(pos_a, pa[0], pos_b, pb[0])
        if kind_a == BOX:
            return _box_sphere(pos_a, rot_a, pa, pos_b, pb[0])
        if kind_a == CAPSULE:
            return _capsule_sphere(pos_a, rot_a, pa[0], pa[1], pos_b, pb[0])
        if kind_a == CYLINDER:
            return _cylinder_sphere(pos_a, rot_a, pa[0], pa[1], pos_b, pb[0])
    elif kind_b == CYLINDER:
        if kind_a == CIRCLE:
            return _ring_cylinder(pos_a, rot_a, pa[0], 0.0, _TWO_PI, False, pos_b, rot_b, pb[0])
        if kind_a == ARC:
            return _ring_cylinder(pos_a, rot_a, pa[0], pa[1], pa[2] - pa[1], True, pos_b, rot_b,
                                  pb[0])
    raise ValueError(f"unsupported pair {kind_a}-{kind_b}")


def _placement_precedes(pa, pos_a, rot_a, pb, pos_b, rot_b):
    for x, y in zip(pa, pb, strict=True):
        if x != y:
            return x < y
    for x, y in zip(pos_a, pos_b, strict=True):
        if x != y:
            return x < y
    for row_a, row_b in zip(rot_a, rot_b, strict=True):
        for x, y in zip(row_a, row_b, strict=True):
            if x != y:
                return x < y
    return False


def _tuples(params, position, rotation):
    params = tuple(float(v) for v in params) + (0.0,) * (8 - len(params))
    position = tuple(np.asarray(position, dtype=float).tolist())
    rotation = tuple(tuple(row) for row in np.asarray(rotation, dtype=float).tolist())
    return params, position, rotation


def pair_contact_slots(kind_a, params_a, position_a, rotation_a, kind_b, params_b,
                       position_b, rotation_b):
    """Every candidate slot of shape A against shape B, dropped or not.

    A bounded face (rectangle, disc) or a bore drops the candidates outside it (or, for a face
    with a depth, deeper than it); the shared geometry compacts the kept ones to the front,
    this function keeps each candidate in its slot (slot k is always the same kernel
    candidate, so one Siconos interaction follows it) and flags it.

    Parameters
    ----------
    kind_a, kind_b : str
        Shape kinds ('sphere', 'box', ...).
    params_a, params_b : sequence of float
        Packed parameters as ``scenarios.geometry.pack_shape_parameters`` (sphere [radius],
        box [hx, hy, hz], capsule / cylinder [radius, half_length], plane [], circle [radius],
        arc [radius, start_angle, end_angle], rectangle [hx, hy, depth], disc [radius, depth],
        bore [radius, half_length, start_angle, end_angle]; depth 0: unbounded).
    position_a, position_b : (3,) world position of each shape frame [L].
    rotation_a, rotation_b : (3, 3) world rotation of each shape frame.

    Returns
    -------
    gap : ndarray (K,) [L], K = candidate_count(kind_a, kind_b)
    point_a, point_b : ndarray (K, 3) world [L]
    frame : ndarray (K, 3, 3), rows (n, t1, t2), n from A toward B
    kept : ndarray (K,) bool, False for a dropped candidate (its values are the kernel's
        before the bound was applied, or a placeholder when the kernel computed none)
    """
    pa, pos_a, rot_a = _tuples(params_a, position_a, rotation_a)
    pb, pos_b, rot_b = _tuples(params_b, position_b, rotation_b)
    if kind_a == kind_b:
        swap = _placement_precedes(pb, pos_b, rot_b, pa, pos_a, rot_a)
    else:
        swap = (kind_a, kind_b) not in CANONICAL_PAIRS
    if swap:
        staged, kept = _canonical(kind_b, pb, pos_b, rot_b, kind_a, pa, pos_a, rot_a)
    else:
        staged, kept = _canonical(kind_a, pa, pos_a, rot_a, kind_b, pb, pos_b, rot_b)
    gaps, points_a, points_b, frames = [], [], [], []
    for normal, first, g in staged:
        normal = _scale(normal, 1.0 / _norm(normal))
        second = _axpy(g, normal, first)
        if swap:
            normal = _scale(normal, -1.0)
            first, second = second, first
        # The shared kernel caches t1 while the normal repeats; t1 is a function of n alone.
        tangent = frame_tangent(normal[0], normal[1], normal[2])
        gaps.append(g)
        points_a.append(first)
        points_b.append(second)
        frames.append((normal, tangent, _cross(normal, tangent)))
    return (np.array(gaps, dtype=float), np.array(points_a, dtype=float).reshape(-1, 3),
            np.array(points_b, dtype=float).reshape(-1, 3),
            np.array(frames, dtype=float).reshape(-1, 3, 3), np.array(kept, dtype=bool))


def pair_contacts(kind_a, params_a, position_a, rotation_a, kind_b, params_b, position_b,
                  rotation_b):
    """Candidate contacts of shape A against shape B, as ``scenarios.geometry`` returns them:
    the kept slots of :func:`pair_contact_slots`, in order (gap (K,), point_a (K, 3), point_b
    (K, 3), frame (K, 3, 3); K <= candidate_count)."""
    gap, point_a, point_b, frame, kept = pair_contact_slots(
        kind_a, params_a, position_a, rotation_a, kind_b, params_b, position_b, rotation_b)
    return gap[kept], point_a[kept], point_b[kept], frame[kept]
