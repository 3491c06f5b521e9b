"""Contact geometry: frames, gap signs, pair symmetry, gap derivatives, bearing rings, boxes."""

import itertools
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from clearbench.kernels.gaps import CANONICAL_PAIRS
from clearbench.kernels.quaternion import quat_from_axis_angle, quat_to_matrix
from clearbench.scenarios import geometry as G
from clearbench.scenarios.shapes import Arc, Box, Capsule, Circle, Cylinder, Plane, Sphere

EPS = np.finfo(float).eps
IDENTITY = np.eye(3)
K = G.MAX_CONTACTS_PER_PAIR


def rotation(axis, angle) -> np.ndarray:
    return quat_to_matrix(quat_from_axis_angle(np.asarray(axis, float), float(angle)))


def random_rotation(rng) -> np.ndarray:
    q = rng.normal(size=4)
    return quat_to_matrix(q / np.linalg.norm(q))


def params(*values) -> np.ndarray:
    packed = np.zeros(G.PARAMETER_COUNT)
    packed[: len(values)] = values
    return packed


def contacts(kind_a, params_a, position_a, rotation_a, kind_b, params_b, position_b,
             rotation_b):
    """pair_contacts into fresh arrays; returns (gap, point_a, point_b, frame) of length k."""
    gap = np.full(K, np.nan)
    point_a = np.full((K, 3), np.nan)
    point_b = np.full((K, 3), np.nan)
    frame = np.full((K, 3, 3), np.nan)
    count = G.pair_contacts(kind_a, params_a, np.asarray(position_a, float), rotation_a, kind_b,
                            params_b, np.asarray(position_b, float), rotation_b, gap, point_a,
                            point_b, frame)
    assert 0 <= count <= K
    return gap[:count], point_a[:count], point_b[:count], frame[:count]


# ------------------------------------------------------------------------------------------------
# Contact frames
# ------------------------------------------------------------------------------------------------


def assert_proper_frame(frame, normal):
    # Orthonormality and det = +1 to round-off: a few ulp of O(1) quantities.
    assert np.allclose(frame @ frame.T, IDENTITY, rtol=0, atol=8 * EPS)
    assert abs(np.linalg.det(frame) - 1.0) < 8 * EPS
    assert np.allclose(np.cross(frame[1], frame[2]), frame[0], rtol=0, atol=8 * EPS)
    assert np.allclose(frame[0], normal / np.linalg.norm(normal), rtol=0, atol=4 * EPS)


unit_normals = st.tuples(
    st.floats(-1, 1, allow_nan=False), st.floats(-1, 1, allow_nan=False),
    st.floats(-1, 1, allow_nan=False),
).filter(lambda v: sum(c * c for c in v) > 1e-8).map(lambda v: np.asarray(v) / np.linalg.norm(v))


@given(unit_normals)
@settings(max_examples=500, deadline=None)
def test_frame_is_right_handed_orthonormal_for_random_normals(normal):
    assert_proper_frame(G.contact_frame(normal), normal)


AXIS_ALIGNED = [np.array(v, float) for v in itertools.product((-1, 0, 1), repeat=3) if any(v)]


@pytest.mark.parametrize("normal", AXIS_ALIGNED, ids=lambda v: str(v.astype(int)))
def test_frame_is_proper_for_axis_aligned_normals_including_plus_minus_z(normal):
    assert_proper_frame(G.contact_frame(normal), normal)


@pytest.mark.parametrize("offset", [0.0, 1e-300, 1e-16, 1e-12, 1e-8, 1e-4])
def test_frame_is_proper_at_and_near_its_singular_direction(offset):
    singular = np.asarray(G.FRAME_SINGULAR_DIRECTION)
    normal = singular + offset * np.array([0.3, -0.7, 0.2])
    assert_proper_frame(G.contact_frame(normal), normal)


def test_frame_of_the_pole_is_the_fixed_basis_and_smooth_elsewhere():
    pole = np.asarray(G.FRAME_POLE)
    frame = G.contact_frame(pole)
    # The pole's frame is (p, e1, e2) with e1 = (3, -2, 0)/sqrt(13): exact up to round-off.
    assert np.allclose(frame[1], np.array([3.0, -2.0, 0.0]) / math.sqrt(13.0), atol=4 * EPS)
    # Lipschitz continuity away from the singular direction: a rotation of the normal by 1e-6
    # rad turns the tangents by O(1e-6) (here at most ~1/cos^2(angle/2) times that; the bound
    # 1e-5 holds at least 60 degrees away from the singular direction).
    rng = np.random.default_rng(3)
    singular = np.asarray(G.FRAME_SINGULAR_DIRECTION)
    checked = 0
    while checked < 200:
        normal = rng.normal(size=3)
        normal /= np.linalg.norm(normal)
        if normal @ singular > 0.5:
            continue
        nudged = rotation(rng.normal(size=3), 1e-6) @ normal
        change = np.abs(G.contact_frame(nudged) - G.contact_frame(normal)).max()
        assert change < 1e-5
        checked += 1


def test_frames_batch_matches_the_kernel():
    rng = np.random.default_rng(4)
    normals = rng.normal(size=(4, 5, 3))
    normals /= np.linalg.norm(normals, axis=-1, keepdims=True)
    batch = G.contact_frames_batch(normals)
    assert batch.shape == (4, 5, 3, 3)
    for index in np.ndindex(4, 5):
        assert np.array_equal(batch[index], G.contact_frame(normals[index]))  # same kernel


# ------------------------------------------------------------------------------------------------
# Gap signs on hand-built configurations (gap0 = +0.1 separated, 0 touching, -0.1 penetrating)
# ------------------------------------------------------------------------------------------------

GAPS = [0.1, 0.0, -0.1]
# Hand-built positions are sums of a few numbers of size <= 10 (the bore): a few ulp of 10.
HAND_TOLERANCE = 64 * EPS


