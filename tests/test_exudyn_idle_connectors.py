"""Exudyn's idle contact connectors switched off between steps (``cull_idle_connectors``).

The claim is exactness: an idle connector adds zeros, so a run with the idle ones off equals
the run with all of them on bit for bit, Newton iterations included. Checked on ``c60-on``
through its first clearance closures; the gap bound under it is checked against the exact
sphere-triangle distance, and the margin's after-the-fact check against a synthetic breach.

Cost: about 20 s on two shared cores (50 us of ``c60-on`` twice; the run with every connector
on is the expensive one).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from clearbench.adapters.base import RunSettings
from clearbench.adapters.exudyn import create
from clearbench.adapters.exudyn.geometry import ConnectorPlan, PairPlan
from clearbench.adapters.exudyn.idle_connectors import (
    MIN_CONNECTORS,
    IdleConnectors,
    culling_wanted,
)
from clearbench.adapters.exudyn.settings import resolve_settings
from clearbench.adapters.trajectory import RunStatus
from clearbench.kernels.quaternion import quat_to_matrix_batch
from clearbench.scenarios.bodies import Body, Motion
from clearbench.scenarios.contacts import ContactPair
from clearbench.scenarios.library import get_scene
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.shapes import Sphere

warnings.filterwarnings("ignore", category=DeprecationWarning)

COMPARED = ("times", "positions", "orientations", "velocities", "angular_velocities",
            "contact_normal_force", "contact_force", "solver_iterations", "solver_residual",
            "active_contacts")


def test_culled_c60_on_equals_the_run_with_every_connector_bit_for_bit():
    """50 us of c60-on at 1 us, every step recorded: the journals' first clearances close
    from 34 us on (contacts switch, steps are reduced), so connectors go off and on again."""
    scene = get_scene("c60-on")
    runs = {choice: create("mechanism").run(scene, RunSettings(
        horizon=0.05, options={"cull_idle_connectors": choice})) for choice in ("on", "off")}
    culled, full = runs["on"], runs["off"]
    assert culled.status is RunStatus.OK and full.status is RunStatus.OK, \
        (culled.message, full.message)
    for name in COMPARED:
        # Exact equality: an idle connector contributes +0.0 to every residual and Jacobian
        # entry, and is on again a step before it can touch; any difference is a defect.
        assert np.array_equal(getattr(culled, name), getattr(full, name), equal_nan=True), name
    assert culled.active_contacts.max() > 0  # contacts did close in the span
    idle = culled.metadata["solver_statistics"]["idle_connectors"]
    assert idle["margin_breaches"] == 0, idle["breach_examples"]
    # Most of the 1298 connectors are idle here (measured 2 %); 0.25 leaves room for the
    # margin's dependence on the speeds, and still says the culling happened.
    assert idle["mean_active_fraction"] < 0.25
    assert idle["switches"] > 0
    assert full.metadata["solver_statistics"]["idle_connectors"] is None


def _point_triangle_distance(point: np.ndarray, corners: np.ndarray) -> tuple[float, bool]:
    """Exact distance from ``point`` (3,) to the closed triangle ``corners`` (3, 3), and
    whether it is the plane's (the foot inside) or an edge's."""
    a, b, c = corners
    normal = np.cross(b - a, c - a)
    normal /= np.linalg.norm(normal)
    foot = point - np.dot(point - a, normal) * normal
    inside = all(np.dot(np.cross(q - p, foot - p), normal) >= 0.0
                 for p, q in ((a, b), (b, c), (c, a)))
    if inside:
        return float(abs(np.dot(point - a, normal))), True
    best = np.inf
    for p, q in ((a, b), (b, c), (c, a)):
        t = np.clip(np.dot(point - p, q - p) / np.dot(q - p, q - p), 0.0, 1.0)
        best = min(best, float(np.linalg.norm(point - (p + t * (q - p)))))
    return best, False


def _two_bodies() -> Scene:
    return Scene(name="two", bodies=(
        Body("a", motion=Motion.FIXED, shapes=(Sphere("s", radius=0.1),)),
        Body("b", shapes=(Sphere("s", radius=0.1),), position=(1.0, 0.0, 0.0))),
        contacts=(ContactPair("touch", body_a="a", shape_a="s", body_b="b", shape_b="s"),))


def test_the_gap_bound_never_exceeds_the_exact_sphere_triangle_gap():
    rng = np.random.default_rng(7)
    scene = _two_bodies()
    plans, truth, over_face = [], [], []
    poses = rng.normal(size=(2, 3)), rng.normal(size=(2, 4))
    rotation = quat_to_matrix_batch(poses[1] / np.linalg.norm(poses[1], axis=1,
                                                              keepdims=True))
    for _ in range(400):
        corners = rng.normal(size=(3, 3))
        centre, radius = rng.normal(size=3) * 1.5, float(rng.uniform(0.01, 0.5))
        plans.append(ConnectorPlan("sphere_triangle", "a", tuple(centre), radius, "b",
                                   triangle=tuple(map(tuple, corners))))
        # The sphere's centre in b's frame, where the triangle's corners are given.
        world = poses[0][0] + rotation[0] @ centre
        distance, inside = _point_triangle_distance(rotation[1].T @ (world - poses[0][1]),
                                                    corners)
        truth.append(distance - radius)
        over_face.append(inside)
    pair = PairPlan(scene.all_contacts[0], plans)
    idle = IdleConnectors.from_plans(scene, [pair], list(range(len(plans))), np.zeros((2, 3)))
    bound = idle.gap_bounds(poses[0], rotation)
    truth, over_face = np.asarray(truth), np.asarray(over_face)
    # A lower bound: never above the exact gap (1e-12 of these unit-sized distances is
    # round-off); and exact, to round-off, over the face (a sphere resting on a face, the
    # common case of a culled connector that must stay off).
    assert np.all(bound <= truth + 1e-12)
    assert over_face.sum() > 10  # the random cases include spheres over the face
    np.testing.assert_allclose(bound[over_face], truth[over_face], rtol=0, atol=1e-12)


def test_a_connector_that_closes_faster_than_its_margin_is_counted_as_a_breach():
    scene = _two_bodies()
    plan = PairPlan(scene.all_contacts[0], [ConnectorPlan("sphere_sphere", "a", (0.0, 0.0, 0.0),
                                                      0.1, "b", other_radius=0.1)])
    idle = IdleConnectors.from_plans(scene, [plan], [0], np.zeros((2, 3)))
    rotation = np.broadcast_to(np.eye(3), (2, 3, 3))

    def at(distance: float, margin: float) -> np.ndarray:
        position = np.array([[0.0, 0.0, 0.0], [distance, 0.0, 0.0]])
        return idle.update(position, rotation, margin, time=0.0)

    at(1.0, 0.05)                      # first step: always every connector on
    assert idle.active.all()
    assert len(at(1.0, 0.05)) == 1     # gap 0.8 > margin: off
    assert not idle.active.any()
    at(0.22, 0.05)                     # gap 0.02: back on, but it closed 0.78 in one step
    assert idle.active.all()
    assert idle.margin_breaches == 1 and "switched off at margin 0.05" in \
        idle.breach_examples[0]


def test_auto_culls_only_systems_large_enough_to_gain():
    assert culling_wanted("auto", MIN_CONNECTORS) and not culling_wanted("auto", 8)
    assert culling_wanted("on", 1) and not culling_wanted("on", 0)
    assert not culling_wanted("off", 1298)
    with pytest.raises(ValueError, match="cull_idle_connectors"):
        resolve_settings("tuned", {"cull_idle_connectors": "yes"})
