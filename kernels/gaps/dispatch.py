"""The dispatch on shape codes: each pair computed in its canonical order
(:data:`.codes.PAIR_SLOTS`) and mirrored for the other, the staged contacts expanded into
gaps, points and frames; the entry points :func:`pair_contacts` and :func:`pair_contact_slots`."""

from __future__ import annotations

import numpy as np

from clearbench.kernels.frames import frame_tangent
from clearbench.kernels.gaps.bores import bore_slots, compact_bore_slots
from clearbench.kernels.gaps.boxes import box_box
from clearbench.kernels.gaps.codes import (
    ARC,
    BORE,
    BOX,
    CANONICAL_ORDER,
    CAPSULE,
    CIRCLE,
    CYLINDER,
    DISC,
    NUMBER_OF_KINDS,
    PARAMETER_COUNT,
    PLANE,
    RECTANGLE,
    SPHERE,
    TWO_PI,
)
from clearbench.kernels.gaps.faces import face_contacts
from clearbench.kernels.gaps.planes import plane_box, plane_capsule, plane_cylinder, plane_sphere
from clearbench.kernels.gaps.ring_cylinders import ring_cylinder_solid
from clearbench.kernels.gaps.segments import capsule_capsule
from clearbench.kernels.gaps.spheres import (
    box_sphere,
    capsule_sphere,
    cylinder_sphere,
    sphere_sphere,
)
from clearbench.kernels.gaps.vectors import axpy, cross, norm, scaled
from clearbench.kernels.jit import njit


@njit(cache=True, inline="always")
def _canonical_contacts(kind_a, params_a, position_a, rotation_a, kind_b, params_b, position_b,
                        rotation_b, stage, work_1, work_2):
    """Contacts of a pair listed in CANONICAL_PAIRS in this order; -1 for any other pair.
    Inputs are tuples (params 8, position 3, rotation 3 rows of 3)."""
    if kind_a == PLANE:
        if kind_b == SPHERE:
            return plane_sphere(position_a, rotation_a, position_b, params_b[0], stage)
        if kind_b == BOX:
            return plane_box(position_a, rotation_a, position_b, rotation_b, params_b, stage)
        if kind_b == CAPSULE:
            return plane_capsule(position_a, rotation_a, position_b, rotation_b, params_b[0],
                                 params_b[1], stage)
        if kind_b == CYLINDER:
            return plane_cylinder(position_a, rotation_a, position_b, rotation_b, params_b[0],
                                  params_b[1], stage)
        if kind_b == CIRCLE or kind_b == ARC:
            return face_contacts(kind_a, params_a, position_a, rotation_a, kind_b, params_b,
                                 position_b, rotation_b, stage)
        return -1
    if kind_a == RECTANGLE or kind_a == DISC:
        return face_contacts(kind_a, params_a, position_a, rotation_a, kind_b, params_b,
                             position_b, rotation_b, stage)
    if kind_b == SPHERE:
        if kind_a == SPHERE:
            return sphere_sphere(position_a, params_a[0], position_b, params_b[0], stage)
        if kind_a == BOX:
            return box_sphere(position_a, rotation_a, params_a, position_b, params_b[0], stage)
        if kind_a == CAPSULE:
            return capsule_sphere(position_a, rotation_a, params_a[0], params_a[1], position_b,
                                  params_b[0], stage)
        if kind_a == CYLINDER:
            return cylinder_sphere(position_a, rotation_a, params_a[0], params_a[1],
                                   position_b, params_b[0], stage)
        return -1
    if kind_a == BOX and kind_b == BOX:
        return box_box(position_a, rotation_a, params_a, position_b, rotation_b, params_b,
                       stage, work_1, work_2)
    if kind_a == CAPSULE and kind_b == CAPSULE:
        return capsule_capsule(position_a, rotation_a, params_a[0], params_a[1], position_b,
                               rotation_b, params_b[0], params_b[1], stage)
    if kind_b == BORE:
        slots, kept_0, kept_1 = bore_slots(kind_a, params_a, position_a, rotation_a, params_b,
                                           position_b, rotation_b, stage)
        return compact_bore_slots(slots, kept_0, kept_1, stage)
    if kind_b == CYLINDER:
        if kind_a == CIRCLE:
            return ring_cylinder_solid(position_a, rotation_a, params_a[0], 0.0, TWO_PI, False,
                                       position_b, rotation_b, params_b[0], params_b[1], stage)
        if kind_a == ARC:
            return ring_cylinder_solid(position_a, rotation_a, params_a[0], params_a[1],
                                       params_a[2] - params_a[1], True, position_b,
                                       rotation_b, params_b[0], params_b[1], stage)
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
    return not CANONICAL_ORDER[kind_a, kind_b]


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
        normal = scaled(normal, 1.0 / norm(normal))
        first = (out_frame[k, 1, 0], out_frame[k, 1, 1], out_frame[k, 1, 2])
        gap = out_frame[k, 2, 0]
        second = axpy(gap, normal, first)  # p_B = p_A + g n of the computed order
        if swap:
            normal = scaled(normal, -1.0)
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
        bitangent = cross(normal, tangent)
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


@njit(cache=True)
def _canonical_slots(kind_a, params_a, position_a, rotation_a, kind_b, params_b, position_b,
                     rotation_b, stage, work_1, work_2, out_kept):
    """:func:`_canonical_contacts` without compaction: every candidate of a bore stays in its
    slot and ``out_kept`` flags the ones the bore's bounds keep. Returns the number
    of slots (-1 for a pair not in CANONICAL_PAIRS)."""
    if kind_b == BORE:
        slots, kept_0, kept_1 = bore_slots(kind_a, params_a, position_a, rotation_a, params_b,
                                           position_b, rotation_b, stage)
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

    A journal's bore drops its candidates when they do not overlap axially or the journal is
    deeper than the bore's depth;
    :func:`pair_contacts` compacts the kept ones to the front. Here slot k is always the same
    candidate of the kernel (an engine with one interaction per candidate follows it from step
    to step) and ``out_kept[k]`` says whether the bounds keep it; the kept slots, in order, are
    :func:`pair_contacts`'s output.
    A dropped slot holds the kernel's candidate before the bound applied; a journal with no
    axial overlap with its bore fills its slot 1, dropped, with its centre, a gap 0 and a
    normal across the bore axis (slot 0: its end rim nearer the bore, kept). Pairs that drop
    nothing fill every slot with a kept candidate.

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