def hand_built_cases(gap0):
    """(name, shape A args, shape B args, expected gaps of the candidates that must exist)."""
    c45 = math.sqrt(0.5)
    yield "sphere-plane", (G.PLANE, params(), (0, 0, 0), IDENTITY), (
        G.SPHERE, params(0.5), (0.3, -0.2, 0.5 + gap0), IDENTITY), [gap0]
    yield "sphere-sphere", (G.SPHERE, params(0.5), (0, 0, 0), IDENTITY), (
        G.SPHERE, params(0.25), np.array([0.6, 0.0, 0.8]) * (0.75 + gap0), IDENTITY), [gap0]
    yield "box-sphere face", (G.BOX, params(1.0, 0.5, 0.25), (0, 0, 0), IDENTITY), (
        G.SPHERE, params(0.5), (0.2, 0.1, 0.75 + gap0), IDENTITY), [gap0]
    yield "box-sphere corner", (G.BOX, params(1.0, 0.5, 0.25), (0, 0, 0), IDENTITY), (
        G.SPHERE, params(0.5), np.array([1.0, 0.5, 0.25]) + (0.5 + gap0) * np.ones(3)
        / math.sqrt(3.0), IDENTITY), [gap0]
    yield "capsule-sphere", (G.CAPSULE, params(0.2, 1.0), (0, 0, 0), IDENTITY), (
        G.SPHERE, params(0.3), (0.0, 0.5 + gap0, 0.4), IDENTITY), [gap0]
    yield "cylinder-sphere side", (G.CYLINDER, params(0.4, 1.0), (0, 0, 0), IDENTITY), (
        G.SPHERE, params(0.3), (0.7 + gap0, 0.0, 0.9), IDENTITY), [gap0]
    yield "cylinder-sphere cap", (G.CYLINDER, params(0.4, 1.0), (0, 0, 0), IDENTITY), (
        G.SPHERE, params(0.3), (0.1, 0.2, 1.3 + gap0), IDENTITY), [gap0]
    yield "cylinder-sphere rim", (G.CYLINDER, params(0.4, 1.0), (0, 0, 0), IDENTITY), (
        G.SPHERE, params(0.3), (0.4 + (0.3 + gap0) * c45, 0.0, 1.0 + (0.3 + gap0) * c45),
        IDENTITY), [gap0]
    yield "box-plane", (G.PLANE, params(), (0, 0, 0), IDENTITY), (
        G.BOX, params(0.5, 0.3, 0.2), (1.0, 2.0, 0.2 + gap0), rotation((0, 0, 1), 0.7)), \
        [gap0] * 4 + [gap0 + 0.4] * 4
    yield "box-box stack", (G.BOX, params(1.0, 1.0, 0.5), (0, 0, 0), IDENTITY), (
        G.BOX, params(0.3, 0.2, 0.1), (0.2, -0.3, 0.6 + gap0), rotation((0, 0, 1), 0.5)), \
        [gap0] * 4
    yield "capsule-plane", (G.PLANE, params(), (0, 0, 1.0), IDENTITY), (
        G.CAPSULE, params(0.25, 0.8), (0.0, 0.0, 1.25 + gap0), rotation((1, 0, 0), math.pi / 2)
    ), [gap0, gap0]
    yield "capsule-capsule crossed", (G.CAPSULE, params(0.2, 1.0), (0, 0, 0),
                                      rotation((0, 1, 0), math.pi / 2)), (
        G.CAPSULE, params(0.3, 1.0), (0.1, 0.2, 0.5 + gap0), rotation((1, 0, 0), math.pi / 2)
    ), [gap0]
    yield "capsule-capsule parallel", (G.CAPSULE, params(0.2, 1.0), (0, 0, 0), IDENTITY), (
        G.CAPSULE, params(0.3, 0.5), (0.5 + gap0, 0.0, 0.8), IDENTITY), [gap0, gap0]
    yield "cylinder-plane lying", (G.PLANE, params(), (0, 0, 0), IDENTITY), (
        G.CYLINDER, params(0.4, 1.0), (0.0, 0.0, 0.4 + gap0), rotation((1, 1, 0), math.pi / 2)
    ), [gap0, gap0, gap0 + 0.4, gap0 + 0.4, gap0 + 0.8, gap0 + 0.8, gap0 + 0.4, gap0 + 0.4]
    yield "cylinder-plane standing", (G.PLANE, params(), (0, 0, 0), IDENTITY), (
        G.CYLINDER, params(0.4, 1.0), (0.0, 0.0, 1.0 + gap0), IDENTITY), \
        [gap0, gap0 + 2.0] * 4
    yield "circle-plane tilted", (G.PLANE, params(), (0, 0, 0), IDENTITY), (
        G.CIRCLE, params(0.5), (0.0, 0.0, 0.5 * math.sin(0.4) + gap0), rotation((1, 0, 0), 0.4)
    ), [gap0]
    yield "arc-plane lowest inside", (G.PLANE, params(), (0, 0, 0), IDENTITY), (
        G.ARC, params(0.5, -2.0, -1.0), (0.0, 0.0, 0.5 + gap0), rotation((1, 0, 0), math.pi / 2)
    ), [gap0]
    # Bore radius 10, eccentricity 0.05, journal radius 9.95 - gap0: gap = 10 - R_j - e.
    yield "circle-cylinder internal", (G.CIRCLE, params(10.0), (0.03, 0.04, 2.0), IDENTITY), (
        G.CYLINDER, params(9.95 - gap0, 5.0), (0, 0, 0), IDENTITY), [gap0]
    yield "circle-cylinder external", (G.CIRCLE, params(1.0), (0, 0, 0), IDENTITY), (
        G.CYLINDER, params(0.2, 3.0), (0.0, 1.2 + gap0, 0.0), IDENTITY), [gap0]
    yield "arc-cylinder external", (G.ARC, params(1.0, 0.0, math.pi), (0, 0, 0), IDENTITY), (
        G.CYLINDER, params(0.2, 3.0), (0.0, 1.2 + gap0, 0.0), IDENTITY), [gap0]


@pytest.mark.parametrize("gap0", GAPS, ids=["separated", "touching", "penetrating"])
def test_gaps_of_hand_built_configurations(gap0):
    for name, shape_a, shape_b, expected in hand_built_cases(gap0):
        gap, point_a, point_b, frame = contacts(*shape_a, *shape_b)
        assert np.allclose(np.sort(gap)[: len(expected)], np.sort(expected),
                           rtol=0, atol=HAND_TOLERANCE), (name, gap, expected)
        # The smallest gap carries the sign of the configuration.
        if expected:
            assert np.sign(round(gap.min(), 12)) == np.sign(gap0), name
        # p_B - p_A = g n for every candidate (to round-off, as above).
        difference = point_b - point_a - gap[:, None] * frame[:, 0, :]
        assert np.abs(difference).max() < HAND_TOLERANCE, name


