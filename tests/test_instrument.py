"""The independent geometry instrument against closed forms computed by hand.

Every expected value below is written from the geometry (a distance, a depth), not from any
code of the project; each pair reading is also checked for its guarantee: the true value lies
in [gap - resolution, gap] and the resolution is at most the tolerance asked for.
"""

from __future__ import annotations

import math
import zlib

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from clearbench.harness.measure.instrument import independent_gap
from clearbench.harness.measure.instrument.pair import RESOLUTION_FRACTION, pair_resolution
from clearbench.harness.measure.instrument.solids import Solid
from clearbench.scenarios.shapes import (
    Arc,
    Bore,
    Box,
    Capsule,
    Circle,
    Cylinder,
    Disc,
    Plane,
    Rectangle,
    Sphere,
)
from tests.test_import_layering import import_graph

IDENTITY = (1.0, 0.0, 0.0, 0.0)
#: A quarter turn about x: the shape's xy-plane becomes the world's xz-plane (a ring standing
#: up, its axis along -y).
STAND_UP = (math.cos(math.pi / 4), math.sin(math.pi / 4), 0.0, 0.0)
#: Round-off allowance of a closed form [L]: values of order 1 computed in float64.
ROUND_OFF = 1e-12


def sdf(shape, point) -> float:
    return float(Solid(shape).distance(np.array([point], dtype=float))[0][0])


# -- the solids' signed distances ------------------------------------------------------------

@pytest.mark.parametrize(("shape", "point", "expected"), [
    (Sphere("s", radius=0.5), (0.0, 0.0, 2.0), 1.5),
    (Sphere("s", radius=0.5), (0.1, 0.0, 0.0), -0.4),
    # box: beyond a corner the distance to the corner; inside, to the nearest face
    (Box("b", half_extents=(1.0, 2.0, 3.0)), (2.0, 4.0, 5.0), 3.0),
    (Box("b", half_extents=(1.0, 2.0, 3.0)), (0.5, 0.0, 0.0), -0.5),
    (Box("b", half_extents=(1.0, 2.0, 3.0)), (0.0, 1.8, 0.0), -0.2),
    # capsule: distance to its axis segment minus the radius
    (Capsule("c", radius=0.2, half_length=1.0), (0.0, 0.0, 1.7), 0.5),
    (Capsule("c", radius=0.2, half_length=1.0), (0.5, 0.0, 0.3), 0.3),
    # finite solid cylinder: beyond its rim the distance to the rim circle
    (Cylinder("c", radius=1.0, half_length=0.5), (4.0, 0.0, 4.5), 5.0),
    (Cylinder("c", radius=1.0, half_length=0.5), (0.0, 0.9, 0.0), -0.1),
    (Cylinder("c", radius=1.0, half_length=0.5), (0.0, 0.0, 0.45), -0.05),
    (Plane("p"), (3.0, -2.0, -0.25), -0.25),
    # rectangle slab: above the face, beside it, below its depth, inside near a side
    (Rectangle("r", half_extents=(1.0, 2.0), depth=0.5), (0.3, 0.3, 0.2), 0.2),
    (Rectangle("r", half_extents=(1.0, 2.0), depth=0.5), (4.0, 0.0, 4.0), 5.0),
    (Rectangle("r", half_extents=(1.0, 2.0), depth=0.5), (0.0, 0.0, -0.75), 0.25),
    (Rectangle("r", half_extents=(1.0, 2.0), depth=0.5), (0.95, 0.0, -0.2), -0.05),
    (Rectangle("r", half_extents=(1.0, 2.0)), (0.0, 0.0, -7.0), -1.0),
    (Rectangle("r", half_extents=(1.0, 2.0)), (1.3, 0.0, -7.0), 0.3),
    # disc: beside its rim, below it
    (Disc("d", radius=1.0, depth=0.2), (2.0, 0.0, -0.1), 1.0),
    (Disc("d", radius=1.0, depth=0.2), (0.0, 0.0, -0.05), -0.05),
    (Disc("d", radius=1.0), (0.0, 0.5, -3.0), -0.5),
    # bore: in the hole, in the material, past its end, outside its angles
    (Bore("b", radius=1.0, half_length=0.5), (0.7, 0.0, 0.0), 0.3),
    (Bore("b", radius=1.0, half_length=0.5, depth=0.4), (1.1, 0.0, 0.0), -0.1),
    (Bore("b", radius=1.0, half_length=0.5, depth=0.4), (0.0, 1.3, 0.45), -0.05),
    (Bore("b", radius=1.0, half_length=0.5), (0.0, 1.0, 0.8), 0.3),
    (Bore("b", radius=1.0, half_length=0.5), (0.0, 0.0, 0.0), 1.0),
    (Bore("b", radius=1.0, half_length=0.5, start_angle=0.0, end_angle=math.pi / 2),
     (1.2, -0.3, 0.0), 0.3),
    # circle and arc: distance to the curve (unsigned), beyond an arc's end to that end
    (Circle("c", radius=1.0), (2.0, 0.0, 1.0), math.sqrt(2.0)),
    (Circle("c", radius=1.0), (0.0, 0.0, 0.0), 1.0),
    (Arc("a", radius=1.0, start_angle=0.0, end_angle=math.pi / 2), (-1.0, 0.0, 0.0),
     math.sqrt(2.0)),
    (Arc("a", radius=1.0, start_angle=0.0, end_angle=math.pi / 2), (0.0, 2.0, 0.0), 1.0),
])
def test_solid_signed_distance(shape, point, expected):
    assert sdf(shape, point) == pytest.approx(expected, abs=ROUND_OFF)


