"""Ring (circle or arc) or journal (cylinder) INSIDE a bore (A = ring or journal, B = bore)."""

from __future__ import annotations

import math

import numpy as np

from clearbench.kernels.gaps.codes import ARC, CIRCLE, CYLINDER, TWO_PI
from clearbench.kernels.gaps.ring_cylinders import ring_cylinder_solid
from clearbench.kernels.gaps.rings import (
    arc_angle_in_range,
    ring_angle,
    ring_axis_distance,
)
from clearbench.kernels.gaps.round_solids import (
    _GOLDEN,
    BORE_SOLID,
    CYLINDER_SOLID,
    cylinder_solid_distance,
    radial_exit_is_nearest,
    ring_solid_minimum,
)
from clearbench.kernels.gaps.staging import (
    copy_staged,
    copy_staged_from,
    stage_contact,
    within_depth,
)
from clearbench.kernels.gaps.vectors import (
    add,
    any_perpendicular,
    axpy,
    column_of,
    dot,
    norm,
    rotate,
    rotate_back,
    scaled,
    sub,
    to_local,
    to_world,
)
from clearbench.kernels.jit import njit

#: Golden-section steps along a bore's cut edge (:func:`_segment_in_cylinder`).
EDGE_GOLDEN_STEPS = 80
#: Golden-section steps along a partial bore's axis (:func:`_surface_in_journal`).
SURFACE_GOLDEN_STEPS = 40
#: Two candidates of a journal beside its bore whose points on the journal lie within this
#: fraction of the journal's radius are one contact (the bore's end rim met at the journal's
#: own rim): the second is not kept, so a solver is not given the same contact twice. Far above
#: the two searches' agreement (1e-12 of the radius where both are closed forms, about 1e-9
#: where one is a golden-section minimum), far below any distance between distinct contacts.
SAME_CONTACT = 1e-6


@njit(cache=True, inline="always")
def _bore_angle_in_range(bore_position, bore_rotation, point, start_angle, span):
    """True if the radial direction of ``point`` from the bore axis lies in the bore's angles."""
    local = to_local(bore_position, bore_rotation, point)
    if span >= TWO_PI:
        return True
    return arc_angle_in_range(math.atan2(local[1], local[0]), start_angle, span)


@njit(cache=True)
def _ring_in_bore(ring_position, ring_rotation, ring_radius, start_angle, span, is_arc,
                  bore_position, bore_rotation, bore_radius, bore_half_length, bore_start,
                  bore_span, bore_depth, check_axial, read_back, index, stage):
    """Ring (A) inside the bore (B), staged at ``index``: the ring point of smallest signed
    distance to the bore's solid (:mod:`.round_solids`), the normal from it into the solid
    (from A into B). Without ``check_axial`` (a journal's end rim, inside the axial overlap by
    construction) the bore's ends are not read; without ``read_back`` (the end rim of a journal
    whose axis is in the hole) its back is not: such a rim deeper in the wall than half its
    depth is pushed back into the hole (the journal's separation from the solid), not on
    through the wall.

    The closed form first: gap = bore radius - largest distance of a ring point from the bore
    axis, the normal radially outward from that point. It is that smallest signed distance when
    the point lies within the bore's angles and ends and, beyond the surface, is no nearer
    another boundary of the solid (a point inside the hole is no nearer any other boundary
    than the bore's surface, and a ring point no farther from the axis is no deeper). Otherwise
    (the ring passing the bore's edge, its end, or deep in the solid)
    :func:`.round_solids.ring_solid_minimum`. Returns 1 (the slot is always kept).
    """
    axis = column_of(bore_rotation, 2)
    e1 = column_of(ring_rotation, 0)
    e2 = column_of(ring_rotation, 1)
    centre_offset = sub(ring_position, bore_position)
    theta = ring_angle(centre_offset, e1, e2, ring_radius, axis, start_angle, span, is_arc,
                       -1.0)
    distance, perpendicular = ring_axis_distance(theta, centre_offset, e1, e2, ring_radius,
                                                 axis)
    if distance > 0.0:
        outward = scaled(perpendicular, 1.0 / distance)
    else:
        outward = any_perpendicular(axis)
    c, s = math.cos(theta), math.sin(theta)
    ring_point = add(ring_position, add(scaled(e1, ring_radius * c),
                                          scaled(e2, ring_radius * s)))
    gap = bore_radius - distance
    half_length = bore_half_length if check_axial else math.inf
    back = bore_depth if read_back else 0.0
    on_bore = axpy(gap, outward, ring_point)
    if (abs(dot(sub(on_bore, bore_position), axis)) <= half_length
            and _bore_angle_in_range(bore_position, bore_rotation, on_bore, bore_start,
                                     bore_span)
            and radial_exit_is_nearest(gap, to_local(bore_position, bore_rotation, ring_point),
                                       bore_radius, half_length, bore_start, bore_span, back)):
        stage_contact(stage, index, gap, ring_point, outward)
        return 1
    _, smallest, point, gradient = ring_solid_minimum(
        BORE_SOLID, to_local(bore_position, bore_rotation, ring_position),
        rotate_back(bore_rotation, e1), rotate_back(bore_rotation, e2), ring_radius,
        start_angle, span, is_arc, bore_radius, half_length, bore_start, bore_span, bore_depth)
    stage_contact(stage, index, smallest, to_world(bore_position, bore_rotation, point),
                  rotate(bore_rotation, scaled(gradient, -1.0)))
    return 1