def test_circle_plane_tilted_lowest_point_closed_form():
    # Circle of radius 0.5 whose axis is tilted by 0.4 rad from the plane normal: its lowest point
    # is 0.5 sin(0.4) below its centre. The kernel finds it by a minimisation over the ring
    # angle (to 1e-9 rad): the gap, quadratic there, to round-off (a sine and a subtraction).
    gap, point_a, point_b, _ = contacts(G.PLANE, params(), (0, 0, 0), IDENTITY, G.CIRCLE,
                                        params(0.5), (0.0, 0.0, 1.0),
                                        rotation((1, 0, 0), 0.4))
    lowest = int(np.argmin(gap))
    assert abs(gap[lowest] - (1.0 - 0.5 * math.sin(0.4))) < 4 * EPS
    assert abs(point_b[lowest, 2] - gap[lowest]) < 4 * EPS  # the plane is z = 0: same numbers


# ------------------------------------------------------------------------------------------------
# Random configurations of every supported pair: swap symmetry, frames, finite differences
# ------------------------------------------------------------------------------------------------


def random_parameters(kind, rng):
    if kind == G.SPHERE:
        return params(rng.uniform(0.2, 1.0))
    if kind == G.BOX:
        return params(*rng.uniform(0.2, 1.0, size=3))
    if kind in (G.CAPSULE, G.CYLINDER):
        return params(rng.uniform(0.2, 0.6), rng.uniform(0.2, 1.0))
    if kind == G.PLANE:
        return params()
    if kind == G.CIRCLE:
        return params(rng.uniform(0.6, 1.2))
    if kind == G.RECTANGLE:
        return params(*rng.uniform(1.0, 3.0, size=2))
    if kind == G.DISC:
        return params(rng.uniform(1.0, 3.0))
    start = rng.uniform(-math.pi, math.pi)
    if kind == G.BORE:
        return params(rng.uniform(1.5, 2.5), rng.uniform(0.5, 2.0), start,
                      start + rng.uniform(1.0, 2 * math.pi))
    return params(rng.uniform(0.6, 1.2), start, start + rng.uniform(0.3, 2 * math.pi))


def random_pair(kind_a, kind_b, rng):
    return (
        (kind_a, random_parameters(kind_a, rng), rng.uniform(-0.5, 0.5, 3), random_rotation(rng)),
        (kind_b, random_parameters(kind_b, rng), rng.uniform(-1.5, 1.5, 3), random_rotation(rng)),
    )


ALL_ORDERED_PAIRS = CANONICAL_PAIRS + tuple((b, a) for a, b in CANONICAL_PAIRS if a != b)


def pair_id(pair):
    return f"{G.kind_name(pair[0])}-{G.kind_name(pair[1])}"


@pytest.mark.parametrize("pair", ALL_ORDERED_PAIRS, ids=pair_id)
@given(seed=st.integers(0, 2**32 - 1))
@settings(max_examples=40, deadline=None)
def test_swapping_bodies_mirrors_the_contacts_exactly(pair, seed):
    a, b = random_pair(*pair, np.random.default_rng(seed))
    gap, point_a, point_b, frame = contacts(*a, *b)
    gap_s, point_a_s, point_b_s, frame_s = contacts(*b, *a)
    # One canonical computation mirrored: bit-identical gaps and points, negated normals.
    assert np.array_equal(gap, gap_s)
    assert np.array_equal(point_a, point_b_s) and np.array_equal(point_b, point_a_s)
    assert np.array_equal(frame[:, 0], -frame_s[:, 0])
    for k in range(gap.shape[0]):
        assert_proper_frame(frame[k], frame[k, 0])
        assert_proper_frame(frame_s[k], frame_s[k, 0])
    # p_B - p_A = g n (positions O(3): a few ulp of 3).
    assert np.allclose(point_b - point_a, gap[:, None] * frame[:, 0], rtol=0, atol=64 * EPS)
    assert np.all(np.isfinite(gap))


# Pairs whose every candidate is a closest point (box-box clipping points are not).
DIFFERENTIABLE_PAIRS = tuple(p for p in ALL_ORDERED_PAIRS if p != (G.BOX, G.BOX))


def gap_derivative(a, b, which, count):
    """Central differences of the gaps with respect to translating A or B: (count, 3)."""
    step = 1e-6
    derivative = np.empty((count, 3))
    for axis in range(3):
        moved = []
        for sign in (1.0, -1.0):
            shift = np.zeros(3)
            shift[axis] = sign * step
            if which == "b":
                gap = contacts(*a, b[0], b[1], b[2] + shift, b[3])[0]
            else:
                gap = contacts(a[0], a[1], a[2] + shift, a[3], *b)[0]
            assert gap.shape[0] == count
            moved.append(gap)
        derivative[:, axis] = (moved[0] - moved[1]) / (2 * step)
    return derivative


RING_FACE_PAIRS = {(face, ring) for face in (G.PLANE, G.RECTANGLE, G.DISC)
                   for ring in (G.CIRCLE, G.ARC)}


RING_SOLID_PAIRS = {(G.CIRCLE, G.BORE), (G.ARC, G.BORE), (G.CYLINDER, G.BORE),
                    (G.CIRCLE, G.CYLINDER), (G.ARC, G.CYLINDER)}


def kinked_candidates(pair, gap) -> np.ndarray:
    """Candidates whose gap has no derivative: a ring's deepest point INSIDE a face's solid
    (slots 6, 7 of kernels/gaps/ring_faces.py with a negative gap) or inside a bore's or a
    cylinder's solid (a ring's one slot or a journal's end rims with a negative gap,
    kernels/gaps/round_solids.py). Inside, the signed distance is minus the distance to the
    nearest boundary face; along the ring its minimum typically lies where two faces are equally
    near (the ring's deepest point in the corner region of an edge, or level with an end face),
    a corner of the function whose normal is that of one of the two faces, or a flat stretch
    (the same depth below an end face all along)."""
    if pair in RING_SOLID_PAIRS or pair[::-1] in RING_SOLID_PAIRS:
        return gap < 0.0
    if pair not in RING_FACE_PAIRS and pair[::-1] not in RING_FACE_PAIRS:
        return np.zeros(gap.shape[0], dtype=bool)
    return (np.arange(gap.shape[0]) >= 6) & (gap < 0.0)


