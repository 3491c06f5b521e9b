"""Shape codes, the packed-parameter length, and the table of pairs: which ordered pairs the
kernels compute, and how many candidate slots each returns.

:data:`PAIR_SLOTS` is the one declaration of the pairs. :data:`CANONICAL_PAIRS` and
:data:`SUPPORTED` are derived from it here, the Siconos worker's table of interactions
(``adapters/siconos/worker/geometry.py``) there, and a test checks every kernel's slot count
against it.
"""

from __future__ import annotations

import math

import numpy as np

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
#: Upper bound of the contacts one pair can return (box corners, box clipping, cylinder rims,
#: a ring's support points and minima against a face).
MAX_CONTACTS_PER_PAIR = 8

#: Pairs implemented with the first kind on body A (the reversed order is handled by swapping),
#: and the number of candidate slots of each in ``pair_contact_slots`` (one interaction per slot
#: for an engine that follows candidates from step to step); None where the number of
#: candidates changes with the configuration (box clipping, parallel capsule axes). A ring
#: against a face (plane, rectangle, disc) has 8: its 6 support points and 2 deepest points
#: (:data:`.ring_faces.RING_FACE_SLOTS`).
PAIR_SLOTS = {
    (PLANE, SPHERE): 1,
    (PLANE, BOX): 8,
    (PLANE, CAPSULE): 2,
    (PLANE, CYLINDER): 8,
    (PLANE, CIRCLE): 8,
    (PLANE, ARC): 8,
    (SPHERE, SPHERE): 1,
    (BOX, SPHERE): 1,
    (CAPSULE, SPHERE): 1,
    (CYLINDER, SPHERE): 1,
    (BOX, BOX): None,
    (CAPSULE, CAPSULE): None,
    (CIRCLE, CYLINDER): 1,
    (ARC, CYLINDER): 1,
    (RECTANGLE, SPHERE): 1,
    (RECTANGLE, CYLINDER): 8,
    (RECTANGLE, CIRCLE): 8,
    (RECTANGLE, ARC): 8,
    (DISC, SPHERE): 1,
    (DISC, CYLINDER): 8,
    (DISC, CIRCLE): 8,
    (DISC, ARC): 8,
    (CIRCLE, BORE): 1,
    (ARC, BORE): 1,
    (CYLINDER, BORE): 2,
}
#: Canonical pairs that can leave a slot empty (``pair_contact_slots``'s kept False): a journal
#: with no axial overlap with its bore, or behind the bore's depth. Every other pair fills
#: every slot with a candidate (a face's or a bore's solid has a gap everywhere).
DROPPING_PAIRS = ((CYLINDER, BORE),)
#: The canonical pairs, in the order of :data:`PAIR_SLOTS`.
CANONICAL_PAIRS = tuple(PAIR_SLOTS)

#: CANONICAL_ORDER[kind_a, kind_b] is True for a pair computed in that order.
CANONICAL_ORDER = np.zeros((NUMBER_OF_KINDS, NUMBER_OF_KINDS), dtype=np.bool_)
for _a, _b in CANONICAL_PAIRS:
    CANONICAL_ORDER[_a, _b] = True
#: SUPPORTED[kind_a, kind_b] is True when pair_contacts handles that ordered pair.
SUPPORTED = CANONICAL_ORDER | CANONICAL_ORDER.T
SUPPORTED.setflags(write=False)
CANONICAL_ORDER.setflags(write=False)

TWO_PI = 2.0 * math.pi