@njit(cache=True, inline="always")
def _cylinder_end_in_bore(end, direction, centre, reach, journal_position, journal_rotation,
                          journal_radius, journal_half_length, bore_position, bore_rotation,
                          bore_radius, bore_half_length, bore_start, bore_span, bore_depth,
                          in_hole, index, stage):
    """The candidate at the ``end`` (-1: the bore's -z side, +1: its +z side) of the axial
    overlap of a journal (A) and a bore (B), staged at ``index``; True if kept. An end inside
    the bore is the journal's end rim (a ring in the bore, :func:`_ring_in_bore`); an
    end where the journal runs beyond the bore is the bore's end rim against the journal's
    lateral surface; kept unless the journal is behind the solid (:func:`bore_slots`)."""
    axis_b = column_of(bore_rotation, 2)
    if end * (centre + end * reach) > bore_half_length:
        # The journal runs beyond this end of the bore: the bore's end rim.
        rim_position = axpy(end * bore_half_length, axis_b, bore_position)
        # Against the journal's finite solid: where the journal's end has just passed the
        # rim, the rim's nearest point can lie beyond that end (the infinitely long journal
        # read 0.001 mm there in c60-trip's plunger bearing, the finite one 0.0018 mm).
        ring_cylinder_solid(rim_position, bore_rotation, bore_radius, bore_start, bore_span,
                            bore_span < TWO_PI, journal_position, journal_rotation,
                            journal_radius, journal_half_length, stage[index:])
        # Mirror into (A = journal, B = bore): normal from the journal outward.
        gap = stage[index, 2, 0]
        normal = (-stage[index, 0, 0], -stage[index, 0, 1], -stage[index, 0, 2])
        rim_point = (stage[index, 1, 0], stage[index, 1, 1], stage[index, 1, 2])
        stage_contact(stage, index, gap, axpy(-gap, normal, rim_point), normal)
        # A tilted journal's own end rim can be inside the bore there while its axis runs
        # beyond: that rim against the bore's solid, its ends read, where it is nearer. A rim
        # wholly beyond the bore's end (its points reach r sin(tilt) along the bore's axis)
        # is not.
        axis_j = column_of(journal_rotation, 2)
        rim_centre = axpy(direction * end * journal_half_length, axis_j, journal_position)
        tilt_reach = journal_radius * math.sqrt(max(0.0, 1.0 - dot(axis_j, axis_b) ** 2))
        if end * dot(sub(rim_centre, bore_position), axis_b) - tilt_reach < bore_half_length:
            own = np.empty((1, 3, 3))
            _ring_in_bore(rim_centre, journal_rotation, journal_radius, 0.0, TWO_PI, False,
                          bore_position, bore_rotation, bore_radius, bore_half_length,
                          bore_start, bore_span, bore_depth, True, not in_hole, 0, own)
            if own[0, 2, 0] < gap:
                copy_staged_from(own, stage, index)
        return in_hole or within_depth(bore_depth, stage, index)
    rim_position = axpy(direction * end * journal_half_length, column_of(journal_rotation, 2),
                        journal_position)
    _ring_in_bore(rim_position, journal_rotation, journal_radius, 0.0, TWO_PI, False,
                  bore_position, bore_rotation, bore_radius, bore_half_length, bore_start,
                  bore_span, bore_depth, False, not in_hole, index, stage)
    # A journal whose axis is in the hole is in the bore, however deep in its wall; one
    # beside the hole deeper than the bore's depth is behind its solid, not in it.
    return in_hole or within_depth(bore_depth, stage, index)


