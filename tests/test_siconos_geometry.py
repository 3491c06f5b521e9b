"""The Siconos worker's contact geometry is the project's gap kernels, one slot per candidate.

The worker (adapters/siconos/worker/geometry.py) keeps only what is Siconos's own: the pairs it
supports with a fixed number of slots (one Siconos interaction each) and the gap of a dropped
slot; gaps, points and frames come from :func:`clearbench.kernels.gaps.pair_contact_slots`.
These tests run in the project's environment (no Siconos needed) on random configurations of
every supported pair, in both orders: each pair fills exactly its declared number of slots, and
the kept slots, in order, are the shared geometry's (compacted) candidates. That the kernels give
the same numbers without numba (the worker's interpreter) is tests/test_kernels_without_numba.py.
"""

from __future__ import annotations

import inspect
import math

import numpy as np
import pytest

from clearbench.adapters.siconos.worker import geometry as worker
from clearbench.kernels import gaps
from clearbench.kernels.quaternion import quat_normalize, quat_to_matrix
from clearbench.scenarios import geometry as shared

# 1e-12 [m] on configurations of size ~1 m: a few hundred ulp. Both sides run the same compiled
# operations in the same order (the slot form only skips the compaction), so they agree far
# below this bound.
TOLERANCE = 1e-12


def _random_parameters(kind: str, rng) -> list[float]:
    if kind == "sphere":
        return [rng.uniform(0.05, 0.3)]
    if kind == "box":
        return list(rng.uniform(0.05, 0.4, size=3))
    if kind in ("capsule", "cylinder"):
        return [rng.uniform(0.02, 0.2), rng.uniform(0.05, 0.5)]
    if kind == "plane":
        return []
    if kind == "circle":
        return [rng.uniform(0.05, 0.3)]
    if kind == "rectangle":  # [hx, hy, depth], depth 0 (unbounded) one time in three
        return [*rng.uniform(0.1, 0.5, size=2), rng.choice([0.0, rng.uniform(0.05, 0.3),
                                                            rng.uniform(0.05, 0.3)])]
    if kind == "disc":
        return [rng.uniform(0.1, 0.5), rng.choice([0.0, rng.uniform(0.05, 0.3)])]
    if kind == "bore":  # a full bore one time in two, else a patch of it
        start = rng.uniform(-math.pi, math.pi)
        span = 2 * math.pi if rng.uniform() < 0.5 else rng.uniform(0.5, 2 * math.pi)
        return [rng.uniform(0.2, 0.4), rng.uniform(0.05, 0.5), start, start + span]
    start = rng.uniform(-math.pi, math.pi)
    return [rng.uniform(0.05, 0.3), start, start + rng.uniform(0.2, 2 * math.pi)]


def _random_rotation(rng) -> np.ndarray:
    return quat_to_matrix(quat_normalize(rng.normal(size=4)))


def _ring_journal_configuration(rng, ring_kind: str, ring_first: bool):
    """A journal near the inside of a ring (the clearance-joint case), small tilt."""
    journal_radius = rng.uniform(0.005, 0.02)
    ring = _random_parameters(ring_kind, rng)
    ring[0] = journal_radius + rng.uniform(1e-5, 1e-3)
    rotation = _random_rotation(rng)
    tilt = quat_to_matrix(quat_normalize(np.r_[1.0, rng.normal(scale=0.02, size=3)]))
    journal = ([journal_radius, 0.05], rng.normal(scale=1e-3, size=3), rotation @ tilt)
    ring_shape = (ring, rng.normal(scale=1e-3, size=3), rotation)
    return ring_shape, journal


