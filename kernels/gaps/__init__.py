"""Contact kernels: signed gaps, contact points and frames for pairs of shapes.

The conventions (normal from A toward B, signed gap, contact frame, what each pair returns) are
documented in :mod:`clearbench.scenarios.geometry`, which is the public entry point; this package
holds the compiled kernels, one module per pair family, and the shape codes they dispatch on.
Only :func:`pair_contacts` and :func:`pair_contact_slots` (every candidate in a fixed slot, for
an engine with one interaction per candidate: the Siconos worker) are meant to be called from
outside, with the codes and tables of :mod:`.codes`.

============  =================================================================================
module        what it holds
============  =================================================================================
codes         shape codes, parameter count, the pair table :data:`PAIR_SLOTS` (slots per pair)
vectors       3-tuple arithmetic the kernels are written in
staging       how a kernel stages a contact for :mod:`.dispatch` to expand
planes        plane against sphere, box, capsule, cylinder
spheres       sphere against sphere, box, capsule, cylinder
segments      closest points of segments; capsule against capsule
boxes         box against box
face_solids   the solid behind a face (plane, rectangle, disc) and the signed distance to it
faces         a face's solid against sphere, cylinder and ring
ring_faces    ring (circle, arc) against a face's solid: support points and deepest points
rings         ring (circle, arc) against a cylinder's lateral surface
bores         ring or journal inside a bore
dispatch      the dispatch on codes, canonical order and mirroring; the two entry points
enclosing     a ring that must enclose its journal (measurement side, plain Python)
============  =================================================================================

Implementation notes. :func:`pair_contacts` converts its inputs to tuples once, so the kernels
take tuples and scalars (no array arguments, hence no reference counting in the hot path). A
kernel stages each contact it finds in the ``out_frame`` slot of that contact (row 0: normal,
row 1: point on A, row [2, 0]: gap) and returns the count; :func:`pair_contacts` then expands
the staged contacts into gaps, both points (``p_B = p_A + g n``) and frames, and mirrors them
when the pair was computed in the other order. Every module takes ``njit`` from
:mod:`clearbench.kernels.jit`, so the kernels also run as plain Python without numba (the
Siconos worker under Debian's Python).
"""

from clearbench.kernels.gaps.codes import (
    ARC,
    BORE,
    BOX,
    CANONICAL_PAIRS,
    CAPSULE,
    CIRCLE,
    CYLINDER,
    DISC,
    DROPPING_PAIRS,
    MAX_CONTACTS_PER_PAIR,
    NUMBER_OF_KINDS,
    PAIR_SLOTS,
    PARAMETER_COUNT,
    PLANE,
    RECTANGLE,
    SHAPE_KIND_NAMES,
    SPHERE,
    SUPPORTED,
)
from clearbench.kernels.gaps.dispatch import pair_contact_slots, pair_contacts
from clearbench.kernels.gaps.enclosing import axis_crosses_inside_ring, enclosing_ring_gap

__all__ = [
    "ARC",
    "BORE",
    "BOX",
    "CANONICAL_PAIRS",
    "CAPSULE",
    "CIRCLE",
    "CYLINDER",
    "DISC",
    "DROPPING_PAIRS",
    "MAX_CONTACTS_PER_PAIR",
    "NUMBER_OF_KINDS",
    "PAIR_SLOTS",
    "PARAMETER_COUNT",
    "PLANE",
    "RECTANGLE",
    "SHAPE_KIND_NAMES",
    "SPHERE",
    "SUPPORTED",
    "axis_crosses_inside_ring",
    "enclosing_ring_gap",
    "pair_contact_slots",
    "pair_contacts",
]