@njit(cache=True)
def _segment_in_cylinder(start, end, radius, half_length):
    """The point of the segment ``start``-``end`` (cylinder-frame 3-tuples [L]) of smallest
    signed distance to the cylinder's solid: (distance [L], point, gradient). The distance is
    convex along the segment (the solid is convex), so a golden-section search over it finds
    its minimum: EDGE_GOLDEN_STEPS shrink the segment to 0.618^80 = 2e-17 of its length."""
    low, high = 0.0, 1.0
    inner = high - _GOLDEN * (high - low)
    outer = low + _GOLDEN * (high - low)
    f_inner = cylinder_solid_distance(radius, half_length, _along(start, end, inner))[0]
    f_outer = cylinder_solid_distance(radius, half_length, _along(start, end, outer))[0]
    for _ in range(EDGE_GOLDEN_STEPS):
        if f_inner <= f_outer:
            high, outer, f_outer = outer, inner, f_inner
            inner = high - _GOLDEN * (high - low)
            f_inner = cylinder_solid_distance(radius, half_length, _along(start, end, inner))[0]
        else:
            low, inner, f_inner = inner, outer, f_outer
            outer = low + _GOLDEN * (high - low)
            f_outer = cylinder_solid_distance(radius, half_length, _along(start, end, outer))[0]
    best_t = inner if f_inner <= f_outer else outer
    for t in (0.0, 1.0):  # the ends, where the minimum of a monotone stretch lies
        if cylinder_solid_distance(radius, half_length, _along(start, end, t))[0] \
                < cylinder_solid_distance(radius, half_length, _along(start, end, best_t))[0]:
            best_t = t
    point = _along(start, end, best_t)
    distance, gradient = cylinder_solid_distance(radius, half_length, point)
    return distance, point, gradient


@njit(cache=True, inline="always")
def _along(start, end, t):
    return (start[0] + t * (end[0] - start[0]), start[1] + t * (end[1] - start[1]),
            start[2] + t * (end[2] - start[2]))


@njit(cache=True)
def _bore_edges_in_journal(journal_position, journal_rotation, journal_radius,
                           journal_half_length, bore_position, bore_rotation, bore_radius,
                           bore_half_length, bore_start, bore_span, bore_depth):
    """The point of the bore's edges (its two end rims, circles or arcs, and a partial bore's
    two cut edges at its radius; for a bore with a back also the back's end rims, the cut edges
    at the back's radius and the cut faces' radial edges at the ends) of smallest signed
    distance to the journal's solid: (distance
    [L], point on the journal's surface (world), unit normal from the journal toward that edge
    point (world), the edge point's z in the bore's frame [L]). The journal's end rims (the
    other candidates) do not see these where the journal's lateral surface or end face lies
    across a partial bore's cut or its end."""
    best = math.inf
    best_local = (0.0, 0.0, 0.0)
    best_gradient = (1.0, 0.0, 0.0)
    best_z = 0.0
    axis_b = column_of(bore_rotation, 2)
    is_arc = bore_span < TWO_PI
    e1 = rotate_back(journal_rotation, column_of(bore_rotation, 0))
    e2 = rotate_back(journal_rotation, column_of(bore_rotation, 1))
    # A bore with a back has a second rim at each end, the back's (radius + depth).
    rims = 2 if bore_depth > 0.0 else 1
    for end in (-1.0, 1.0):
        rim_centre = to_local(journal_position, journal_rotation,
                              axpy(end * bore_half_length, axis_b, bore_position))
        for which in range(rims):
            r = bore_radius + which * bore_depth
            _, distance, point, gradient = ring_solid_minimum(
                CYLINDER_SOLID, rim_centre, e1, e2, r, bore_start, bore_span, is_arc,
                journal_radius, journal_half_length, 0.0, 0.0, 0.0)
            if distance < best:
                best, best_local, best_gradient, best_z = distance, point, gradient, \
                    end * bore_half_length
    axis_j = column_of(journal_rotation, 2)
    for end in (-1.0, 1.0):
        # Where the journal's axis crosses the plane of this end face, if that point is on
        # the face (a journal beside the hole, its lateral surface across the face): the
        # journal's deepest point of that plane when away from the journal's ends.
        face_centre = axpy(end * bore_half_length, axis_b, bore_position)
        across = dot(axis_j, axis_b)
        if abs(across) < 1e-12:
            continue
        along = dot(sub(face_centre, journal_position), axis_b) / across
        crossing = axpy(along, axis_j, journal_position)
        local_b = to_local(bore_position, bore_rotation, crossing)
        rho = math.hypot(local_b[0], local_b[1])
        if rho < bore_radius or (bore_depth > 0.0 and rho > bore_radius + bore_depth):
            continue
        if is_arc and not arc_angle_in_range(math.atan2(local_b[1], local_b[0]), bore_start,
                                             bore_span):
            continue
        point = to_local(journal_position, journal_rotation, crossing)
        distance, gradient = cylinder_solid_distance(journal_radius, journal_half_length, point)
        if distance < best:
            best, best_local, best_gradient, best_z = distance, point, gradient, \
                end * bore_half_length
    if is_arc:
        # The cut edges along the axis (at the radius, and at the back's for a bore with one)
        # and, for a bore with a back, the cut face's radial edges at the ends.
        for angle in (bore_start, bore_start + bore_span):
            c, s = math.cos(angle), math.sin(angle)
            for segment in range(4 if rims == 2 else 1):
                if segment < 2:
                    r = bore_radius + segment * bore_depth
                    first = (r * c, r * s, -bore_half_length)
                    second = (r * c, r * s, bore_half_length)
                else:
                    z = (2 * segment - 5) * bore_half_length  # -h, then +h
                    back = bore_radius + bore_depth
                    first = (bore_radius * c, bore_radius * s, z)
                    second = (back * c, back * s, z)
                low = to_local(journal_position, journal_rotation,
                               to_world(bore_position, bore_rotation, first))
                high = to_local(journal_position, journal_rotation,
                                to_world(bore_position, bore_rotation, second))
                distance, point, gradient = _segment_in_cylinder(low, high, journal_radius,
                                                                 journal_half_length)
                if distance < best:
                    best, best_local, best_gradient = distance, point, gradient
                    best_z = dot(sub(to_world(journal_position, journal_rotation, point),
                                     bore_position), axis_b)
    surface = axpy(-best, best_gradient, best_local)
    return (best, to_world(journal_position, journal_rotation, surface),
            rotate(journal_rotation, best_gradient), best_z)


