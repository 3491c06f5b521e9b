"""A bare ring on a face's edge: the gap kernel's contact is the ring against the edge line,
along their common normal (kernels/gaps/ring_edges.py), checked against the hoop's geometry
computed here by hand.

A hoop of radius R = 0.1 m stands in the xz-plane over the edge x = 0, z = 0 of a slab (x <= 0,
-0.02 <= z <= 0) or a disc's rim, its centre at angle ``phi`` from the vertical through the edge
at distance R (1 + s) from it. Its nearest point to the edge is on the line from the edge to its
centre, so the exact gap is R s and the exact normal the unit vector from the edge to the
centre, whatever s: on the edge to round-off (|s| = 1e-15), a hair inside (the step's drift)
or apart. Bounds: the normal within 1e-9 (the kernel finds the ring point by Newton on the ring
angle to round-off; a normal from the faces is 0.1-1 off), the gap within 1e-12 m (round-off
of 0.1 m lengths, 1e-15, times the few operations between).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from clearbench.scenarios.geometry import contacts_between
from clearbench.scenarios.shapes import Circle, Disc, Rectangle

R = 0.1  # [m]
#: The hoop's frame: +90 degrees about world x, its circle in the world xz-plane.
STANDING = np.array([math.sqrt(0.5), math.sqrt(0.5), 0.0, 0.0])
IDENTITY = np.array([1.0, 0.0, 0.0, 0.0])


def _faces():
    slab = Rectangle("top", half_extents=(0.5, 0.5), depth=0.02)
    disc = Disc("top", radius=0.5, depth=0.02)
    # Each face placed so that its edge (a disc's rim point) is at the world origin, the
    # material at x < 0.
    return {"slab": (slab, np.array([-0.5, 0.0, 0.0])),
            "disc": (disc, np.array([-0.5, 0.0, 0.0]))}


@pytest.mark.parametrize("face", ["slab", "disc"])
@pytest.mark.parametrize("phi", [0.05, 0.4, 0.75])
@pytest.mark.parametrize("s", [1e-3, 1e-9, 1e-15, 0.0, -1e-15, -1e-11])
def test_a_hoop_on_an_edge_meets_it_along_the_line_to_its_centre(face, phi, s):
    shape, position = _faces()[face]
    outward = np.array([math.sin(phi), 0.0, math.cos(phi)])
    centre = R * (1.0 + s) * outward
    contacts = contacts_between(shape, (position, IDENTITY), Circle("ring", radius=R),
                                (centre, STANDING))
    slot = int(np.argmin(contacts.gap))
    assert contacts.gap[slot] == pytest.approx(R * s, abs=1e-12)
    np.testing.assert_allclose(contacts.normal[slot], outward, atol=1e-9)
