"""The Siconos worker's plain-numpy geometry agrees with the shared geometry module.

The worker runs under Debian's Python without numba, so it carries its own copy of the
formulas (adapters/siconos_worker_geometry.py). These tests run in the project's environment
(no Siconos needed) and compare both on random configurations of every pair the worker supports,
in both orders.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from clearbench.adapters import siconos_worker_geometry as worker
from clearbench.scenarios import geometry as shared
from clearbench.scenarios.quaternion import quat_normalize, quat_to_matrix

# 1e-12 [m] on configurations of size ~1 m: a few hundred ulp. Both sides run the same
# operations in the same order; differences come only from libm/np.roots round-off (the ring
# stationary angles are polished by Newton steps, so they agree far below this bound).
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
    w_gap, w_point_a, w_point_b, w_frame = worker.pair_contacts(
        kind_a, params_a, position_a, rotation_a, kind_b, params_b, position_b, rotation_b)
    assert len(w_gap) == count == worker.candidate_count(kind_a, kind_b)
    np.testing.assert_allclose(w_gap, gap[:count], rtol=0, atol=TOLERANCE)
    np.testing.assert_allclose(w_point_a, point_a[:count], rtol=0, atol=TOLERANCE)
    np.testing.assert_allclose(w_point_b, point_b[:count], rtol=0, atol=TOLERANCE)
    # Frames are dimensionless: 1e-12 is ~5000 ulp.
    np.testing.assert_allclose(w_frame, frame[:count], rtol=0, atol=TOLERANCE)


PAIRS = sorted(worker.CANONICAL_PAIRS)


@pytest.mark.parametrize("pair", PAIRS, ids=[f"{a}-{b}" for a, b in PAIRS])
@pytest.mark.parametrize("swapped", [False, True], ids=["canonical", "swapped"])
def test_worker_geometry_matches_shared_geometry(pair, swapped):
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


def test_worker_frame_matches_shared_frame_everywhere():
    rng = np.random.default_rng(7)
    normals = rng.normal(size=(2000, 3))
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    # Include the pole, the singular direction and the axes.
    extra = [shared.FRAME_POLE, shared.FRAME_SINGULAR_DIRECTION, (1, 0, 0), (0, -1, 0),
             (0, 0, 1), (0, 0, -1)]
    for normal in list(normals) + [np.asarray(e, dtype=float) for e in extra]:
        # Dimensionless, orthonormal rows: 1e-14 is ~50 ulp.
        np.testing.assert_allclose(worker.contact_frame(normal), shared.contact_frame(normal),
                                   rtol=0, atol=1e-14)


def test_unported_pairs_have_reasons():
    for kind_a, kind_b in (("box", "box"), ("capsule", "capsule")):
        assert worker.candidate_count(kind_a, kind_b) is None
        assert "Siconos" in worker.unsupported_reason(kind_a, kind_b)
    assert worker.unsupported_reason("plane", "box") == ""