@njit(cache=True)
def _surface_in_journal(journal_position, journal_rotation, journal_radius, journal_half_length,
                        low, high, bore_position, bore_rotation, bore_radius, bore_start,
                        bore_span):
    """The point of a partial bore's surface between its axial coordinates ``low`` and
    ``high`` [L] (where the journal is) of smallest signed distance to the journal's solid:
    (distance [L], point on the journal's surface (world), unit normal from the journal toward
    that point (world), its z in the bore's frame [L]). Across the bore's cut that point can
    lie between the journal's end rims and off the cut's edge (the journal's depth below the
    bore's surface and the distance to the cut balance there). Each of the bore's arcs is
    minimised over its angle (:func:`.round_solids.ring_solid_minimum`); the arcs' minimum over
    z by SURFACE_GOLDEN_STEPS of golden-section search (0.618^40 = 4e-9 of the range)."""
    inner = high - _GOLDEN * (high - low)
    outer = low + _GOLDEN * (high - low)
    f_inner = _arc_in_journal(journal_position, journal_rotation, journal_radius,
                              journal_half_length, inner, bore_position, bore_rotation,
                              bore_radius, bore_start, bore_span)[0]
    f_outer = _arc_in_journal(journal_position, journal_rotation, journal_radius,
                              journal_half_length, outer, bore_position, bore_rotation,
                              bore_radius, bore_start, bore_span)[0]
    for _ in range(SURFACE_GOLDEN_STEPS):
        if f_inner <= f_outer:
            high, outer, f_outer = outer, inner, f_inner
            inner = high - _GOLDEN * (high - low)
            f_inner = _arc_in_journal(journal_position, journal_rotation, journal_radius,
                                      journal_half_length, inner, bore_position, bore_rotation,
                                      bore_radius, bore_start, bore_span)[0]
        else:
            low, inner, f_inner = inner, outer, f_outer
            outer = low + _GOLDEN * (high - low)
            f_outer = _arc_in_journal(journal_position, journal_rotation, journal_radius,
                                      journal_half_length, outer, bore_position, bore_rotation,
                                      bore_radius, bore_start, bore_span)[0]
    z = inner if f_inner <= f_outer else outer
    distance, point, gradient = _arc_in_journal(
        journal_position, journal_rotation, journal_radius, journal_half_length, z,
        bore_position, bore_rotation, bore_radius, bore_start, bore_span)
    surface = axpy(-distance, gradient, point)
    return (distance, to_world(journal_position, journal_rotation, surface),
            rotate(journal_rotation, gradient), z)


