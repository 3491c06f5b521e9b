"""A ring or arc that crosses a bounded face's edge is seen by the gap kernel.

The blind spot this guards against: the kernel once took one candidate for a ring against a
bounded face, the ring's lowest point, and dropped it when that point lay beyond the face's
bound, so a ring passing through the face's solid beside its edge was not seen at all. These
tests use only :func:`clearbench.scenarios.geometry.contacts_between` and the scene shapes, so
they also run against the old kernel, where they fail (docs/contact-geometry.md gives the
command).

The configuration, computed by hand. The face is a rectangle |x| <= 1, |y| <= 1 with its
solid 0.5 deep below z = 0 (the slab -0.5 <= z <= 0). The ring is a circle of radius 0.5 in
the xz-plane, centred at (1.3, 0, 0.35): its point at angle t is (1.3 + 0.5 cos t, 0,
0.35 + 0.5 sin t). Its lowest point (1.3, 0, -0.15) lies beyond the edge x = 1, but the ring
crosses the edge plane x = 1 at z = 0.35 - 0.5 * 0.8 = -0.05, inside the slab. A ring point
(x, z) in the slab near that edge is at depth min(-z, 1 - x) from the slab's surface; along the
ring this is largest where -z = 1 - x, i.e. sin t - cos t = -0.1, which with cos^2 + sin^2 = 1
gives cos t = (0.2 - sqrt(7.96)) / 4, sin t = cos t - 0.1, and the depth -0.35 - 0.5 sin t =
0.02767 (the ring's signed distance to the solid is -0.02767).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from clearbench.scenarios.geometry import contacts_between
from clearbench.scenarios.shapes import Arc, Circle, Rectangle

#: cos t and sin t of the deepest ring point (module docstring).
_COS = (0.2 - math.sqrt(7.96)) / 4.0
_SIN = _COS - 0.1
#: The ring's signed distance to the face's solid [L]: minus the depth of its deepest point.
TRUE_GAP = 0.35 + 0.5 * _SIN
#: How close the kernel's gap must come to TRUE_GAP [L]: 1e-6 of the shapes' size (1). The
#: kernel finds the deepest point by a minimisation over the ring angle, converged far below
#: this; the bound only needs to tell "seen" from "not seen" (0.0277).
TOLERANCE = 1e-6

FACE = Rectangle("face", half_extents=(1.0, 1.0), depth=0.5)
#: The ring's plane is the xz-plane: a quarter turn about x takes the ring's z axis to -y, its
#: y axis to +z, so its point at angle t is centre + 0.5 (cos t x + sin t z).
QUARTER_TURN_ABOUT_X = (math.cos(math.pi / 4), math.sin(math.pi / 4), 0.0, 0.0)
CENTRE = (1.3, 0.0, 0.35)
RINGS = {
    "circle": Circle("ring", position=CENTRE, orientation=QUARTER_TURN_ABOUT_X, radius=0.5),
    # The lower half of that circle (angles pi..2 pi): it holds the deepest point.
    "arc": Arc("ring", position=CENTRE, orientation=QUARTER_TURN_ABOUT_X, radius=0.5,
               start_angle=math.pi, end_angle=2.0 * math.pi),
}
AT_ORIGIN = (np.zeros(3), np.array([1.0, 0.0, 0.0, 0.0]))


def test_the_hand_computed_depth_is_a_ring_point_in_the_slab():
    # The point of the ring at (cos t, sin t) = (_COS, _SIN) lies in the slab at the depth
    # claimed, equally far below the top face and inside the edge plane x = 1.
    x, z = 1.3 + 0.5 * _COS, 0.35 + 0.5 * _SIN
    assert _COS ** 2 + _SIN ** 2 == pytest.approx(1.0, abs=1e-12)
    assert 0.0 < 1.0 - x == pytest.approx(-z, abs=1e-12)
    assert -0.5 < z < 0.0
    assert TRUE_GAP == pytest.approx(-0.0276684, abs=1e-7)


@pytest.mark.parametrize("kind", sorted(RINGS))
@pytest.mark.parametrize("face_first", [True, False], ids=["face-ring", "ring-face"])
def test_a_ring_through_the_solid_beside_the_faces_edge_is_seen(kind, face_first):
    ring = RINGS[kind]
    if face_first:
        contacts = contacts_between(FACE, AT_ORIGIN, ring, AT_ORIGIN)
    else:
        contacts = contacts_between(ring, AT_ORIGIN, FACE, AT_ORIGIN)
    assert contacts.count > 0, f"{kind} crossing the face's edge: no contact reported"
    deepest = float(np.min(contacts.gap))
    assert deepest == pytest.approx(TRUE_GAP, abs=TOLERANCE), (
        f"{kind}: smallest gap {deepest:.6g}, true signed distance {TRUE_GAP:.6g}")


@pytest.mark.parametrize("kind", sorted(RINGS))
def test_the_gap_is_continuous_while_the_ring_crosses_the_faces_edge(kind):
    # The ring slides along x from well over the face (lowest point inside the bound) to
    # beyond the edge, its lowest point 0.15 below the top face plane. The ring's signed
    # distance to the solid is 1-Lipschitz in a translation, so between neighbouring positions
    # the smallest gap changes by at most |dx| (plus 1e-9 of the shapes' size for the angle
    # minimisation's convergence), and it never jumps to "no contact" while the ring is in the
    # solid.
    ring = RINGS[kind]
    steps = np.linspace(0.5, 1.6, 221)
    smallest = []
    for x in steps:
        pose = (np.array([x - CENTRE[0], 0.0, 0.0]), np.array([1.0, 0.0, 0.0, 0.0]))
        contacts = contacts_between(FACE, AT_ORIGIN, ring, pose)
        smallest.append(float(np.min(contacts.gap)) if contacts.count else math.inf)
    smallest = np.array(smallest)
    # The ring's centre is at x = ``steps`` (the pose offsets the shape's 1.3). Its lower arc
    # crosses the edge plane x = 1 at z = 0.35 - 0.5 sqrt(1 - (2 (1 - x))^2), below the top
    # face while x < 1 + 0.5 sqrt(0.51) = 1.357: up to x = 1.3 the ring is certainly in the
    # solid.
    inside = steps <= 1.3
    assert np.all(np.isfinite(smallest[inside])), "the ring in the solid lost its contact"
    jumps = np.abs(np.diff(smallest[inside]))
    assert np.max(jumps) <= (steps[1] - steps[0]) + 1e-9