def _compare(kind_a, shape_a, kind_b, shape_b):
    params_a, position_a, rotation_a = shape_a
    params_b, position_b, rotation_b = shape_b
    packed_a = np.zeros(shared.PARAMETER_COUNT)
    packed_a[:len(params_a)] = params_a
    packed_b = np.zeros(shared.PARAMETER_COUNT)
    packed_b[:len(params_b)] = params_b
    k = shared.MAX_CONTACTS_PER_PAIR
    gap, point_a, point_b, frame = np.empty(k), np.empty((k, 3)), np.empty((k, 3)), \
        np.empty((k, 3, 3))
    count = shared.pair_contacts(shared.shape_code(kind_a), packed_a, np.asarray(position_a),
                                 np.ascontiguousarray(rotation_a), shared.shape_code(kind_b),
                                 packed_b, np.asarray(position_b),
                                 np.ascontiguousarray(rotation_b), gap, point_a, point_b, frame)
    slots = worker.pair_contact_slots(worker.packed_shape(kind_a, params_a), position_a,
                                      rotation_a, worker.packed_shape(kind_b, params_b),
                                      position_b, rotation_b)
    # One slot per candidate the kernel can return; the kept slots, in order, are the shared
    # geometry's (compacted) candidates.
    assert all(len(values) == worker.candidate_count(kind_a, kind_b) for values in slots)
    kept = slots[4]
    assert count == int(np.sum(kept))
    if not worker.drops_candidates(kind_a, kind_b):
        assert count == worker.candidate_count(kind_a, kind_b)
    np.testing.assert_allclose(slots[0][kept], gap[:count], rtol=0, atol=TOLERANCE)
    np.testing.assert_allclose(slots[1][kept], point_a[:count], rtol=0, atol=TOLERANCE)
    np.testing.assert_allclose(slots[2][kept], point_b[:count], rtol=0, atol=TOLERANCE)
    # Frames are dimensionless: 1e-12 is ~5000 ulp.
    np.testing.assert_allclose(slots[3][kept], frame[:count], rtol=0, atol=TOLERANCE)
    return count, slots


PAIRS = sorted(worker.CANONICAL_PAIRS)
BOUNDED_PAIRS = [pair for pair in PAIRS if worker.drops_candidates(*pair)]


@pytest.mark.parametrize("pair", PAIRS, ids=[f"{a}-{b}" for a, b in PAIRS])
@pytest.mark.parametrize("swapped", [False, True], ids=["canonical", "swapped"])
def test_worker_slots_are_the_shared_geometry(pair, swapped):
    kind_a, kind_b = pair
    rng = np.random.default_rng(2 * PAIRS.index(pair) + int(swapped))
    for trial in range(200):
        if kind_b == "cylinder" and kind_a in ("circle", "arc") and trial % 2 == 0:
            shape_a, shape_b = _ring_journal_configuration(rng, kind_a, True)
        else:
            shape_a = (_random_parameters(kind_a, rng), rng.normal(scale=0.3, size=3),
                       _random_rotation(rng))
            shape_b = (_random_parameters(kind_b, rng), rng.normal(scale=0.3, size=3),
                       _random_rotation(rng))
        if swapped:
            _compare(kind_b, shape_b, kind_a, shape_a)
        else:
            _compare(kind_a, shape_a, kind_b, shape_b)


def _bounded_configuration(kind_a, kind_b, rng):
    """A face (A) with its partner (B) over it, beside it, or behind its depth; or a ring or
    journal (A) inside a bore (B), within its length or beyond it. Canonical order."""
    rotation_a = _random_rotation(rng)
    if kind_b == "bore":
        bore = _random_parameters("bore", rng)
        tilt = quat_to_matrix(quat_normalize(np.r_[1.0, rng.normal(scale=0.1, size=3)]))
        inner = _random_parameters(kind_a, rng)
        inner[0] = bore[0] - rng.uniform(0.0, 0.05)
        offset = rotation_a @ np.r_[rng.uniform(-0.05, 0.05, 2),
                                    rng.uniform(-1.6, 1.6) * bore[1]]
        return (inner, offset, rotation_a @ tilt), (bore, np.zeros(3), rotation_a)
    face = _random_parameters(kind_a, rng)
    reach = np.r_[face[0], face[1]] if kind_a == "rectangle" else np.r_[face[0], face[0]]
    other = _random_parameters(kind_b, rng)
    local = np.r_[rng.uniform(-1.3, 1.3, 2) * reach, rng.uniform(-0.5, 0.6)]
    return (face, np.zeros(3), rotation_a), (other, rotation_a @ local, _random_rotation(rng))