@njit(cache=True, inline="always")
def _arc_in_journal(journal_position, journal_rotation, journal_radius, journal_half_length, z,
                    bore_position, bore_rotation, bore_radius, bore_start, bore_span):
    """The bore's arc at height ``z`` [L] against the journal's solid: its point of smallest
    signed distance (distance [L], point and gradient in the journal's frame)."""
    centre = to_local(journal_position, journal_rotation,
                      axpy(z, column_of(bore_rotation, 2), bore_position))
    _, distance, point, gradient = ring_solid_minimum(
        CYLINDER_SOLID, centre, rotate_back(journal_rotation, column_of(bore_rotation, 0)),
        rotate_back(journal_rotation, column_of(bore_rotation, 1)), bore_radius, bore_start,
        bore_span, True, journal_radius, journal_half_length, 0.0, 0.0, 0.0)
    return distance, point, gradient


@njit(cache=True)
def _cylinder_in_bore(journal_position, journal_rotation, journal_radius, journal_half_length,
                      bore_position, bore_rotation, bore_radius, bore_half_length, bore_start,
                      bore_span, bore_depth, stage):
    """Journal cylinder (A) inside the bore (B): one candidate at each end of their axial
    overlap, where the radial gap of two nearly coaxial cylinders is smallest (it is concave
    along the axis), in slot 0 (the bore's -z side) and slot 1 (its +z side)
    (:func:`_cylinder_end_in_bore`). Returns (2, kept_0, kept_1). Without axial overlap, slot
    0 is the journal's end rim nearer the bore, a ring against the bore's solid with its ends
    (:func:`_ring_in_bore`), so a journal pushed along its axis onto the bore's end face (or,
    off centre, onto its rim) is seen before it enters the hole; slot 1 is the bore's edges
    against the journal's solid (:func:`_bore_edges_in_journal`: its end rim against the
    journal's lateral surface, tilted or beside the hole), not kept where it is slot 0's contact
    (its point within SAME_CONTACT of the journal's radius of slot 0's)."""
    axis_b = column_of(bore_rotation, 2)
    axis_j = column_of(journal_rotation, 2)
    direction = 1.0 if dot(axis_j, axis_b) >= 0.0 else -1.0
    centre = dot(sub(journal_position, bore_position), axis_b)
    reach = journal_half_length * abs(dot(axis_j, axis_b))
    if centre - reach > bore_half_length or centre + reach < -bore_half_length:
        # No axial overlap: the journal's end rim nearer the bore, a ring against the bore's
        # solid (ends included), meets the bore's end face or its rim.
        end = -1.0 if centre > 0.0 else 1.0
        rim_position = axpy(direction * end * journal_half_length, axis_j, journal_position)
        _ring_in_bore(rim_position, journal_rotation, journal_radius, 0.0, TWO_PI, False,
                      bore_position, bore_rotation, bore_radius, bore_half_length, bore_start,
                      bore_span, bore_depth, True, True, 0, stage)
        # Slot 1: the bore's edges against the journal's solid (its end rim against the
        # journal's lateral surface or end face, a journal beside the hole across its end face).
        edge, point, normal, _ = _bore_edges_in_journal(
            journal_position, journal_rotation, journal_radius, journal_half_length,
            bore_position, bore_rotation, bore_radius, bore_half_length, bore_start, bore_span,
            bore_depth)
        stage_contact(stage, 1, edge, point, normal)
        kept_0 = within_depth(bore_depth, stage, 0)
        apart = norm(sub((stage[1, 1, 0], stage[1, 1, 1], stage[1, 1, 2]),
                         (stage[0, 1, 0], stage[0, 1, 1], stage[0, 1, 2])))
        return 2, kept_0, not kept_0 or apart > SAME_CONTACT * journal_radius
    local = to_local(bore_position, bore_rotation, journal_position)
    in_hole = math.hypot(local[0], local[1]) < bore_radius
    kept_0 = _cylinder_end_in_bore(-1.0, direction, centre, reach, journal_position,
                                   journal_rotation, journal_radius, journal_half_length,
                                   bore_position, bore_rotation, bore_radius, bore_half_length,
                                   bore_start, bore_span, bore_depth, in_hole, 0, stage)
    kept_1 = _cylinder_end_in_bore(1.0, direction, centre, reach, journal_position,
                                   journal_rotation, journal_radius, journal_half_length,
                                   bore_position, bore_rotation, bore_radius, bore_half_length,
                                   bore_start, bore_span, bore_depth, in_hole, 1, stage)
    if bore_span < TWO_PI:
        # Across a partial bore's cut, the bore's surface in the journal between its rims.
        # The bore's z within the journal's axial reach (the overlap).
        low = max(-bore_half_length, centre - reach - journal_radius)
        high = min(bore_half_length, centre + reach + journal_radius)
        lateral, point, normal, z = _surface_in_journal(
            journal_position, journal_rotation, journal_radius, journal_half_length, low, high,
            bore_position, bore_rotation, bore_radius, bore_start, bore_span)
        side = 0 if z < centre else 1
        if lateral < stage[side, 2, 0] or not (kept_0 if side == 0 else kept_1):
            stage_contact(stage, side, lateral, point, normal)
            if side == 0:
                kept_0 = True
            else:
                kept_1 = True
    tilt_reach = journal_radius * math.sqrt(max(0.0, 1.0 - dot(axis_j, axis_b) ** 2))
    end_face_out = abs(centre) + reach + tilt_reach > bore_half_length
    if bore_span < TWO_PI or bore_depth > 0.0 or end_face_out:
        # A partial bore or one with a back: its edges inside the journal, deeper than the
        # journal's rims where the journal lies across its cut or its end, replace the
        # candidate of their side. A full bore without a back (the C-60's plunger bearing)
        # has such a place only where the journal's end face reaches past the bore's end (a
        # tilted journal whose axis ends inside: the bore's end rim meets the end face's
        # edge, which the journal's own rim, read against the bore's surface, does not see).
        edge, point, normal, z = _bore_edges_in_journal(
            journal_position, journal_rotation, journal_radius, journal_half_length,
            bore_position, bore_rotation, bore_radius, bore_half_length, bore_start, bore_span,
            bore_depth)
        side = 0 if z < centre else 1
        kept = kept_0 if side == 0 else kept_1
        if not kept or edge < stage[side, 2, 0]:
            stage_contact(stage, side, edge, point, normal)
            if side == 0:
                kept_0 = True
            else:
                kept_1 = True
    return 2, kept_0, kept_1


