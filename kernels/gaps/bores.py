"""Ring (circle or arc) or journal (cylinder) INSIDE a bore (A = ring or journal, B = bore)."""

from __future__ import annotations

import math

from clearbench.kernels.gaps.codes import ARC, CIRCLE, CYLINDER, TWO_PI
from clearbench.kernels.gaps.rings import (
    arc_angle_in_range,
    ring_angle,
    ring_axis_distance,
    ring_cylinder,
)
from clearbench.kernels.gaps.round_solids import (
    BORE_SOLID,
    radial_exit_is_nearest,
    ring_solid_minimum,
)
from clearbench.kernels.gaps.staging import copy_staged, stage_contact, within_depth
from clearbench.kernels.gaps.vectors import (
    add,
    any_perpendicular,
    axpy,
    column_of,
    dot,
    rotate,
    rotate_back,
    scaled,
    sub,
    to_local,
    to_world,
)
from clearbench.kernels.jit import njit


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
                  bore_span, bore_depth, check_axial, index, stage):
    """Ring (A) inside the bore (B), staged at ``index``: the ring point of smallest signed
    distance to the bore's solid (:mod:`.round_solids`), the normal from it into the solid
    (from A into B). Without ``check_axial`` (a journal's end rim, inside the axial overlap by
    construction) the bore's ends are not read.

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
    on_bore = axpy(gap, outward, ring_point)
    if (abs(dot(sub(on_bore, bore_position), axis)) <= half_length
            and _bore_angle_in_range(bore_position, bore_rotation, on_bore, bore_start,
                                     bore_span)
            and radial_exit_is_nearest(gap, to_local(bore_position, bore_rotation, ring_point),
                                       bore_radius, half_length, bore_start, bore_span,
                                       bore_depth)):
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
                          bore_radius, bore_half_length, bore_start, bore_span, bore_depth, index,
                          stage):
    """The candidate at the ``end`` (-1: the bore's -z side, +1: its +z side) of the axial
    overlap of a journal (A) and a bore (B), staged at ``index``; True if kept. An end inside
    the bore is the journal's end rim (a ring in the bore, :func:`_ring_in_bore`); an
    end where the journal runs beyond the bore is the bore's end rim against the journal's
    lateral surface (always kept)."""
    axis_b = column_of(bore_rotation, 2)
    if end * (centre + end * reach) > bore_half_length:
        # The journal runs beyond this end of the bore: the bore's end rim.
        rim_position = axpy(end * bore_half_length, axis_b, bore_position)
        is_arc = bore_span < TWO_PI
        ring_cylinder(rim_position, bore_rotation, bore_radius, bore_start, bore_span, is_arc,
                      journal_position, journal_rotation, journal_radius, stage[index:])
        # Mirror into (A = journal, B = bore): normal from the journal outward.
        gap = stage[index, 2, 0]
        normal = (-stage[index, 0, 0], -stage[index, 0, 1], -stage[index, 0, 2])
        rim_point = (stage[index, 1, 0], stage[index, 1, 1], stage[index, 1, 2])
        stage_contact(stage, index, gap, axpy(-gap, normal, rim_point), normal)
        return True
    rim_position = axpy(direction * end * journal_half_length, column_of(journal_rotation, 2),
                        journal_position)
    return _ring_in_bore(rim_position, journal_rotation, journal_radius, 0.0, TWO_PI, False,
                         bore_position, bore_rotation, bore_radius, bore_half_length,
                         bore_start, bore_span, bore_depth, False, index, stage) == 1


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
    off centre, onto its rim) is seen before it enters the hole; slot 1 is dropped."""
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
                      bore_span, bore_depth, True, 0, stage)
        # Slot 1 is dropped; it holds the journal's centre, a gap 0 and a normal across the
        # bore's axis (an engine following slots from step to step reads a defined state).
        stage_contact(stage, 1, 0.0, journal_position, any_perpendicular(axis_b))
        return 2, True, False
    kept_0 = _cylinder_end_in_bore(-1.0, direction, centre, reach, journal_position,
                                   journal_rotation, journal_radius, journal_half_length,
                                   bore_position, bore_rotation, bore_radius, bore_half_length,
                                   bore_start, bore_span, bore_depth, 0, stage)
    kept_1 = _cylinder_end_in_bore(1.0, direction, centre, reach, journal_position,
                                   journal_rotation, journal_radius, journal_half_length,
                                   bore_position, bore_rotation, bore_radius, bore_half_length,
                                   bore_start, bore_span, bore_depth, 1, stage)
    return 2, kept_0, kept_1


@njit(cache=True, inline="always")
def bore_slots(kind_a, params_a, position_a, rotation_a, params_b, position_b, rotation_b,
               stage):
    """A circle, arc or journal (A) inside a bore (B): (slots, kept_0, kept_1), every slot
    staged (:func:`_ring_in_bore`, :func:`_cylinder_in_bore`); slots -1 for any other A. A
    ring's slot is always kept (its gap is a signed distance to the bore's solid, never below
    -depth / 2); a journal's slot whose gap is below -depth (``params_b[4]`` > 0) is not kept:
    the journal is behind the bore's solid, not in it."""
    bore_span = params_b[3] - params_b[2]
    if kind_a == CIRCLE:
        kept = _ring_in_bore(position_a, rotation_a, params_a[0], 0.0, TWO_PI, False,
                             position_b, rotation_b, params_b[0], params_b[1], params_b[2],
                             bore_span, params_b[4], True, 0, stage)
        return 1, kept == 1, False
    if kind_a == ARC:
        kept = _ring_in_bore(position_a, rotation_a, params_a[0], params_a[1],
                             params_a[2] - params_a[1], True, position_b, rotation_b,
                             params_b[0], params_b[1], params_b[2], bore_span, params_b[4], True,
                             0, stage)
        return 1, kept == 1, False
    if kind_a == CYLINDER:
        slots, kept_0, kept_1 = _cylinder_in_bore(
            position_a, rotation_a, params_a[0], params_a[1], position_b, rotation_b,
            params_b[0], params_b[1], params_b[2], bore_span, params_b[4], stage)
        return (slots, kept_0 and within_depth(params_b[4], stage, 0),
                kept_1 and slots == 2 and within_depth(params_b[4], stage, 1))
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