#: |ring axis . face normal| from which a ring lies on a face (kernels/gaps/ring_faces.py's
#: _LYING, cos 45 deg), and the distance [m] within which a face point is on its bound.
_LYING = math.cos(0.25 * math.pi)
_ON_BOUND = 1e-9


def supports_at_the_bound(pair, a, b, point_a, point_b) -> np.ndarray:
    """Candidates whose point moves along the ring as the bodies move: a lying ring's support
    points (slots 0-5 of kernels/gaps/ring_faces.py) moved to where the ring crosses the face's
    bound, as a box's clipped vertex slides along its edge. Their gap follows the crossing, so
    its derivative is not the normal (it is where the point is the ring against the edge line,
    which these include). Recognised by the face point on the bound of a lying ring's face."""
    count = point_a.shape[0]
    out = np.zeros(count, dtype=bool)
    if pair in RING_FACE_PAIRS:
        face, ring, face_points = a, b, point_a
    elif pair[::-1] in RING_FACE_PAIRS:
        face, ring, face_points = b, a, point_b
    else:
        return out
    kind, parameters, position, rotation = face
    if kind == G.PLANE or abs(rotation[:, 2] @ ring[3][:, 2]) < _LYING:
        return out
    for k in range(min(6, count)):
        x, y, _ = rotation.T @ (face_points[k] - position)
        beyond = (math.hypot(x, y) - parameters[0] if kind == G.DISC
                  else max(abs(x) - parameters[0], abs(y) - parameters[1]))
        out[k] = abs(beyond) <= _ON_BOUND
    return out


@pytest.mark.parametrize("pair", DIFFERENTIABLE_PAIRS, ids=pair_id)
def test_gap_derivative_is_the_normal(pair):
    rng = np.random.default_rng(sum(pair) * 101 + pair[0])
    checked = 0
    for _ in range(25):
        a, b = random_pair(*pair, rng)
        gap, point_a, point_b, frame = contacts(*a, *b)
        normal = frame[:, 0]
        smooth = ~(kinked_candidates(pair, gap)
                   | supports_at_the_bound(pair, a, b, point_a, point_b))
        checked += int(np.count_nonzero(smooth))
        # Central difference, step 1e-6 on O(1) geometry with curvature radius >= 0.2:
        # truncation ~ h^2 / r^2 = 2.5e-11, round-off ~ 3 eps / h = 7e-10. 1e-7 is far above both
        # and far below any wrong-normal error (O(1)).
        assert np.allclose(gap_derivative(a, b, "b", gap.shape[0])[smooth], normal[smooth],
                           atol=1e-7)
        assert np.allclose(gap_derivative(a, b, "a", gap.shape[0])[smooth], -normal[smooth],
                           atol=1e-7)
    assert checked > 0  # not vacuous (a journal's bore drops candidates beyond its bounds)


def test_box_box_corner_gaps_have_the_normal_as_derivative():
    # A small box tilted by 0.1 rad resting inside the top face of a big one: the 4 candidates
    # are the small box's bottom corners (no clipping), each a closest point.
    a = (G.BOX, params(2.0, 2.0, 0.5), np.zeros(3), IDENTITY)
    b = (G.BOX, params(0.3, 0.2, 0.1), np.array([0.1, 0.2, 0.65]),
         rotation((1, 0.5, 0), 0.1) @ rotation((0, 0, 1), 0.3))
    gap, _, _, frame = contacts(*a, *b)
    assert gap.shape[0] == 4
    # Same bound as test_gap_derivative_is_the_normal (flat faces: no truncation term).
    assert np.allclose(gap_derivative(a, b, "b", 4), frame[:, 0], atol=1e-7)
    assert np.allclose(gap_derivative(a, b, "a", 4), -frame[:, 0], atol=1e-7)


# ------------------------------------------------------------------------------------------------
# Bearing ring against journal
# ------------------------------------------------------------------------------------------------


def brute_force_ring_gap(ring_position, ring_rotation, ring_radius, cylinder_position,
                         cylinder_rotation, cylinder_radius, start=0.0, span=2 * math.pi):
    """min over the ring (arc) of distance-to-axis minus radius: 100001 samples, then four
    rounds of 10001-point refinement around the best sample (final bracket ~1e-15 rad), plus
    the arc ends."""
    axis = cylinder_rotation[:, 2]

    def distance(theta):
        points = ring_position + ring_radius * (
            np.cos(theta)[:, None] * ring_rotation[:, 0]
            + np.sin(theta)[:, None] * ring_rotation[:, 1]
        )
        relative = points - cylinder_position
        relative -= (relative @ axis)[:, None] * axis
        return np.linalg.norm(relative, axis=1)

    theta = start + np.linspace(0.0, span, 100001)
    values = distance(theta)
    best = int(np.argmin(values))
    low, high = theta[max(best - 1, 0)], theta[min(best + 1, theta.size - 1)]
    for _ in range(4):
        fine = np.linspace(low, high, 10001)
        fine_values = distance(fine)
        best = int(np.argmin(fine_values))
        low, high = fine[max(best - 1, 0)], fine[min(best + 1, fine.size - 1)]
    ends = distance(np.array([start, start + span]))
    return min(fine_values.min(), ends.min()) - cylinder_radius


