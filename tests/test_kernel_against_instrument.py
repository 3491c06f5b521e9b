"""Every pair type of the gap kernel against the independent instrument, on random configurations
drawn to include the hard places.

The kernel (:func:`clearbench.scenarios.geometry.contacts_between`) and the instrument
(:func:`clearbench.harness.measure.instrument.independent_gap`, which shares no code with it)
read the same solids (docs/contact-geometry.md). The instrument's reading is a witnessed signed
distance ``gap`` with a ``resolution``: the true value G (the signed distance of the deepest,
or closest, boundary point of one shape to the other's solid) lies in [gap - resolution, gap].
The kernel's figure is its smallest candidate gap (+inf without a candidate). What must hold,
give or take TOLERANCE (round-off, and the kernel's minimisation over a ring's angle):

- EXACT pairs (a plane against anything, a ring or arc against a cylinder or a bore): the
  kernel's candidates are boundary points with their exact signed distances and its smallest
  is G: it lies in [gap - resolution, gap].
- RING_FACE pairs (a ring or arc against a rectangle or disc): separated or touching, as
  EXACT. Penetrating, the kernel measures a ring below the face's plane within the face's bound
  from the face (the push back through it; where the ring crosses the bound, the ring against
  the face's edge along their common normal, docs/contact-geometry.md), not from the face's
  lateral bound where that exit is nearer: a contact patch's bound is not a surface of the
  part. So it sees at least the witnessed penetration, and is no deeper than the ring's deepest
  point below the face's plane within its bound (:func:`_face_push`, computed here from the
  ring's exact points, not by the kernel): a phantom is still caught.
- SEPARATION pairs (two solids: spheres, boxes, capsules, a sphere against a face's slab, a
  journal in a bore): the kernel's gap is a separation distance, the translation
  that parts the two solids. Separated, that is their distance, G; overlapping it is at least
  the depth of the deepest point (a point that deep needs that much motion) and can be more
  once a shape's centre is inside the other (two balls: r_a + r_b - d against the depth of B's
  boundary point nearest A's centre). So: the kernel sees at least the witnessed penetration
  (smallest <= gap), and equals G when the instrument says separated.
- RIMS (a cylinder against a bounded face): its candidates are its eight rim points, boundary
  points measured as a ring's are (RING_FACE: from the face within its bound), so none is
  deeper than the instrument's lower bound or, below the face within its bound, than the rims'
  deepest point below the face (no phantom); its lateral surface lying across the face's edge
  is not a candidate (a stated limitation of :mod:`clearbench.kernels.gaps.faces`), so nothing
  is asserted on the other side.

Configurations: A's body at a random pose, B's placed relative to it in A's frame near the
places that break kernels (a ring or arc across a face's bound, an arc's ends, a disc's rim, a
ring lying flat, a journal past a bore's end or its depth, boxes edge to edge), both pair orders.
Hypothesis prints the failing example. The default suite draws QUICK_EXAMPLES per pair and
order; ``-m slow`` runs THOROUGH_EXAMPLES.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from clearbench.harness.measure.instrument import independent_gap
from clearbench.scenarios.geometry import contacts_between
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

#: Examples per pair and order in the default suite (25 pairs x 2 orders: about 10 s).
QUICK_EXAMPLES = 6
#: Examples per pair and order under ``-m slow``.
THOROUGH_EXAMPLES = 150
#: Slack of an equality between the kernel and the instrument [L], on shapes of size 0.2-2:
#: 1e-8 is far above round-off (1e-15) and the kernel's angle minimisation (gap error
#: quadratic in its 1e-9 rad tolerance), far below any missed or invented contact (1e-3+).
TOLERANCE = 1e-8

#: Pairs, canonical order (A, B) as the kernel computes them, and what is asserted.
EXACT, SEPARATION, RIMS, RING_FACE = "exact", "separation", "rims", "ring_face"
PAIRS = {
    ("plane", "sphere"): EXACT, ("plane", "box"): EXACT, ("plane", "capsule"): EXACT,
    ("plane", "cylinder"): EXACT, ("plane", "circle"): EXACT, ("plane", "arc"): EXACT,
    ("sphere", "sphere"): SEPARATION, ("box", "sphere"): SEPARATION,
    ("capsule", "sphere"): SEPARATION, ("cylinder", "sphere"): SEPARATION,
    ("box", "box"): SEPARATION, ("capsule", "capsule"): SEPARATION,
    ("circle", "cylinder"): EXACT, ("arc", "cylinder"): EXACT,
    ("rectangle", "sphere"): SEPARATION, ("rectangle", "cylinder"): RIMS,
    ("rectangle", "circle"): RING_FACE, ("rectangle", "arc"): RING_FACE,
    ("disc", "sphere"): SEPARATION, ("disc", "cylinder"): RIMS,
    ("disc", "circle"): RING_FACE, ("disc", "arc"): RING_FACE,
    ("circle", "bore"): EXACT, ("arc", "bore"): EXACT, ("cylinder", "bore"): SEPARATION,
}
ORDERED = [(pair, swapped) for pair in PAIRS for swapped in (False, True)]


def _param(item):
    return pytest.param(item, id=_id(item))


def _id(item) -> str:
    (a, b), swapped = item
    return f"{b}-{a}" if swapped else f"{a}-{b}"


# -- poses -------------------------------------------------------------------------------------

def _multiply(p, q) -> np.ndarray:
    w1, x1, y1, z1 = p
    w2, x2, y2, z2 = q
    return np.array([w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2, w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
                     w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2, w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2])


def _rotate(q, v) -> np.ndarray:
    return _multiply(_multiply(q, np.r_[0.0, v]), q * np.array([1.0, -1.0, -1.0, -1.0]))[1:]


def _about(axis, angle) -> np.ndarray:
    axis = np.asarray(axis, dtype=float)
    axis = axis / np.linalg.norm(axis)
    return np.r_[math.cos(0.5 * angle), math.sin(0.5 * angle) * axis]


@st.composite
def quaternions(draw, tilt=None):
    """A unit quaternion: any rotation, or (``tilt`` given) a turn about z followed by a tilt of
    at most ``tilt`` rad, exactly 0 one time in four (a ring lying flat)."""
    spin = draw(st.floats(-math.pi, math.pi))
    if tilt is None:
        axis = draw(st.tuples(*[st.floats(-1.0, 1.0)] * 3).filter(
            lambda v: np.linalg.norm(v) > 0.1))
        return _multiply(_about(axis, draw(st.floats(-math.pi, math.pi))), _about((0, 0, 1), spin))
    angle = draw(st.one_of(st.just(0.0), st.floats(-tilt, tilt)))
    direction = draw(st.floats(-math.pi, math.pi))
    return _multiply(_about((math.cos(direction), math.sin(direction), 0.0), angle),
                     _about((0, 0, 1), spin))


def _size(draw, low=0.2, high=1.0):
    return draw(st.floats(low, high))


# -- shapes and relative placements of B in A's frame ------------------------------------------

def _shape(draw, kind: str, name: str):
    if kind == "sphere":
        return Sphere(name, radius=_size(draw))
    if kind == "box":
        return Box(name, half_extents=(_size(draw), _size(draw), _size(draw)))
    if kind in ("capsule", "cylinder"):
        cls = Capsule if kind == "capsule" else Cylinder
        return cls(name, radius=_size(draw, 0.2, 0.6), half_length=_size(draw, 0.2, 1.0))
    if kind == "plane":
        return Plane(name)
    if kind == "circle":
        return Circle(name, radius=_size(draw, 0.3, 1.0))
    if kind == "arc":
        start = draw(st.floats(-math.pi, math.pi))
        return Arc(name, radius=_size(draw, 0.3, 1.0), start_angle=start,
                   end_angle=start + draw(st.floats(0.3, 2.0 * math.pi)))
    depth = draw(st.one_of(st.none(), st.floats(0.2, 1.0)))
    if kind == "rectangle":
        return Rectangle(name, half_extents=(_size(draw, 0.5, 2.0), _size(draw, 0.5, 2.0)),
                         depth=depth)
    if kind == "disc":
        return Disc(name, radius=_size(draw, 0.5, 2.0), depth=depth)
    raise AssertionError(kind)


def _near_face_bound(draw, face, reach):
    """A point (face frame) near the face's bound: beyond or within it by up to ``reach``,
    above or below its plane by up to ``reach``."""
    if face.kind == "disc":
        angle = draw(st.floats(-math.pi, math.pi))
        radial = face.radius + draw(st.floats(-reach, reach))
        xy = radial * np.array([math.cos(angle), math.sin(angle)])
    else:
        half_x, half_y = face.half_extents
        sign = draw(st.sampled_from([-1.0, 1.0]))
        across = draw(st.floats(-reach, reach))  # > 0: beyond the bound
        if draw(st.booleans()):  # across an x bound, or a y bound
            xy = np.array([sign * (half_x + across),
                           draw(st.floats(-half_y - reach, half_y + reach))])
        else:
            xy = np.array([draw(st.floats(-half_x - reach, half_x + reach)),
                           sign * (half_y + across)])
    return np.r_[xy, draw(st.floats(-0.4 * reach, reach))]


def _relative(draw, shape_a, shape_b):
    """B's body position and quaternion in A's frame, near the hard places of the pair."""
    kind_a, kind_b = shape_a.kind, shape_b.kind
    size_b = getattr(shape_b, "radius", None) or max(getattr(shape_b, "half_extents", (1.0,)))
    if kind_a in ("rectangle", "disc"):
        return _near_face_bound(draw, shape_a, size_b), draw(quaternions(
            tilt=draw(st.sampled_from([0.3, math.pi]))))
    if kind_a == "plane":
        position = np.r_[draw(st.floats(-1.0, 1.0)), draw(st.floats(-1.0, 1.0)),
                         draw(st.floats(-0.3 * size_b, 1.2 * size_b))]
        return position, draw(quaternions(tilt=draw(st.sampled_from([0.3, math.pi]))))
    if kind_b == "bore":
        # A ring or journal inside the hole, nearly coaxial, near or past its ends.
        reach = shape_b.half_length + draw(st.floats(-0.5, 0.5))
        position = np.r_[draw(st.floats(-0.1, 0.1)), draw(st.floats(-0.1, 0.1)),
                         draw(st.sampled_from([-1.0, 1.0])) * reach]
        return -position, draw(quaternions(tilt=0.2))
    if kind_b == "cylinder" and kind_a in ("circle", "arc"):
        # A bearing ring around the journal (or beside a pin), within the journal's length:
        # the kernel takes the journal's lateral surface as infinitely long.
        eccentricity = draw(st.floats(0.0, shape_a.radius + shape_b.radius + 0.2))
        angle = draw(st.floats(-math.pi, math.pi))
        along = draw(st.floats(-0.5, 0.5)) * max(0.0, shape_b.half_length - shape_a.radius)
        tilt = draw(st.floats(-0.2, 0.2))
        return (np.array([eccentricity * math.cos(angle), eccentricity * math.sin(angle),
                          along]), _about((math.sin(angle), -math.cos(angle), 0.0), tilt))
    # Solids: B's centre near A's surface (edges and corners of a box included).
    size_a = getattr(shape_a, "radius", None) or max(getattr(shape_a, "half_extents", (1.0,)))
    extent = size_a + size_b
    position = np.array([draw(st.floats(-extent, extent)) for _ in range(3)])
    return position, draw(quaternions())


@st.composite
def configurations(draw, pair):
    """(shape A, pose A, shape B, pose B) of the canonical pair (kinds), poses of the BODIES
    (the shapes at their bodies' origins)."""
    shape_a = _shape(draw, pair[0], "a")
    if pair[1] != "bore":
        shape_b = _shape(draw, pair[1], "b")
    else:  # sized to its journal or ring: nearly fitting, with or without a depth
        inner = getattr(shape_a, "radius", 0.5)
        start = draw(st.floats(-math.pi, math.pi))
        partial = draw(st.booleans())
        shape_b = Bore("b", radius=inner + draw(st.floats(-0.05, 0.2)),
                       half_length=_size(draw, 0.3, 1.5), start_angle=start,
                       end_angle=start + (draw(st.floats(0.5, 2.0 * math.pi)) if partial
                                          else 2.0 * math.pi),
                       depth=draw(st.one_of(st.none(), st.floats(0.1, 0.5))))
    position_a = np.array([draw(st.floats(-1.0, 1.0)) for _ in range(3)])
    quaternion_a = draw(quaternions())
    relative_position, relative_quaternion = _relative(draw, shape_a, shape_b)
    position_b = position_a + _rotate(quaternion_a, relative_position)
    quaternion_b = _multiply(quaternion_a, relative_quaternion)
    return shape_a, (position_a, quaternion_a), shape_b, (position_b, quaternion_b)


#: Samples of a ring's angle locating where it crosses a face's bound (then bisected).
_CROSSING_SAMPLES = 2048
#: Bisections of a crossing: its angle to 2 pi / 2048 / 2^50, far below round-off of the depth
#: (also the golden-section steps of a touching point: 0.618^50 = 3e-11 of two samples).
_CROSSING_BISECTIONS = 50
#: The golden section, (sqrt 5 - 1) / 2.
_GOLDEN = 0.5 * (math.sqrt(5.0) - 1.0)


def _frame(shape, pose) -> tuple[np.ndarray, np.ndarray]:
    """The world origin [L] (3,) and axes (3, 3: columns x, y, z) of ``shape`` on its body."""
    turn = _multiply(pose[1], np.asarray(shape.orientation, dtype=float))
    origin = pose[0] + _rotate(pose[1], np.asarray(shape.position, dtype=float))
    return origin, np.column_stack([_rotate(turn, axis) for axis in np.eye(3)])


def _face_push(face, face_pose, ring, ring_pose) -> float:
    """The depth [L] of the ring's deepest point below the face's plane among its points within
    the face's bound (at most the face's ``depth``), 0 if none is below it: the most a contact
    measured from the face can read. Exact up to round-off: over each stretch of the ring's
    angle within the bound the height's minimum is at the ring's lowest point or at the
    stretch's ends (an arc's end, a crossing of the bound found by bisection, or a point where
    the ring touches the bound from outside, found by golden-section search)."""
    start = getattr(ring, "start_angle", 0.0)
    end = getattr(ring, "end_angle", 2.0 * math.pi)
    face_origin, face_axes = _frame(face, face_pose)
    ring_origin, ring_axes = _frame(ring, ring_pose)
    # The ring's centre and its x and y axes in the face's frame.
    centre = face_axes.T @ (ring_origin - face_origin)
    first, second = face_axes.T @ ring_axes[:, 0], face_axes.T @ ring_axes[:, 1]

    def in_face_frame(angles):
        angles = np.asarray(angles, dtype=float)[:, None]
        return centre + ring.radius * (np.cos(angles) * first + np.sin(angles) * second)

    def beyond(points):  # how far beyond the face's bound [L] (<= 0: within it)
        if face.kind == "disc":
            return np.hypot(points[:, 0], points[:, 1]) - face.radius
        return np.max(np.abs(points[:, :2]) - np.asarray(face.half_extents), axis=1)

    def within(points):  # on the bound to round-off counts as within, as in the kernel
        return beyond(points) <= TOLERANCE

    samples = np.linspace(start, end, _CROSSING_SAMPLES + 1)
    outside = beyond(in_face_frame(samples))
    inside = outside <= TOLERANCE
    angles = [start, end]
    # Where the ring touches the bound from outside without crossing it: the local minima of
    # its distance beyond the bound, refined by golden-section search between the samples
    # either side.
    for i in np.flatnonzero((outside[1:-1] <= outside[:-2]) & (outside[1:-1] <= outside[2:])):
        low, high = samples[i], samples[i + 2]
        for _ in range(_CROSSING_BISECTIONS):
            left, right = high - _GOLDEN * (high - low), low + _GOLDEN * (high - low)
            if beyond(in_face_frame([left]))[0] <= beyond(in_face_frame([right]))[0]:
                high = right
            else:
                low = left
        angles.append(0.5 * (low + high))
    for i in np.flatnonzero(inside[:-1] != inside[1:]):
        low, high = samples[i], samples[i + 1]
        for _ in range(_CROSSING_BISECTIONS):
            middle = 0.5 * (low + high)
            if within(in_face_frame([middle]))[0] == inside[i]:
                low = middle
            else:
                high = middle
        angles += [low if inside[i] else high]
    # The ring's lowest point: its height z(theta) = c + a cos(theta) + b sin(theta) is least
    # at atan2(-b, -a), taken into the arc's range (a flat ring has none: its ends and
    # crossings are enough).
    a, b = first[2], second[2]
    if math.hypot(a, b) > 0.0:
        lowest = start + (math.atan2(-b, -a) - start) % (2.0 * math.pi)
        if lowest <= end:
            angles.append(lowest)
    points = in_face_frame(np.array(angles))
    depth = float(np.max(-points[within(points), 2], initial=0.0))
    if face.depth is not None:
        depth = min(depth, face.depth)
    return max(depth, 0.0)


def _rims(cylinder) -> list:
    """The two end rims of a cylinder, as circles in its body's frame."""
    turn = np.asarray(cylinder.orientation, dtype=float)
    centre = np.asarray(cylinder.position, dtype=float)
    return [Circle(f"rim{end:+.0f}", radius=cylinder.radius, orientation=tuple(turn),
                   position=tuple(centre + _rotate(turn, [0.0, 0.0, end * cylinder.half_length])))
            for end in (-1.0, 1.0)]


def _check(pair, swapped, configuration):
    shape_a, pose_a, shape_b, pose_b = configuration
    if swapped:
        shape_a, pose_a, shape_b, pose_b = shape_b, pose_b, shape_a, pose_a
    kernel = contacts_between(shape_a, pose_a, shape_b, pose_b)
    smallest = float(np.min(kernel.gap)) if kernel.count else math.inf
    reading = independent_gap(shape_a, pose_a, shape_b, pose_b)
    lower = reading.gap - reading.resolution
    what = PAIRS[pair]
    seen = smallest <= reading.gap + TOLERANCE
    report = (f"kernel's smallest gap {smallest!r}, instrument's {reading.gap!r} "
              f"(true value in [{lower!r}, {reading.gap!r}])")
    deepest = lower
    if what in (RING_FACE, RIMS) and lower <= 0.0:
        # Penetrating, a ring (or a cylinder's rims) is measured from the face: as deep as
        # its deepest point below the face within its bound, when that is deeper.
        face, face_pose, other, other_pose = configuration
        rings = _rims(other) if what == RIMS else [other]
        push = max(_face_push(face, face_pose, ring, other_pose) for ring in rings)
        deepest = min(lower, -push)
        report += f"; deepest point below the face within its bound {push!r}"
    no_phantom = smallest >= deepest - TOLERANCE
    if what in (EXACT, RING_FACE):
        assert seen and no_phantom, report
    elif what == SEPARATION:
        assert seen, "the kernel misses a penetration or contact: " + report
        if lower > 0.0:
            assert no_phantom, "separated, the kernel's distance is not theirs: " + report
    else:
        assert no_phantom, "a penetration the geometry does not have: " + report


_QUICK = settings(max_examples=QUICK_EXAMPLES, deadline=None, derandomize=True,
                  suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
_THOROUGH = settings(max_examples=THOROUGH_EXAMPLES, deadline=None,
                     suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])


@pytest.mark.parametrize("item", [_param(item) for item in ORDERED])
@_QUICK
@given(data=st.data())
def test_kernel_agrees_with_the_instrument(item, data):
    pair, swapped = item
    _check(pair, swapped, data.draw(configurations(pair), label="configuration"))


@pytest.mark.slow
@pytest.mark.parametrize("item", [_param(item) for item in ORDERED])
@_THOROUGH
@given(data=st.data())
def test_kernel_agrees_with_the_instrument_thoroughly(item, data):
    pair, swapped = item
    _check(pair, swapped, data.draw(configurations(pair), label="configuration"))


def test_every_pair_of_the_kernel_is_checked():
    from clearbench.kernels.gaps import CANONICAL_PAIRS, SHAPE_KIND_NAMES

    assert {(SHAPE_KIND_NAMES[a], SHAPE_KIND_NAMES[b]) for a, b in CANONICAL_PAIRS} == set(PAIRS)


@pytest.mark.parametrize("offset", [1e-3, 0.0])
def test_a_journal_rim_at_a_partial_bores_edge_is_seen(offset):
    """The example the property test drew (under some collections of test files): a journal
    (r 0.5, half length 1) whose end is in the middle plane of a bore of the same radius, the
    bore's arc 0..1 rad, tilted 0.125 rad about the arc's start line, moved ``offset`` away
    from it [L]. The journal's end-rim point on the tilt axis is the pair's closest point, on
    the arc's start edge: the separation is ``offset`` (the instrument reads it within its
    resolution, 4e-7), and the kernel's smallest gap must be it within TOLERANCE.

    The rim's point farthest from the bore's axis is the one opposite, outside the bore's
    angles: a kernel that takes that point and drops it outside the angles (as the kernel did
    until the rim's nearest point to the bore's solid was searched) reads 0.0163 here, the
    other end's figure."""
    tilt = 0.125
    journal = Cylinder("a", radius=0.5, half_length=1.0)
    bore = Bore("b", radius=0.5, half_length=1.0, start_angle=0.0, end_angle=1.0, depth=None)
    pose_a = (np.zeros(3), np.array([1.0, 0.0, 0.0, 0.0]))
    pose_b = (np.array([offset, 0.0, 1.0]),
              np.array([math.cos(tilt / 2), math.sin(tilt / 2), 0.0, 0.0]))
    reading = independent_gap(journal, pose_a, bore, pose_b)
    assert reading.gap - reading.resolution <= offset <= reading.gap + TOLERANCE
    kernel = contacts_between(journal, pose_a, bore, pose_b)
    assert kernel.count and abs(float(np.min(kernel.gap)) - offset) <= TOLERANCE, (
        f"kernel {np.min(kernel.gap) if kernel.count else math.inf!r}, instrument "
        f"{reading.gap!r} +- {reading.resolution!r}")


def _journal_and_bore(journal, bore, journal_position):
    """The kernel's and the instrument's readings of ``journal`` at ``journal_position`` (bore
    at the origin, both unrotated)."""
    identity = np.array([1.0, 0.0, 0.0, 0.0])
    pose_a, pose_b = (np.asarray(journal_position, float), identity), (np.zeros(3), identity)
    kernel = contacts_between(journal, pose_a, bore, pose_b)
    return kernel, independent_gap(journal, pose_a, bore, pose_b)


def test_a_journal_through_a_thin_wall_is_pushed_back_into_the_hole():
    """A journal (r 0.5) coaxial with a bore of the same radius whose wall is 0.1 thick, moved
    0.15 off the axis: it crosses the whole wall. Its separation from the bore's solid is the
    radial 0.15 back into the hole (the bore's surface point on the offset's line is 0.15 deep
    in the journal: the instrument's reading). A kernel that measures each rim point against
    the nearest boundary of the wall reads at most half the wall: the kernel before the rims
    of a journal in the hole were measured from the hole read -0.05 at both rims, its normal
    (-0.45, -0.89, 0), at a rim point where the wall is thinnest around it."""
    journal = Cylinder("a", radius=0.5, half_length=0.5)
    bore = Bore("b", radius=0.5, half_length=1.0, depth=0.1)
    kernel, reading = _journal_and_bore(journal, bore, (0.15, 0.0, 0.0))
    assert reading.gap - reading.resolution <= -0.15 <= reading.gap + TOLERANCE
    # Both end rims, each 0.15 into the wall along +x; the normal from the journal into the
    # wall, +x (the journal is pushed back along -x).
    assert kernel.count == 2
    np.testing.assert_allclose(kernel.gap, -0.15, atol=TOLERANCE)
    np.testing.assert_allclose(kernel.normal, [[1.0, 0.0, 0.0]] * 2, atol=TOLERANCE)


def test_a_journal_across_a_half_bearings_cut_edge_is_seen_at_the_edge():
    """A half bearing (a bore of r 0.5 over 0..pi, no back) and a journal of the same radius,
    shorter than it and within its ends, moved 0.02 toward the cut at angle 0: the cut's edge
    line (x 0.5, y 0) runs through the journal 0.02 deep along its whole length, between the
    journal's end rims. The rims see less: a rim point past the edge is outside the bearing's
    angles, one within them is shallower as it turns away: the kernel read -0.019985 before
    the bearing's edges were measured against the journal."""
    journal = Cylinder("a", radius=0.5, half_length=0.3)
    bore = Bore("b", radius=0.5, half_length=1.0, start_angle=0.0, end_angle=math.pi)
    kernel, reading = _journal_and_bore(journal, bore, (0.02, 0.0, 0.1))
    assert reading.gap - reading.resolution <= -0.02 <= reading.gap + TOLERANCE
    deepest = int(np.argmin(kernel.gap))
    assert abs(kernel.gap[deepest] + 0.02) <= TOLERANCE
    # The edge point is pushed out of the journal along the journal's radius: +x.
    np.testing.assert_allclose(kernel.normal[deepest], [1.0, 0.0, 0.0], atol=1e-7)


@pytest.mark.parametrize("swapped", [False, True], ids=["face-arc", "arc-face"])
def test_an_arcs_end_beyond_the_bound_is_seen_when_its_support_moves(swapped):
    """An arc (r 1, 1.25 to 7 rad) lying nearly parallel to a rectangle (half extents 1 x 0.5,
    no depth), its centre over the face's x bound and 0.5 above it, turned 2.52 rad about -x:
    its end at 7 rad is its point nearest the face's solid, just beyond the face's y bound and
    above its plane. That end's support point has a neighbour within the bound, so it is moved
    to where the arc crosses the bound; the kernel before it staged a minimum there read the
    nearest point 0.1265 away (a crossing), 0.0165 farther than the end (the example the
    thorough property test drew). The end's distance is computed here from the end point and
    the slab x in [-1, 1], y in [-0.5, 0.5], z <= 0."""
    face = Rectangle("a", half_extents=(1.0, 0.5))
    arc = Arc("b", radius=1.0, start_angle=1.25, end_angle=7.0)
    turn = np.array([0.31532236, -0.94898462, 0.0, 0.0])
    face_pose = (np.zeros(3), np.array([1.0, 0.0, 0.0, 0.0]))
    arc_pose = (np.array([-1.0, 0.0, 0.5]), turn / np.linalg.norm(turn))
    end = arc_pose[0] + _rotate(arc_pose[1], np.array([math.cos(7.0), math.sin(7.0), 0.0]))
    beyond = np.maximum(np.abs(end[:2]) - [1.0, 0.5], 0.0)
    by_hand = math.hypot(*beyond, max(end[2], 0.0))
    assert abs(by_hand - 0.1100) < 1e-4  # the place the docstring describes
    pairs = (arc, arc_pose, face, face_pose) if swapped else (face, face_pose, arc, arc_pose)
    kernel = contacts_between(*pairs)
    assert abs(float(np.min(kernel.gap)) - by_hand) < TOLERANCE
    _check(("rectangle", "arc"), swapped, (face, face_pose, arc, arc_pose))


def _cylinder_solid_distance(points, radius, half_length):
    """Signed distance [L] of points (n, 3) in a cylinder's frame to its solid (written here,
    independently of the kernel's)."""
    radial = np.hypot(points[:, 0], points[:, 1]) - radius
    axial = np.abs(points[:, 2]) - half_length
    outside = np.hypot(np.maximum(radial, 0.0), np.maximum(axial, 0.0))
    return np.where((radial <= 0.0) & (axial <= 0.0), np.maximum(radial, axial), outside)


def _tilted_journal_in_a_full_bore(radius, half_length, tilt, end_centre):
    """A journal (``radius``, ``half_length``) tilted by ``tilt`` [rad] about x, its +z end
    face's centre at ``end_centre``, and a full bore without a back (r 0.5, half length 1) at
    the origin: (journal, journal pose, bore, bore pose, the bore's +z end rim sampled every
    1e-5 rad in the journal's frame (n, 3))."""
    journal = Cylinder("a", radius=radius, half_length=half_length)
    bore = Bore("b", radius=0.5, half_length=1.0)
    turn = _about((1.0, 0.0, 0.0), tilt)
    axes = np.column_stack([_rotate(turn, axis) for axis in np.eye(3)])
    centre = np.asarray(end_centre, dtype=float) - half_length * axes[:, 2]
    angles = np.arange(0.0, 2.0 * math.pi, 1e-5)
    rim = np.c_[0.5 * np.cos(angles), 0.5 * np.sin(angles), np.ones(angles.size)]
    return (journal, (centre, turn), bore, (np.zeros(3), np.array([1.0, 0.0, 0.0, 0.0])),
            (rim - centre) @ axes)


@pytest.mark.parametrize("swapped", [False, True], ids=["journal-bore", "bore-journal"])
def test_a_journal_just_past_a_full_bores_end_is_read_as_finite(swapped):
    """A journal (r 0.45, half length 0.2) tilted 0.1 rad about x, in a full bore without a
    back (r 0.5, half length 1; the C-60's plunger bearing is one), its axis's end 0.002 past
    the bore's +z end, 0.03 toward -y: past its end the journal's axis heads on toward the
    bore's wall. The bore's rim is measured against the journal's finite solid: the journal
    taken as infinitely long (the kernel before it, for a full bore without a back) reads
    the rim 0.0179 from it where the journal is 0.0222 from the bore's solid (the instrument),
    a contact seen 0.0044 early (in c60-trip: 0.001 mm read where the plunger was 0.0018 mm
    away). The infinitely long reading is computed here from the rim's samples (error below
    1e-10)."""
    journal, journal_pose, bore, bore_pose, rim = _tilted_journal_in_a_full_bore(
        0.45, 0.2, 0.1, (0.0, -0.03, 1.002))
    infinitely_long = float(np.min(np.hypot(rim[:, 0], rim[:, 1]) - 0.45))
    reading = independent_gap(journal, journal_pose, bore, bore_pose)
    assert infinitely_long < reading.gap - reading.resolution - 4e-3  # the docstring's place
    pairs = (bore, bore_pose, journal, journal_pose) if swapped else \
        (journal, journal_pose, bore, bore_pose)
    kernel = contacts_between(*pairs)
    assert reading.gap - reading.resolution - TOLERANCE <= float(np.min(kernel.gap)) \
        <= reading.gap + TOLERANCE
    _check(("cylinder", "bore"), swapped, (journal, journal_pose, bore, bore_pose))


def test_a_tilted_journals_end_face_past_a_full_bores_rim_is_seen():
    """A journal (r 0.45, half length 0.5) tilted 0.05 rad about x in a full bore without a
    back (r 0.5, half length 1), its axis ending 0.01 inside the bore's +z end: its end face
    is tilted, so its edge on the +y side reaches 0.0125 past the bore's end. The +z side's
    candidate is the bore's end rim against that edge, 0.049875 away (the rim's samples
    against the journal's solid, computed here); the kernel before it read the journal's own
    end rim against the bore's surface there, 0.05, the radial gap as if the bore went on.
    (The pair's smallest gap is at the journal's -z end, 0.0006, which the property test
    compares; this test reads the +z side's slot.)"""
    journal, journal_pose, bore, bore_pose, rim = _tilted_journal_in_a_full_bore(
        0.45, 0.5, 0.05, (0.0, 0.0, 0.99))
    edge = float(np.min(_cylinder_solid_distance(rim, 0.45, 0.5)))
    assert abs(edge - 0.049875) < 1e-6  # the place the docstring describes
    kernel = contacts_between(journal, journal_pose, bore, bore_pose)
    plus_z = [k for k in range(kernel.count) if kernel.point_b[k, 2] > 0.5]  # the upper end
    assert len(plus_z) == 1
    assert abs(kernel.gap[plus_z[0]] - edge) < TOLERANCE
    _check(("cylinder", "bore"), False, (journal, journal_pose, bore, bore_pose))


@pytest.mark.parametrize("swapped", [False, True], ids=["journal-bore", "bore-journal"])
def test_a_journal_beyond_a_half_bearing_is_nearest_its_backs_rim(swapped):
    """A journal (r 0.5, half length 0.25) at the origin, a partial bore (r 0.5, 0 to 5 rad,
    half length 1, a back 0.125 deep) whose -z end is 0.5 above it, tilted 0.125 rad about x:
    no axial overlap. The bore's solid is nearest the journal at its back's end rim (radius
    0.625), not at its rim at its radius; the kernel before it read the back's edges read the
    inner rim's 0.179938 (the example the thorough property test drew). Both rims' distances
    are computed here by sampling the arcs every 5e-5 rad (a minimum's error below 1e-9)."""
    journal = Cylinder("a", radius=0.5, half_length=0.25)
    bore = Bore("b", radius=0.5, half_length=1.0, start_angle=0.0, end_angle=5.0, depth=0.125)
    journal_pose = (np.zeros(3), np.array([1.0, 0.0, 0.0, 0.0]))
    bore_pose = (np.array([0.0, 0.0, 1.5]), _about((1.0, 0.0, 0.0), 0.125))
    angles = np.arange(0.0, 5.0 + 2.5e-5, 5e-5)

    def rim(radius):
        local = np.c_[radius * np.cos(angles), radius * np.sin(angles), -np.ones(angles.size)]
        world = np.array([bore_pose[0] + _rotate(bore_pose[1], p) for p in local])
        return float(np.min(_cylinder_solid_distance(world, 0.5, 0.25)))

    back, inner = rim(0.625), rim(0.5)
    assert back < inner - 1e-5  # the place the docstring describes: the back's rim is nearer
    pairs = (bore, bore_pose, journal, journal_pose) if swapped else \
        (journal, journal_pose, bore, bore_pose)
    kernel = contacts_between(*pairs)
    assert abs(float(np.min(kernel.gap)) - back) < TOLERANCE
    _check(("cylinder", "bore"), swapped, (journal, journal_pose, bore, bore_pose))