def test_quarter_bore_outside_its_angles():
    """A quarter bore (angles 0 .. pi/2, material rho >= 1, no depth): from (-1.5, 0, 0) the
    nearest material is the corner (0, 1) where the inner arc meets the cut ray at pi/2
    (sqrt(1.5^2 + 1)); from (-1.5, 2, 0), the ray {(0, t), t >= 1} at (0, 2); from
    (1.5, -0.5, 0), the ray {(t, 0), t >= 1} at (1.5, 0)."""
    bore = Bore("b", radius=1.0, half_length=0.5, start_angle=0.0, end_angle=math.pi / 2)
    assert sdf(bore, (-1.5, 0.0, 0.0)) == pytest.approx(math.sqrt(3.25), abs=ROUND_OFF)
    assert sdf(bore, (-1.5, 2.0, 0.0)) == pytest.approx(1.5, abs=ROUND_OFF)
    assert sdf(bore, (1.5, -0.5, 0.0)) == pytest.approx(0.5, abs=ROUND_OFF)


def test_tube_around_a_ring():
    """A circle with a tube radius is a torus: the signed distance is the distance to the
    circle less the tube radius (the field K1 may add is read with getattr)."""
    ring = Circle("c", radius=1.0)
    object.__setattr__(ring, "tube_radius", 0.1)
    assert sdf(ring, (1.0, 0.0, 0.5)) == pytest.approx(0.4, abs=ROUND_OFF)
    assert sdf(ring, (1.05, 0.0, 0.0)) == pytest.approx(-0.05, abs=ROUND_OFF)


# -- pair readings -----------------------------------------------------------------------------

def _check(reading, expected: float, tolerance: float) -> None:
    """The guarantee: expected in [gap - resolution, gap], resolution <= tolerance, and the
    gap is the distance between its two witnesses' surfaces where separated."""
    assert reading.resolution <= tolerance * (1 + 1e-9)
    assert reading.gap - reading.resolution - ROUND_OFF <= expected <= reading.gap + ROUND_OFF
    assert np.all(np.isfinite(reading.point_a)) and np.all(np.isfinite(reading.point_b))
    if reading.gap > 0:
        assert np.linalg.norm(reading.point_b - reading.point_a) == pytest.approx(
            reading.gap, abs=ROUND_OFF + tolerance)


def _both_orders(shape_a, pose_a, shape_b, pose_b, expected: float) -> None:
    tolerance = pair_resolution(shape_a, shape_b)
    _check(independent_gap(shape_a, pose_a, shape_b, pose_b), expected, tolerance)
    _check(independent_gap(shape_b, pose_b, shape_a, pose_a), expected, tolerance)


