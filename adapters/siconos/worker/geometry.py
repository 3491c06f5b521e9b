"""Contact geometry of the Siconos worker: the project's gap kernels, one interaction per slot.

The gaps, contact points and contact frames are those of every other engine and the metrics:
:func:`clearbench.kernels.gaps.pair_contact_slots` (conventions in
:mod:`clearbench.scenarios.geometry`), imported through :mod:`project_kernels` (under Debian's
Python, without numba, the kernels run as plain Python). What is Siconos's own is kept here:
which pairs the worker supports, with a fixed number of candidate SLOTS each (one Siconos
interaction per slot, created once), and the gap it hands Siconos for a dropped slot.

Supported pairs (either order; K = number of slots, fixed for each pair):

=================  ===  =======================================================================
plane-sphere        1   centre height minus radius
plane-box           8   every corner
plane-capsule       2   the two end spheres
plane-cylinder      8   four rim points on each end rim (indices 0, 1: the two lowest)
plane-circle        8   6 support points and the 2 deepest points of the ring (kernels/gaps/
plane-arc           8   ring_faces.py)
sphere-sphere       1   centre distance minus radii
box-sphere          1   closest point of the solid box
capsule-sphere      1   closest point of the axis segment
cylinder-sphere     1   closest point of the solid cylinder
circle-cylinder     1   ring against the (infinitely long) lateral surface of a journal
arc-cylinder        1   the same, restricted to the arc
rectangle-X         as  plane-X for X = sphere (1), cylinder (8), circle (8), arc (8), each
disc-X              ..  candidate's gap its distance to the face's solid (the edge beyond the
                        face's bound): never dropped
circle-bore         1   ring point nearest the bore's solid (the farthest from its axis while
arc-bore            1   that is within its angles and length): never dropped
cylinder-bore       2   one per end of the axial overlap (slot 0 at the bore's -z side);
                        dropped when there is no overlap or behind the bore's depth
=================  ===  =======================================================================

Box-box and capsule-capsule are not supported: their candidates come from clipping or from a
parallel-axes test, with no fixed slot a Siconos interaction could follow.
"""

import numpy as np

if __package__:  # imported within clearbench (the adapter's capabilities, the tests)
    from clearbench.kernels import gaps
else:  # the worker script's sibling, under Debian's Python
    from project_kernels import gaps

#: Shape kinds (the ``kind`` strings of the scene description).
SPHERE, BOX, CAPSULE, CYLINDER, PLANE, CIRCLE, ARC, RECTANGLE, DISC, BORE = (
    gaps.SHAPE_KIND_NAMES)
#: Every shape kind the worker knows (packed parameters: see pair_contact_slots).
SHAPE_KINDS = gaps.SHAPE_KIND_NAMES

#: Canonical pairs (kind on A, kind on B) -> number of slots; reversed orders are mirrored.
#: Derived from the kernels' one declaration of the pairs and their slots
#: (:data:`clearbench.kernels.gaps.PAIR_SLOTS`); a pair whose number of candidates changes
#: with the configuration (slots None there) is not supported here (:data:`NOT_PORTED`).
CANONICAL_PAIRS = {
    (SHAPE_KINDS[kind_a], SHAPE_KINDS[kind_b]): slots
    for (kind_a, kind_b), slots in gaps.PAIR_SLOTS.items() if slots is not None
}
#: Gap [L] the worker hands Siconos for a dropped slot (a journal's candidate beyond its bore's
#: length, or deeper than its depth): far beyond any activation threshold
#: (y + h/2 y' <= ~1e-10 of the smallest feature), so the interaction stays inactive until the
#: candidate comes back; finite, so Siconos's norms of the outputs stay finite.
DROPPED_GAP = 1e12
#: Canonical pairs that can drop candidates (a journal in a bore): the kernels' DROPPING_PAIRS.
DROPPING_PAIRS = tuple((SHAPE_KINDS[kind_a], SHAPE_KINDS[kind_b])
                       for kind_a, kind_b in gaps.DROPPING_PAIRS)

#: Why the pairs of the shared geometry that the worker does not support are missing.
NOT_PORTED = {
    (BOX, BOX): "box-box contacts come from clipping: their number changes with the "
                "configuration, which a fixed set of Siconos interactions cannot follow",
    (CAPSULE, CAPSULE): "capsule-capsule gives one or two contacts depending on whether the "
                        "axes are parallel; a fixed set of Siconos interactions cannot follow",
}


def candidate_count(kind_a, kind_b):
    """Number of candidate slots of the pair (either order; one Siconos interaction each), or
    None if not supported here."""
    if (kind_a, kind_b) in CANONICAL_PAIRS:
        return CANONICAL_PAIRS[(kind_a, kind_b)]
    return CANONICAL_PAIRS.get((kind_b, kind_a))


def drops_candidates(kind_a, kind_b):
    """True if the pair (either order) can leave candidate slots empty."""
    return (kind_a, kind_b) in DROPPING_PAIRS or (kind_b, kind_a) in DROPPING_PAIRS


def unsupported_reason(kind_a, kind_b):
    """Why the pair is not supported here ('' when it is)."""
    if candidate_count(kind_a, kind_b) is not None:
        return ""
    key = (kind_a, kind_b) if (kind_a, kind_b) in NOT_PORTED else (kind_b, kind_a)
    return NOT_PORTED.get(key, f"no contact geometry for {kind_a}-{kind_b}")


def packed_shape(kind, params):
    """(shape code, packed parameters (8,)) of a shape kind and its parameters (the list
    ``scenarios.geometry.pack_shape_parameters`` writes, without its trailing zeros)."""
    packed = np.zeros(gaps.PARAMETER_COUNT)
    packed[:len(params)] = params
    return SHAPE_KINDS.index(kind), packed


def pair_contact_slots(shape_a, position_a, rotation_a, shape_b, position_b, rotation_b):
    """Every candidate slot of shape A against shape B, dropped or not
    (:func:`clearbench.kernels.gaps.pair_contact_slots`).

    Parameters
    ----------
    shape_a, shape_b : (int, ndarray (8,))
        Shape code and packed parameters (:func:`packed_shape`) [L, rad].
    position_a, position_b : ndarray (3,)
        World position of each shape frame [L].
    rotation_a, rotation_b : ndarray (3, 3)
        World rotation of each shape frame (columns: the shape's axes).

    Returns
    -------
    gap : ndarray (K,) [L], K = candidate_count of the pair
    point_a, point_b : ndarray (K, 3) world [L]
    frame : ndarray (K, 3, 3), rows (n, t1, t2), n from A toward B
    kept : ndarray (K,) bool, False for a dropped candidate
    """
    rows = gaps.MAX_CONTACTS_PER_PAIR
    gap, point_a, point_b = np.empty(rows), np.empty((rows, 3)), np.empty((rows, 3))
    frame, kept = np.empty((rows, 3, 3)), np.zeros(rows, dtype=np.bool_)
    slots = gaps.pair_contact_slots(
        shape_a[0], shape_a[1], np.ascontiguousarray(position_a, dtype=float),
        np.ascontiguousarray(rotation_a, dtype=float), shape_b[0], shape_b[1],
        np.ascontiguousarray(position_b, dtype=float),
        np.ascontiguousarray(rotation_b, dtype=float), gap, point_a, point_b, frame, kept)
    return gap[:slots], point_a[:slots], point_b[:slots], frame[:slots], kept[:slots]