@pytest.mark.parametrize("ring_on", ["a", "b"])
@pytest.mark.parametrize("eccentricity", [0.0, 1e-9, 0.03, 0.05, 0.0999, 0.1, 0.15])
def test_bearing_ring_with_parallel_axes_gives_clearance_minus_eccentricity(
    ring_on, eccentricity
):
    bore_radius, journal_radius = 10.0, 9.9  # radial clearance 0.1
    rng = np.random.default_rng(int(eccentricity * 1e4) + (ring_on == "a"))
    axis_rotation = random_rotation(rng)  # the common axis direction, arbitrary
    for _ in range(10):
        direction_angle = rng.uniform(0, 2 * math.pi)
        direction = axis_rotation @ np.array([math.cos(direction_angle),
                                              math.sin(direction_angle), 0.0])
        journal_position = rng.uniform(-5, 5, 3)
        # The ring sits anywhere along the axis, turned by any angle about it.
        ring_rotation = axis_rotation @ rotation((0, 0, 1), rng.uniform(0, 2 * math.pi))
        ring_position = (journal_position + rng.uniform(-3, 3) * axis_rotation[:, 2]
                         - eccentricity * direction)
        ring = (G.CIRCLE, params(bore_radius), ring_position, ring_rotation)
        journal = (G.CYLINDER, params(journal_radius, 4.0), journal_position, axis_rotation)
        pair = (ring, journal) if ring_on == "a" else (journal, ring)
        gap, point_a, point_b, frame = contacts(*pair[0], *pair[1])
        expected = bore_radius - journal_radius - eccentricity
        # Exact up to round-off of positions of size ~20: about 16 ulp of 20 (7e-14); the
        # clearance is 0.1, so this is 1e-12 relative to the clearance.
        assert abs(gap[0] - expected) < 16 * EPS * 20, (gap[0], expected)
        ring_point = point_a[0] if ring_on == "a" else point_b[0]
        if eccentricity >= 0.03:
            # The contact is on the side toward which the journal is displaced. Its angle comes
            # from the eccentricity vector, known to ~1e-14 (positions ~10): angle error
            # 1e-14 / e <= 4e-13, point error 10 x that.
            assert np.allclose(ring_point, ring_position + bore_radius * direction, atol=1e-10)
            sign = 1.0 if ring_on == "a" else -1.0  # n from A toward B
            assert np.allclose(frame[0, 0], -sign * direction, atol=1e-12)


@pytest.mark.parametrize("case", ["internal", "internal_centred", "external"])
def test_tilted_ring_matches_dense_sampling(case):
    rng = np.random.default_rng({"internal": 1, "internal_centred": 2, "external": 3}[case])
    ring_radius = 1.0
    worst = 0.0
    for trial in range(60):
        tilt = math.radians(rng.uniform(0.0, 10.0)) if trial < 50 else math.radians(
            rng.uniform(10.0, 60.0))  # beyond the design range too
        ring_rotation = rotation(rng.normal(size=3), tilt) @ rotation((0, 0, 1),
                                                                     rng.uniform(0, 6.3))
        cylinder_rotation = IDENTITY
        in_plane = rng.normal(size=2)
        in_plane /= np.linalg.norm(in_plane)
        if case == "internal":
            cylinder_radius = 0.98
            eccentricity = 10 ** rng.uniform(-5, math.log10(0.03))
            scale = ring_radius - cylinder_radius  # radial clearance
        elif case == "internal_centred":
            # Tiny eccentricity against the tilt term: two near-equal minima (quartic path).
            cylinder_radius = 0.98
            eccentricity = 10 ** rng.uniform(-12, -4) if trial % 5 else 0.0
            scale = ring_radius - cylinder_radius
        else:
            cylinder_radius = 0.2
            eccentricity = ring_radius + cylinder_radius + rng.uniform(-0.05, 0.1)
            scale = cylinder_radius
        ring_position = np.r_[eccentricity * in_plane, rng.uniform(-0.5, 0.5)]
        # Half length 3: the ring (|z| <= 0.5 + 1) stays within the cylinder's length, where
        # the distance to the axis minus the radius is the gap the sampling computes.
        gap, _, _, _ = contacts(G.CIRCLE, params(ring_radius), ring_position, ring_rotation,
                                G.CYLINDER, params(cylinder_radius, 3.0), np.zeros(3),
                                cylinder_rotation)
        reference = brute_force_ring_gap(ring_position, ring_rotation, ring_radius, np.zeros(3),
                                         cylinder_rotation, cylinder_radius)
        worst = max(worst, abs(gap[0] - reference) / scale)
    # Both are minima of the same distance computed to round-off (~1e-16 of the radius 1);
    # 1e-9 relative to the clearance is the design target.
    assert worst < 1e-9, worst


def test_a_ring_beyond_a_pins_end_is_outside_it():
    # A ring (r 0.2) coaxial with a pin (r 0.5, half length 1), 0.3 past its end: every ring
    # point is 0.3 from the pin's end face (the infinitely long pin would put it 0.3 inside).
    pin = (G.CYLINDER, params(0.5, 1.0), np.zeros(3), IDENTITY)
    ring = (G.CIRCLE, params(0.2), np.array([0.0, 0.0, 1.3]), IDENTITY)
    for first, second in ((ring, pin), (pin, ring)):
        gap = contacts(*first, *second)[0]
        assert abs(gap[0] - 0.3) < 4 * EPS  # differences of O(1) numbers


@pytest.mark.parametrize("kind", ["circle", "arc"])
def test_a_ring_through_a_short_pin_leaves_it_through_the_end_face(kind):
    # The example the property test drew: a ring (r 0.5) through the axis of a pin (r 0.5,
    # half length 0.25) with parallel axes, in the pin's middle plane. Its point on the pin's
    # axis is 0.5 from the lateral surface but 0.25 from either end face: depth 0.25.
    pin = (G.CYLINDER, params(0.5, 0.25), np.array([0.5, 0.0, 0.0]), IDENTITY)
    shape = params(0.5) if kind == "circle" else params(0.5, -1.0, 1.0)
    ring = (G.CIRCLE if kind == "circle" else G.ARC, shape, np.zeros(3), IDENTITY)
    gap, point_a, point_b, frame = contacts(*ring, *pin)
    assert abs(gap[0] + 0.25) < 4 * EPS  # differences of O(1) numbers
    # Every ring point within 0.25 of the pin's axis is that deep (a flat stretch of the
    # depth): the witness is one of them, the normal along the axis (either end face).
    assert np.linalg.norm(point_a[0] - [0.5, 0.0, 0.0]) <= 0.25 + 4 * EPS
    assert np.allclose(np.abs(frame[0, 0]), [0.0, 0.0, 1.0], atol=4 * EPS)