@pytest.mark.parametrize(("centre", "expected"), [(2.0, 0.5), (1.3, -0.2)])
def test_sphere_sphere(centre, expected):
    """Centre distance less the radii (separated; overlapping by less than a radius)."""
    _both_orders(Sphere("a", radius=1.0), ((0, 0, 0), IDENTITY),
                 Sphere("b", radius=0.5), ((centre, 0.3 * centre, 0.0), IDENTITY),
                 math.hypot(centre, 0.3 * centre) - 1.5)
    assert expected  # the parametrisation documents the regime


@pytest.mark.parametrize("height", [0.8, 0.3])
def test_sphere_plane(height):
    """Height of the centre less the radius (the plane rotated and moved: a tilted floor)."""
    tilt = Rotation.from_euler("x", 0.3)
    normal = tilt.apply((0.0, 0.0, 1.0))
    floor_at = np.array([0.2, -0.1, 0.4])
    centre = floor_at + height * normal + np.array([1.0, 0.0, 0.0]) - (
        np.array([1.0, 0.0, 0.0]) @ normal) * normal
    pose_floor = (floor_at, tuple(tilt.as_quat(scalar_first=True)))
    _both_orders(Plane("floor"), pose_floor, Sphere("ball", radius=0.5), (centre, IDENTITY),
                 height - 0.5)


def test_box_corner_on_a_plane():
    """A cube of half side 0.5 with a body diagonal vertical: its lowest corner is 0.5 sqrt(3)
    below its centre."""
    turn, _ = Rotation.align_vectors([[0.0, 0.0, -1.0]], [[1.0, 1.0, 1.0]])
    quaternion = tuple(turn.as_quat(scalar_first=True))
    for height in (1.0, 0.8):
        _both_orders(Plane("floor"), ((0, 0, 0), IDENTITY), Box("cube", half_extents=(0.5,) * 3),
                     ((0.3, 0.1, height), quaternion), height - 0.5 * math.sqrt(3.0))


def test_box_lying_flat_on_a_plane_is_exact_and_cheap():
    """A box face on the floor: every point of its bottom face is the witness; the convex
    bound resolves it at once (resolution 0 to round-off)."""
    reading = independent_gap(Plane("floor"), ((0, 0, 0), IDENTITY),
                              Box("b", half_extents=(0.5, 0.2, 0.1)), ((0, 0, 0.099), IDENTITY))
    assert reading.gap == pytest.approx(-0.001, abs=ROUND_OFF)
    assert reading.resolution <= ROUND_OFF


def test_ring_over_a_face_edge():
    """A ring of radius 0.5 standing in the xz-plane, centre (1.2, 0, 0.3), over the edge
    x = 1 of a face (half extents 1 x 1, depth 0.5). Its lowest point (1.2, 0, -0.2) is past
    the edge, yet the ring enters the slab: the point at angle t (cos t = -0.6, sin t = -0.8),
    (0.9, 0, -0.1), is 0.1 from the side face and 0.1 below the top, the deepest (moving along
    the ring brings it nearer one of the two)."""
    face = Rectangle("face", half_extents=(1.0, 1.0), depth=0.5)
    _both_orders(face, ((0, 0, 0), IDENTITY), Circle("ring", radius=0.5),
                 ((1.2, 0.0, 0.3), STAND_UP), -0.1)
    witness = independent_gap(Circle("ring", radius=0.5), ((1.2, 0.0, 0.3), STAND_UP),
                              face, ((0, 0, 0), IDENTITY))
    np.testing.assert_allclose(witness.point_a, (0.9, 0.0, -0.1), atol=1e-3)


