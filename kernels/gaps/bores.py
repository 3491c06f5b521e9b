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
from clearbench.kernels.gaps.staging import copy_staged, stage_contact, within_depth
from clearbench.kernels.gaps.vectors import (
    add,
    any_perpendicular,
    axpy,
    column_of,
    dot,
    scaled,
    sub,
    to_local,
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
                  bore_span, check_axial, index, stage):
    """Ring (A) inside the bore (B): gap = bore radius - largest distance of a ring point from
    the bore axis; the normal points from that ring point radially outward (from A into B).
    The contact is staged at ``index`` in every case and kept only if its point on the bore
    lies within the bore's angles (and, with ``check_axial``, within |z| <= half_length).
    Returns 1 if kept, else 0 (a compacting caller then reuses the slot).
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
    stage_contact(stage, index, gap, ring_point, outward)
    on_bore = axpy(gap, outward, ring_point)
    if check_axial and abs(dot(sub(on_bore, bore_position), axis)) > bore_half_length:
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
    axis_b = column_of(bore_rotation, 2)
    axis_j = column_of(journal_rotation, 2)
    direction = 1.0 if dot(axis_j, axis_b) >= 0.0 else -1.0
    centre = dot(sub(journal_position, bore_position), axis_b)
    reach = journal_half_length * abs(dot(axis_j, axis_b))
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
def bore_slots(kind_a, params_a, position_a, rotation_a, params_b, position_b, rotation_b,
               stage):
    """A circle, arc or journal (A) inside a bore (B): (slots, kept_0, kept_1), every slot
    staged (:func:`_ring_in_bore`, :func:`_cylinder_in_bore`); slots -1 for any other A. A
    slot whose gap is below -depth (``params_b[4]`` > 0) is not kept: A is behind the bore's
    solid, not in it."""
    bore_span = params_b[3] - params_b[2]
    if kind_a == CIRCLE:
        kept = _ring_in_bore(position_a, rotation_a, params_a[0], 0.0, TWO_PI, False,
                             position_b, rotation_b, params_b[0], params_b[1], params_b[2],
                             bore_span, True, 0, stage)
        return 1, kept == 1 and within_depth(params_b[4], stage, 0), False
    if kind_a == ARC:
        kept = _ring_in_bore(position_a, rotation_a, params_a[0], params_a[1],
                             params_a[2] - params_a[1], True, position_b, rotation_b,
                             params_b[0], params_b[1], params_b[2], bore_span, True, 0, stage)
        return 1, kept == 1 and within_depth(params_b[4], stage, 0), False
    if kind_a == CYLINDER:
        slots, kept_0, kept_1 = _cylinder_in_bore(
            position_a, rotation_a, params_a[0], params_a[1], position_b, rotation_b,
            params_b[0], params_b[1], params_b[2], bore_span, stage)
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