def test_tilted_arcs_match_dense_sampling_including_their_ends():
    rng = np.random.default_rng(11)
    at_end = 0
    for _ in range(60):
        ring_rotation = rotation(rng.normal(size=3), math.radians(rng.uniform(0, 10))) @ rotation(
            (0, 0, 1), rng.uniform(0, 6.3))
        start = rng.uniform(-math.pi, math.pi)
        span = rng.uniform(0.2, 2 * math.pi)
        in_plane = rng.normal(size=2)
        in_plane /= np.linalg.norm(in_plane)
        ring_position = np.r_[10 ** rng.uniform(-6, -1.6) * in_plane, 0.1]
        gap, point_a, _, _ = contacts(G.ARC, params(1.0, start, start + span), ring_position,
                                      ring_rotation, G.CYLINDER, params(0.98, 1.0), np.zeros(3),
                                      IDENTITY)
        reference = brute_force_ring_gap(ring_position, ring_rotation, 1.0, np.zeros(3),
                                         IDENTITY, 0.98, start, span)
        # As in test_tilted_ring_matches_dense_sampling: 1e-9 of the radial clearance 0.02.
        assert abs(gap[0] - reference) < 1e-9 * 0.02
        ends = [ring_position + ring_rotation @ np.array([math.cos(t), math.sin(t), 0.0])
                for t in (start, start + span)]
        # An end point is reproduced to round-off (1e-12 >> ulp of 1, << any arc sampling).
        at_end += any(np.allclose(point_a[0], end, atol=1e-12) for end in ends)
    assert at_end >= 10  # the sample exercises the end-point branch, not only interior minima


def test_arc_excluding_the_nearest_point_returns_its_nearer_end():
    # Journal displaced toward +x: the circle's nearest point is at angle 0. An arc over
    # [pi/4, 3 pi/4] excludes it and must return the end at pi/4 (closer to +x) with the gap of
    # that end point; an arc over [-pi/4, pi/4] contains it and matches the full circle.
    journal = (G.CYLINDER, params(0.9, 1.0), np.array([0.05, 0.0, 0.0]), IDENTITY)
    end_gap = math.hypot(math.cos(math.pi / 4) - 0.05, math.sin(math.pi / 4)) - 0.9
    gap, point_a, _, _ = contacts(G.ARC, params(1.0, math.pi / 4, 3 * math.pi / 4), np.zeros(3),
                                  IDENTITY, *journal)
    assert abs(gap[0] - end_gap) < 8 * EPS  # closed form of one end point
    assert np.allclose(point_a[0], [math.cos(math.pi / 4), math.sin(math.pi / 4), 0.0],
                       atol=4 * EPS)  # one cos / sin of the end angle
    full = contacts(G.CIRCLE, params(1.0), np.zeros(3), IDENTITY, *journal)[0]
    inside = contacts(G.ARC, params(1.0, -math.pi / 4, math.pi / 4), np.zeros(3), IDENTITY,
                      *journal)[0]
    assert abs(full[0] - (1.0 - 0.9 - 0.05)) < 8 * EPS  # parallel axes: exact to a few ulp
    assert inside[0] == full[0]  # same minimiser, same arithmetic


def test_arc_plane_returns_the_lower_end_when_the_lowest_point_is_outside():
    # Upright circle: turned 90 degrees about x, its x axis stays along x and its y axis points
    # up (+z), so the point at angle t is sin(t) radii above the centre; lowest at t = -pi/2.
    # An arc over [0, 2] excludes it: the lower end is t = 0 (at the centre's height), the
    # arc's first support point. Bounds: 4 ulp, one sine / cosine of the angle and a sum.
    upright = rotation((1, 0, 0), math.pi / 2)
    gap, _, point_b, _ = contacts(G.PLANE, params(), np.zeros(3), IDENTITY, G.ARC,
                                  params(0.5, 0.0, 2.0), np.array([0.0, 0.0, 1.0]), upright)
    lowest = int(np.argmin(gap))
    assert abs(gap[lowest] - 1.0) < 4 * EPS
    assert np.allclose(point_b[lowest], [0.5, 0.0, 1.0], atol=4 * EPS)
    # [1.5, 4]: height sin(4) = -0.757 < sin(1.5): the end at t = 4.
    gap = contacts(G.PLANE, params(), np.zeros(3), IDENTITY, G.ARC, params(0.5, 1.5, 4.0),
                   np.array([0.0, 0.0, 1.0]), upright)[0]
    assert abs(gap.min() - (1.0 + 0.5 * math.sin(4.0))) < 4 * EPS
    # An arc that contains -pi/2 (as 3 pi/2) returns the true lowest point (minimised over the
    # angle: the gap, quadratic there, to round-off).
    gap = contacts(G.PLANE, params(), np.zeros(3), IDENTITY, G.ARC, params(0.5, 1.0, 5.0),
                   np.array([0.0, 0.0, 1.0]), upright)[0]
    assert abs(gap.min() - 0.5) < 4 * EPS


# ------------------------------------------------------------------------------------------------
# Boxes
# ------------------------------------------------------------------------------------------------


def test_box_stack_returns_the_four_bottom_corners_of_the_small_box():
    turn = rotation((0, 0, 1), 0.5)
    small = (G.BOX, params(0.3, 0.2, 0.1), np.array([0.2, -0.3, 0.6 + 1e-3]), turn)
    big = (G.BOX, params(1.0, 1.0, 0.5), np.zeros(3), IDENTITY)
    for order in ((big, small), (small, big)):
        gap, point_a, point_b, frame = contacts(*order[0], *order[1])
        assert gap.shape[0] == 4
        assert np.allclose(gap, 1e-3, atol=32 * EPS)  # positions O(1): a few ulp
        corners = {tuple(np.round(small[2] + turn @ (np.array([sx * 0.3, sy * 0.2, -0.1])), 12))
                   for sx in (-1, 1) for sy in (-1, 1)}
        small_points = point_b if order[0] is big else point_a
        assert {tuple(np.round(p, 12)) for p in small_points} == corners