def test_arc_crossing_a_face_bound():
    """An arc (the lower half of a circle of radius 0.5 standing in the xz-plane) centred at
    (1.05, 0, 0.45): its lowest point (1.05, 0, -0.05) is 0.05 past the face's edge x = 1. The
    deepest point inside the slab balances the depth below the top, -0.45 - 0.5 sin t, and the
    distance to the side, -0.05 - 0.5 cos t: sin t - cos t = -0.8, so cos t = (0.8 -
    sqrt(1.36)) / 2 and the depth is sqrt(1.36) / 4 - 0.25 (0.0415 below the plane)."""
    face = Rectangle("face", half_extents=(1.0, 1.0), depth=0.5)
    arc = Arc("arc", radius=0.5, start_angle=math.pi, end_angle=2 * math.pi)
    _both_orders(face, ((0, 0, 0), IDENTITY), arc, ((1.05, 0.0, 0.45), STAND_UP),
                 0.25 - math.sqrt(1.36) / 4)
    # The same arc with its lowest point over the face: it dips 0.05 below the plane there,
    # 0.15 from the side.
    _both_orders(face, ((0, 0, 0), IDENTITY), arc, ((0.85, 0.0, 0.45), STAND_UP), -0.05)


@pytest.mark.parametrize("eccentricity", [0.0, 0.03, 0.1, 0.12])
def test_journal_in_a_bore(eccentricity):
    """A journal (radius 0.9) in a bore (radius 1) at eccentricity e, parallel axes: the radial
    clearance less e (negative: the journal is in the bore's wall)."""
    direction = np.array([math.cos(0.7), math.sin(0.7), 0.0])
    bore = Bore("bore", radius=1.0, half_length=0.5)
    journal = Cylinder("journal", radius=0.9, half_length=0.4)
    _both_orders(bore, ((0, 0, 0), IDENTITY), journal, (eccentricity * direction, IDENTITY),
                 0.1 - eccentricity)


@pytest.mark.parametrize("eccentricity", [0.02, 0.08, 0.15])
def test_bearing_ring_around_a_journal(eccentricity):
    """A bearing ring (radius 1) around a journal (radius 0.9) at eccentricity e: the ring's
    point nearest the journal's axis is 1 - e from it; the gap is 0.1 - e, and a ring inside
    the journal's wall reads the depth of its deepest point, e - 0.1."""
    ring = Circle("ring", radius=1.0)
    journal = Cylinder("journal", radius=0.9, half_length=0.4)
    _both_orders(ring, ((0, 0, 0.1), IDENTITY), journal, ((0.0, -eccentricity, 0.0), IDENTITY),
                 0.1 - eccentricity)


def test_ring_in_a_bore():
    """A ring (radius 0.95) inside a bore (radius 1) at eccentricity 0.08: its farthest point
    from the bore's axis is 1.03 from it, 0.03 inside the wall."""
    _both_orders(Bore("bore", radius=1.0, half_length=0.5), ((0, 0, 0), IDENTITY),
                 Circle("ring", radius=0.95), ((0.08, 0.0, 0.2), IDENTITY), -0.03)


def test_capsule_and_cylinder_against_a_disc():
    """A lying capsule (radius 0.1, half length 0.5, axis along x) 0.05 into a round face, and
    a standing cylinder 0.02 above it."""
    disc = Disc("disc", radius=2.0, depth=1.0)
    lying = tuple(Rotation.from_euler("y", math.pi / 2).as_quat(scalar_first=True))
    _both_orders(disc, ((0, 0, 0), IDENTITY), Capsule("cap", radius=0.1, half_length=0.5),
                 ((0.3, 0.0, 0.05), lying), -0.05)
    _both_orders(disc, ((0, 0, 0), IDENTITY), Cylinder("cyl", radius=0.3, half_length=0.2),
                 ((0.3, 0.2, 0.22), IDENTITY), 0.02)


def test_resolution_follows_the_request():
    """A finer requested tolerance gives a finer certified resolution."""
    shapes = (Sphere("a", radius=1.0), ((0, 0, 0), IDENTITY), Sphere("b", radius=1.0),
              ((1.5, 0.4, 0.2), IDENTITY))
    coarse = independent_gap(*shapes, resolution=1e-2)
    fine = independent_gap(*shapes, resolution=1e-6)
    expected = math.sqrt(1.5**2 + 0.4**2 + 0.2**2) - 2.0
    _check(coarse, expected, 1e-2)
    _check(fine, expected, 1e-6)
    assert pair_resolution(shapes[0], shapes[2]) == RESOLUTION_FRACTION * 1.0