@njit(cache=True, inline="always")
def bore_slots(kind_a, params_a, position_a, rotation_a, params_b, position_b, rotation_b,
               stage):
    """A circle, arc or journal (A) inside a bore (B): (slots, kept_0, kept_1), every slot
    staged (:func:`_ring_in_bore`, :func:`_cylinder_in_bore`); slots -1 for any other A. A
    ring's slot is always kept (its gap is a signed distance to the bore's solid, never below
    -depth / 2); the slot of a journal whose axis is outside the hole and whose gap is below
    -depth (``params_b[4]`` > 0) is not kept: the journal is behind the bore's solid, not in
    it."""
    bore_span = params_b[3] - params_b[2]
    if kind_a == CIRCLE:
        kept = _ring_in_bore(position_a, rotation_a, params_a[0], 0.0, TWO_PI, False,
                             position_b, rotation_b, params_b[0], params_b[1], params_b[2],
                             bore_span, params_b[4], True, True, 0, stage)
        return 1, kept == 1, False
    if kind_a == ARC:
        kept = _ring_in_bore(position_a, rotation_a, params_a[0], params_a[1],
                             params_a[2] - params_a[1], True, position_b, rotation_b,
                             params_b[0], params_b[1], params_b[2], bore_span, params_b[4], True,
                             True, 0, stage)
        return 1, kept == 1, False
    if kind_a == CYLINDER:
        slots, kept_0, kept_1 = _cylinder_in_bore(
            position_a, rotation_a, params_a[0], params_a[1], position_b, rotation_b,
            params_b[0], params_b[1], params_b[2], bore_span, params_b[4], stage)
        return slots, kept_0, kept_1
    return -1, False, False


@njit(cache=True, inline="always")
def compact_bore_slots(slots, kept_0, kept_1, stage):
    """Number of kept contacts of :func:`bore_slots`, moved to the front (-1 stays -1)."""
    if slots < 0:
        return -1
    if kept_0:
        return 2 if slots == 2 and kept_1 else 1
    if slots == 2 and kept_1:
        copy_staged(stage, 1, 0)
        return 1
    return 0