def test_crossed_boxes_get_the_four_corners_of_their_overlap():
    # Two long beams crossed at right angles (Lincoln logs): no corner of either lies over the
    # other's face; the contact patch is the 0.2 x 0.2 square of the overlap.
    a = (G.BOX, params(1.0, 0.1, 0.1), np.zeros(3), IDENTITY)
    b = (G.BOX, params(0.1, 1.0, 0.1), np.array([0.0, 0.0, 0.2 - 1e-3]), IDENTITY)
    gap, point_a, point_b, frame = contacts(*a, *b)
    assert gap.shape[0] == 4
    # Positions O(1), a few operations: 32 ulp.
    assert np.allclose(gap, -1e-3, atol=32 * EPS)
    assert np.allclose(np.sort(np.abs(point_b[:, :2]).ravel()), 0.1, atol=32 * EPS)
    assert np.allclose(frame[:, 0], [0, 0, 1], atol=0)  # A's z axis, exactly (identity)


@pytest.mark.parametrize("gap0", GAPS)
def test_crossed_edges_give_one_edge_edge_contact(gap0):
    # Cube A turned 45 degrees about x: its top is an edge along x at height sqrt(2)/2. Cube B
    # turned 45 degrees about y: its bottom is an edge along y. Crossed edges: one contact at
    # the origin's vertical, gap = height difference.
    half = 0.5
    top = half * math.sqrt(2.0)
    a = (G.BOX, params(half, half, half), np.zeros(3), rotation((1, 0, 0), math.pi / 4))
    b = (G.BOX, params(half, half, half), np.array([0.1, -0.05, 2 * top + gap0]),
         rotation((0, 1, 0), math.pi / 4))
    gap, point_a, point_b, frame = contacts(*a, *b)
    assert gap.shape[0] == 1
    assert abs(gap[0] - gap0) < 32 * EPS  # sqrt(2) products on O(1) numbers
    assert np.allclose(frame[0, 0], [0, 0, 1], atol=1e-15)  # cross product of two unit axes
    assert np.allclose(point_a[0], [0.1, 0.0, top], atol=32 * EPS)  # as the gap
    assert np.allclose(point_b[0], [0.1, 0.0, top + gap0], atol=32 * EPS)


def test_box_on_its_edge_has_its_lowest_candidates_on_that_edge():
    # Small box turned 30 degrees about x, lowest edge 1e-3 above the big box's top face.
    turn = rotation((1, 0, 0), math.radians(30))
    corner_drop = 0.2 * math.sin(math.radians(30)) + 0.1 * math.cos(math.radians(30))
    small = (G.BOX, params(0.3, 0.2, 0.1), np.array([0.0, 0.0, 0.5 + corner_drop + 1e-3]), turn)
    big = (G.BOX, params(1.0, 1.0, 0.5), np.zeros(3), IDENTITY)
    gap = np.sort(contacts(*big, *small)[0])
    assert np.allclose(gap[:2], 1e-3, atol=32 * EPS)  # sines of 30 degrees on O(1) numbers
    assert gap[2] > 1e-3 + 0.1  # the other candidates are well above (0.2 by construction)


@pytest.mark.parametrize("tilt", [0.6, 0.3])
def test_separated_boxes_read_their_distance_past_the_reference_faces_bound(tilt):
    # A plate (half 1 x 1 x 0.1) turned ``tilt`` rad about x, beside and above a cube's top
    # edge (y = 1, z = 1), both 2 long in x: a problem of the (y, z) section, whose distance is
    # the smallest of each section corner's distance to the other section (two convex
    # polygons). The nearest points lie past the cube's top face, where face clipping reads only
    # farther points (at 0.6 rad a height of 0.0804 for a distance of 0.0705; at 0.3 rad no
    # candidate at all).
    cube = (G.BOX, params(1.0, 1.0, 1.0), np.zeros(3), IDENTITY)
    centre = np.array([1.95, 1.5])
    plate = (G.BOX, params(1.0, 1.0, 0.1), np.array([0.0, *centre]), rotation((1, 0, 0), tilt))
    along = np.array([math.cos(tilt), math.sin(tilt)])  # the plate's y axis in the section
    across = np.array([-math.sin(tilt), math.cos(tilt)])  # its z axis
    signs = [(-1, -1), (-1, 1), (1, -1), (1, 1)]
    plate_corners = [centre + sy * along + 0.1 * sz * across for sy, sz in signs]
    cube_corners = [np.array(corner, dtype=float) for corner in signs]
    to_cube = min(np.linalg.norm(p - np.clip(p, -1.0, 1.0)) for p in plate_corners)
    to_plate = min(np.linalg.norm(
        (p - centre) @ np.column_stack([along, across])
        - np.clip((p - centre) @ np.column_stack([along, across]), [-1.0, -0.1], [1.0, 0.1]))
        for p in cube_corners)
    distance = min(to_cube, to_plate)
    for first, second in ((cube, plate), (plate, cube)):
        gap, point_a, point_b, frame = contacts(*first, *second)
        assert abs(gap.min() - distance) < 32 * EPS  # sines on O(1) numbers: a few ulp
        nearest = np.argmin(gap)
        cube_point = point_a[nearest] if first is cube else point_b[nearest]
        # The cube's nearest point is its top edge (y = z = 1; the plate's corner clamps there).
        assert np.allclose(cube_point[1:], 1.0, atol=32 * EPS)


def test_boxes_side_by_side_diagonally_read_their_corners_distance():
    # Unturned cubes offset along x, y and z: no point of either lies over a face of the other
    # (face clipping keeps nothing); the nearest points are the facing corners.
    offset = np.array([0.2, 0.1, 0.3])
    a = (G.BOX, params(1.0, 1.0, 1.0), np.zeros(3), IDENTITY)
    b = (G.BOX, params(1.0, 1.0, 1.0), 2.0 + offset, IDENTITY)
    gap, point_a, point_b, frame = contacts(*a, *b)
    assert gap.shape[0] == 1
    assert abs(gap[0] - np.linalg.norm(offset)) < 4 * EPS  # sums of O(1) numbers
    assert np.allclose(point_a[0], 1.0, atol=4 * EPS)
    assert np.allclose(frame[0, 0], offset / np.linalg.norm(offset), atol=4 * EPS)