def test_two_unbounded_shapes_are_refused():
    with pytest.raises(ValueError, match="plane-rectangle"):
        independent_gap(Plane("p"), ((0, 0, 0), IDENTITY), Rectangle("r"), ((0, 0, 1), IDENTITY))


# -- independence ------------------------------------------------------------------------------

FORBIDDEN = ("clearbench.kernels.gaps", "clearbench.kernels.frames",
             "clearbench.kernels.quaternion", "clearbench.scenarios.geometry")


def test_instrument_shares_no_code_with_the_kernel():
    """Every module of the instrument, and everything it imports in turn, stays clear of the
    gap kernel, its frames, its quaternions and the pair functions of scenarios.geometry."""
    graph = import_graph()
    package = "clearbench.harness.measure.instrument"
    roots = [m for m in graph if m == package or m.startswith(package + ".")]
    assert len(roots) >= 5
    seen, stack, paths = set(roots), list(roots), {m: m for m in roots}
    while stack:
        module = stack.pop()
        for target, _line, _nested in graph.get(module, ()):
            if target not in seen:
                seen.add(target)
                paths[target] = f"{paths[module]} -> {target}"
                stack.append(target)
    reached = [paths[m] for m in FORBIDDEN if m in seen]
    assert not reached, reached


def _with_tube(shape, tube: float):
    """``shape`` with a ``tube_radius`` (the field K1 may add; read with getattr)."""
    object.__setattr__(shape, "tube_radius", tube)
    return shape


def test_tube_ring_lying_on_a_plane():
    """A torus (ring radius 0.5, tube 0.05) lying flat, its centre 0.04 above the floor: every
    point of its lowest circle is 0.01 below the floor (a flat, conformal contact)."""
    ring = _with_tube(Circle("ring", radius=0.5), 0.05)
    _both_orders(Plane("floor"), ((0, 0, 0), IDENTITY), ring, ((0.2, -0.1, 0.04), IDENTITY),
                 -0.01)


def test_tube_arc_end_cap_on_a_face():
    """An arc with a tube (radius 0.5, tube 0.05, angles 0 .. pi/2) lying flat 0.03 above a
    face: its tube's lowest points are 0.05 below its centre line, 0.02 into the face. Tilted
    by 0.3 rad about y, the arc's end at angle 0 (0.5, 0, 0) is its lowest point, and its end
    cap reaches the tube radius below it."""
    arc = _with_tube(Arc("arc", radius=0.5, start_angle=0.0, end_angle=math.pi / 2), 0.05)
    face = Rectangle("face", half_extents=(1.0, 1.0), depth=0.3)
    _both_orders(face, ((0, 0, 0), IDENTITY), arc, ((0.1, 0.1, 0.03), IDENTITY), -0.02)
    tilt = tuple(Rotation.from_euler("y", 0.3).as_quat(scalar_first=True))
    end_height = 0.2 - 0.5 * math.sin(0.3)
    _both_orders(face, ((0, 0, 0), IDENTITY), arc, ((0.1, 0.1, 0.2), tilt), end_height - 0.05)


# -- the search's bound is sound -------------------------------------------------------------

#: One shape of every kind, sizes of order 0.3 (a bore with a depth, faces with one).
KINDS = {
    "sphere": Sphere("s", radius=0.3), "box": Box("b", half_extents=(0.3, 0.2, 0.25)),
    "capsule": Capsule("c", radius=0.15, half_length=0.3),
    "cylinder": Cylinder("y", radius=0.25, half_length=0.3), "plane": Plane("p"),
    "circle": Circle("o", radius=0.3), "arc": Arc("a", radius=0.3, start_angle=0.3, end_angle=2.5),
    "rectangle": Rectangle("r", half_extents=(0.5, 0.4), depth=0.3),
    "disc": Disc("d", radius=0.5, depth=0.3),
    "bore": Bore("B", radius=0.35, half_length=0.3, depth=0.2, start_angle=0.0, end_angle=4.0),
}
#: The kernel's pair kinds (the table of scenarios/geometry.py), as (A, B).
PAIR_KINDS = [("plane", k) for k in ("sphere", "box", "capsule", "cylinder", "circle", "arc")] + [
    ("sphere", "sphere"), ("box", "sphere"), ("capsule", "sphere"), ("cylinder", "sphere"),
    ("box", "box"), ("capsule", "capsule"), ("circle", "cylinder"), ("arc", "cylinder")] + [
    (face, k) for face in ("rectangle", "disc") for k in ("sphere", "cylinder", "circle", "arc")
] + [("circle", "bore"), ("arc", "bore"), ("cylinder", "bore")]