@pytest.mark.parametrize("pair", BOUNDED_PAIRS, ids=[f"{a}-{b}" for a, b in BOUNDED_PAIRS])
@pytest.mark.parametrize("swapped", [False, True], ids=["canonical", "swapped"])
def test_bounded_face_and_bore_slots_match_shared_geometry(pair, swapped):
    kind_a, kind_b = pair
    rng = np.random.default_rng(100 + 2 * BOUNDED_PAIRS.index(pair) + int(swapped))
    kept = dropped = 0
    for _ in range(300):
        shape_a, shape_b = _bounded_configuration(kind_a, kind_b, rng)
        if swapped:
            count, slots = _compare(kind_b, shape_b, kind_a, shape_a)
        else:
            count, slots = _compare(kind_a, shape_a, kind_b, shape_b)
        kept += count
        dropped += len(slots[4]) - count
        # Every slot, dropped or not, carries a finite gap and an orthonormal frame (a Siconos
        # interaction evaluates its Jacobian whatever the slot holds); 1e-12: round-off.
        assert np.all(np.isfinite(slots[0]))
        for frame in slots[3]:
            np.testing.assert_allclose(frame @ frame.T, np.eye(3), rtol=0, atol=1e-12)
    # The configurations exercise both branches of the bound.
    assert kept > 0 and dropped > 0


def test_the_worker_takes_its_geometry_from_the_kernels():
    # The worker's module defines only the Siconos-specific functions; every formula (gaps,
    # frames, quaternions) is the kernels'.
    own = {name for name, function in inspect.getmembers(worker, inspect.isfunction)
           if function.__module__ == worker.__name__}
    assert own == {"candidate_count", "drops_candidates", "unsupported_reason", "packed_shape",
                   "pair_contact_slots"}
    assert worker.gaps is gaps
    assert worker.SHAPE_KINDS == gaps.SHAPE_KIND_NAMES


def test_a_journal_beside_its_bore_keeps_its_near_rim_and_drops_the_same_contact_twice():
    bore = worker.packed_shape("bore", [0.2, 0.1, 0.0, 2.0 * math.pi])
    journal = worker.packed_shape("cylinder", [0.19, 0.05])
    # The journal's centre 1 m along the bore axis: no axial overlap (half-lengths 0.1, 0.05).
    gap, point_a, _, frame, kept = worker.pair_contact_slots(
        journal, np.array([0.0, 0.0, 1.0]), np.eye(3), bore, np.zeros(3), np.eye(3))
    assert kept.tolist() == [True, False]
    # Slot 0: the journal's near end rim (r 0.19, z 0.95) against the bore's solid, nearest
    # its end rim (r 0.2, z 0.1); a few ulp of O(1) numbers.
    assert abs(gap[0] - math.hypot(0.01, 0.85)) < 1e-15
    # Slot 1: the bore's end rim against the journal's solid, met at the same point of the
    # journal's rim: the same contact, staged and not kept (so no solver is given it twice).
    # 1e-9 m: the two searches' agreement on points of O(0.1 m) (SAME_CONTACT is 1e-6 of the
    # radius, 1.9e-7 m here).
    assert abs(gap[1] - gap[0]) < 1e-9
    np.testing.assert_allclose(point_a[1], point_a[0], rtol=0, atol=1e-9)
    for one in frame:
        np.testing.assert_allclose(one @ one.T, np.eye(3), rtol=0, atol=1e-15)


def test_unported_pairs_have_reasons():
    for kind_a, kind_b in (("box", "box"), ("capsule", "capsule")):
        assert worker.candidate_count(kind_a, kind_b) is None
        assert "Siconos" in worker.unsupported_reason(kind_a, kind_b)
    assert worker.unsupported_reason("plane", "box") == ""
    assert worker.unsupported_reason("bore", "cylinder") == ""
    assert worker.unsupported_reason("rectangle", "box") != ""