# ------------------------------------------------------------------------------------------------
# Cylinders and capsules lying and standing on planes
# ------------------------------------------------------------------------------------------------


def test_standing_cylinder_gets_four_support_points_on_its_bottom_rim():
    gap, _, point_b, _ = contacts(G.PLANE, params(), np.zeros(3), IDENTITY, G.CYLINDER,
                                  params(0.4, 1.0), np.array([0.0, 0.0, 1.0]), IDENTITY)
    bottom = np.isclose(gap, 0.0, atol=4 * EPS)  # rim heights: exact sums of O(1) numbers
    assert bottom.sum() == 4
    spread = point_b[bottom][:, :2]
    # Four points 90 degrees apart on the rim: a stable support polygon (a square of side
    # 0.4 sqrt(2) centred on the axis).
    assert np.allclose(spread.mean(axis=0), 0.0, atol=4 * EPS)  # exact up to a few ulp
    assert np.allclose(np.linalg.norm(spread, axis=1), 0.4, atol=4 * EPS)  # likewise


def test_lying_cylinder_has_its_two_support_points_first():
    tilt = rotation((0, 1, 0), math.pi / 2 + 0.01)  # slightly tipped
    gap = contacts(G.PLANE, params(), np.zeros(3), IDENTITY, G.CYLINDER, params(0.4, 1.0),
                   np.array([0.0, 0.0, 2.0]), tilt)[0]
    assert gap[0] == gap.min() or gap[1] == gap.min()
    assert np.all(gap[2:] >= min(gap[0], gap[1]))


# ------------------------------------------------------------------------------------------------
# Python side
# ------------------------------------------------------------------------------------------------


def test_contacts_between_composes_body_and_shape_placements():
    quarter_turn_x = tuple(quat_from_axis_angle(np.array([1.0, 0.0, 0.0]), math.pi / 2))
    ball = Sphere("ball", radius=0.5, position=(0.0, 1.0, 0.0))
    # Body at (0, 0, 2) turned 90 degrees about x: the ball's body offset (0, 1, 0) becomes
    # (0, 0, 1) in world, so its centre is at height 3.
    ball_pose = ((0.0, 0.0, 2.0), quarter_turn_x)
    floor = Plane("floor")
    # A ceiling: a plane shape turned upside down, on a body at height 5.
    ceiling = Plane("ceiling", orientation=(0.0, 1.0, 0.0, 0.0))
    identity_pose = ((0.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0))
    result = G.contacts_between(floor, identity_pose, ball, ball_pose)
    assert result.count == 1 and len(result) == 1
    assert abs(result.gap[0] - 2.5) < 8 * EPS  # quaternion products of exact halves
    assert np.allclose(result.normal[0], [0, 0, 1], atol=4 * EPS)  # identity plane axis
    roof = G.contacts_between(ball, ball_pose, ceiling, ((0.0, 0.0, 5.0), (1.0, 0.0, 0.0, 0.0)))
    assert abs(roof.gap[0] - 1.5) < 8 * EPS  # as above
    assert np.allclose(roof.normal[0], [0, 0, 1], atol=4 * EPS)  # from the ball up to the roof
    with pytest.raises(ValueError):
        roof.gap[0] = 0.0  # results are read-only


def test_pack_shape_parameters_layout():
    assert np.array_equal(G.pack_shape_parameters(Sphere("s", radius=2.0))[:2], [2.0, 0.0])
    assert np.array_equal(G.pack_shape_parameters(Box("b", half_extents=(1, 2, 3)))[:4],
                          [1, 2, 3, 0])
    assert np.array_equal(G.pack_shape_parameters(Capsule("c", radius=1, half_length=2))[:2],
                          [1, 2])
    assert np.array_equal(G.pack_shape_parameters(Cylinder("c", radius=1, half_length=2))[:2],
                          [1, 2])
    assert np.array_equal(G.pack_shape_parameters(Plane("p")), np.zeros(G.PARAMETER_COUNT))
    assert np.array_equal(G.pack_shape_parameters(Circle("c", radius=3))[:1], [3])
    arc = Arc("a", radius=3, start_angle=-1.0, end_angle=2.0)
    assert np.array_equal(G.pack_shape_parameters(arc)[:3], [3, -1, 2])
    for shape in (Sphere("s"), Box("b"), Plane("p"), Arc("a")):
        assert G.pack_shape_parameters(shape).shape == (G.PARAMETER_COUNT,)
        assert G.shape_code(shape) == G.SHAPE_CODES[shape.kind]


def test_unsupported_pairs_are_refused_with_both_kinds_named():
    with pytest.raises(ValueError, match="plane-plane"):
        G.check_supported_pair(Plane("a"), Plane("b"))
    with pytest.raises(G.UnsupportedPairError, match="box-cylinder") as error:
        G.contacts_between(Box("b"), ((0, 0, 0), (1, 0, 0, 0)), Cylinder("c"),
                           ((0, 0, 3), (1, 0, 0, 0)))
    assert error.value.kind_a == "box" and error.value.kind_b == "cylinder"
    assert not G.supported_pair("circle", "sphere")
    assert G.supported_pair("cylinder", "arc") and G.supported_pair(G.ARC, G.CYLINDER)
    # The compiled kernel refuses too (never a silent zero).
    with pytest.raises(ValueError, match="unsupported"):
        contacts(G.CAPSULE, params(0.1, 1), np.zeros(3), IDENTITY, G.BOX, params(1, 1, 1),
                 np.ones(3), IDENTITY)
    with pytest.raises(ValueError, match="unknown shape kind"):
        G.supported_pair("torus", "plane")


def test_supported_table_is_symmetric_and_lists_every_required_pair():
    required = ["sphere-plane", "sphere-sphere", "sphere-box", "box-plane", "box-box",
                "capsule-plane", "cylinder-plane", "capsule-capsule", "circle-cylinder",
                "circle-plane", "arc-plane", "arc-cylinder", "sphere-cylinder", "sphere-capsule"]
    for name in required:
        a, b = name.split("-")
        assert G.supported_pair(a, b) and G.supported_pair(b, a), name
    kinds = list(G.SHAPE_CODES)
    for a, b in itertools.product(kinds, kinds):
        assert G.supported_pair(a, b) == G.supported_pair(b, a)