@pytest.mark.parametrize(("kind_a", "kind_b"), PAIR_KINDS)
def test_certified_bound_holds_against_dense_sampling(kind_a, kind_b):
    """The search's lower bound (gap - resolution) is never above the partner's signed
    distance at any point of a dense grid of the sampled boundaries (10,000 points per patch),
    at two random configurations of each pair kind with overlaps up to about a third of the
    shapes' size: the bounds the search prunes with are sound. (The grid uses the same signed
    distances: this checks the search, the closed-form tests check the distances.)"""
    from clearbench.harness.measure.instrument.pair import _clip_box, _terms
    from clearbench.harness.measure.instrument.placement import (
        relative_transforms,
        shape_placements,
    )
    from clearbench.harness.measure.instrument.surfaces import boundary_patches

    rng = np.random.default_rng(zlib.crc32(f"{kind_a}-{kind_b}".encode()))
    shape_a, shape_b = KINDS[kind_a], KINDS[kind_b]
    fixed = kind_a in ("plane", "rectangle", "disc", "bore") or kind_b == "bore"
    for _ in range(2):
        quaternion_b = tuple(Rotation.random(random_state=rng.integers(2**31))
                             .as_quat(scalar_first=True))
        if kind_b in ("bore", "cylinder") and kind_a in ("circle", "arc", "cylinder"):
            # A journal or ring near its bore's axis, a small tilt.
            quaternion_b = tuple(Rotation.from_euler("xy", rng.normal(0.0, 0.05, 2))
                                 .as_quat(scalar_first=True))
            position_b = rng.normal(0.0, 0.04, 3)
        else:
            position_b = rng.normal(0.0, 0.2, 3) + (0.0, 0.0, 0.3)
        pose_a = ((0.0, 0.0, 0.0), IDENTITY if fixed else tuple(
            Rotation.random(random_state=rng.integers(2**31)).as_quat(scalar_first=True)))
        reading = independent_gap(shape_a, pose_a, shape_b, (position_b, quaternion_b))
        solids = (Solid(shape_a), Solid(shape_b))
        placed = [shape_placements(shape_a, [pose_a[0]], [pose_a[1]]),
                  shape_placements(shape_b, [position_b], [quaternion_b])]
        sampled = [k for k, wanted in enumerate(_terms(*solids)) if wanted]
        dense = np.inf
        for k in sampled:
            (position, rotation), (other_position, other_rotation) = placed[k], placed[1 - k]
            clip = _clip_box(solids[k], rotation, position, solids[1 - k], other_rotation,
                             other_position, np.arange(1))
            m, d = relative_transforms(rotation, position, other_rotation, other_position)
            for patch in boundary_patches(solids[k], clip):
                u0, u1, v0, v1 = patch.domain
                count = 10_000
                side = int(math.sqrt(count)) if not patch.is_curve else count
                uu, vv = np.meshgrid(np.linspace(u0, u1, side),
                                     np.linspace(v0, v1, 1 if patch.is_curve else side))
                points = patch.points(uu.ravel(), vv.ravel()) @ m[0].T + d[0]
                dense = min(dense, float(solids[1 - k].distance(points)[0].min()))
        # Round-off of values of order 1: 1e-12.
        assert reading.gap - reading.resolution <= dense + 1e-12
        assert reading.gap <= dense + 1e-12 or reading.gap - dense <= reading.resolution
