"""The batch gap of a pair over many configurations (what the harness measures trajectories
with) against the one-configuration geometry, on every pair of every library scene."""

from __future__ import annotations

import math

import numpy as np
import pytest

from clearbench.scenarios.geometry import (
    contacts_between,
    enclosing_ring_gap,
    ring_encloses_axis,
    smallest_gaps,
)
from clearbench.scenarios.library import get_scene, scene_names
from clearbench.scenarios.scales import scene_size

#: Configurations per pair: the scene's initial poses, then bodies moved and turned at random.
CONFIGURATIONS = 6


def one_at_a_time(shape_a, pose_a, shape_b, pose_b, encloses: bool) -> float:
    """The smallest gap at one configuration from :func:`contacts_between` (inf without a
    candidate), a ring around its journal counted through its wall beyond it."""
    found = contacts_between(shape_a, pose_a, shape_b, pose_b)
    if not len(found.gap):
        return math.inf
    gap = float(np.min(found.gap))
    if encloses:
        cylinder = shape_a if shape_a.kind == "cylinder" else shape_b
        gap = enclosing_ring_gap(gap, cylinder.radius,
                                 ring_encloses_axis(shape_a, pose_a, shape_b, pose_b))
    return gap


def random_poses(body, size: float, rng) -> tuple[np.ndarray, np.ndarray]:
    """(CONFIGURATIONS, 3) positions and (CONFIGURATIONS, 4) quaternions: the initial pose,
    then moved by up to 5 % of the scene's size and turned by up to 0.3 rad."""
    positions = np.array(body.position, float) + rng.uniform(-0.05, 0.05,
                                                             (CONFIGURATIONS, 3)) * size
    turn = rng.normal(size=(CONFIGURATIONS, 3))
    turn *= rng.uniform(0.0, 0.15, (CONFIGURATIONS, 1)) / np.linalg.norm(turn, axis=1,
                                                                          keepdims=True)
    half_turns = np.column_stack([np.cos(np.linalg.norm(turn, axis=1)),
                                  np.sin(np.linalg.norm(turn, axis=1))[:, None]
                                  * turn / np.linalg.norm(turn, axis=1, keepdims=True)])
    w0, v0 = float(body.orientation[0]), np.array(body.orientation[1:], float)
    w1, v1 = half_turns[:, 0], half_turns[:, 1:]
    quaternions = np.column_stack([w1 * w0 - v1 @ v0,
                                   w1[:, None] * v0 + w0 * v1 + np.cross(v1, v0)])
    positions[0], quaternions[0] = body.position, body.orientation
    return positions, quaternions


@pytest.mark.parametrize("name", scene_names())
def test_the_batch_gap_is_the_one_configuration_gap(name):
    scene = get_scene(name)
    expanded = scene.expanded
    index = {body.name: i for i, body in enumerate(expanded.bodies)}
    size = scene_size(scene)
    rng = np.random.default_rng(7)
    poses = [random_poses(body, size, rng) for body in expanded.bodies]
    for contact in expanded.contacts:
        a, b = index[contact.body_a], index[contact.body_b]
        shape_a = expanded.bodies[a].shape(contact.shape_a)
        shape_b = expanded.bodies[b].shape(contact.shape_b)
        encloses = bool(ring_encloses_axis(
            shape_a, (expanded.bodies[a].position, expanded.bodies[a].orientation),
            shape_b, (expanded.bodies[b].position, expanded.bodies[b].orientation)))
        batch = smallest_gaps(shape_a, poses[a], shape_b, poses[b], encloses)
        single = [one_at_a_time(shape_a, (poses[a][0][t], poses[a][1][t]), shape_b,
                                (poses[b][0][t], poses[b][1][t]), encloses)
                  for t in range(CONFIGURATIONS)]
        # the same candidates (inf where there is none); the gaps equal to round-off of the
        # placements, which the batch computes vectorised: 1e-12 of the scene's size is
        # about 4,500 ulps of a coordinate at the scene's size
        assert np.array_equal(np.isinf(batch), np.isinf(single)), contact.name
        finite = np.isfinite(batch)
        np.testing.assert_allclose(batch[finite], np.array(single)[finite], rtol=0,
                                   atol=1e-12 * size, err_msg=contact.name)
