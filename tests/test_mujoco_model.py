"""MuJoCo adapter, compiled model: what MuJoCo was given equals the scene (mass, inertia,
centre of mass, initial poses and twists), topology, rings and capabilities."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from clearbench.adapters.base import RunSettings, Support
from clearbench.adapters.mujoco.build import build_model
from clearbench.adapters.mujoco.engine import create
from clearbench.adapters.mujoco.settings import resolve_settings
from clearbench.adapters.mujoco.topology import plan_topology
from clearbench.kernels.quaternion import quat_to_matrix
from clearbench.scenarios.bodies import Body, Motion
from clearbench.scenarios.drivers import Driver
from clearbench.scenarios.joints import PrismaticJoint, RevoluteJoint
from clearbench.scenarios.library import get_scene, scene_names
from clearbench.scenarios.scene import Scene

NAMES = scene_names()


def _rotation(q) -> np.ndarray:
    return quat_to_matrix(np.asarray(q, dtype=float) / np.linalg.norm(q))


# Scenes MuJoCo can build: every library scene, the C-60 included (law loads, bores and
# bounded faces approximated, see test_mujoco_c60.py).
SUPPORTED = [n for n in NAMES if not create("default").unsupported_reasons(get_scene(n))]


def test_every_library_scene_is_supported():
    assert set(SUPPORTED) == set(NAMES), sorted(set(NAMES) - set(SUPPORTED))


@pytest.mark.parametrize("name", SUPPORTED)
def test_compiled_mass_inertia_and_pose_equal_the_scene(name):
    scene = get_scene(name)
    built = build_model(scene, resolve_settings("default"), scene.time_step)
    model, data = built.model, built.data
    mujoco.mj_forward(model, data)
    for index, body in enumerate(scene.bodies):
        i = int(built.body_ids[index])
        # Initial pose of the body frame (not the inertial frame): exact up to the round-off
        # of composing relative poses along the tree (1e-12 of O(1) lengths).
        assert np.allclose(data.xpos[i], body.position, atol=1e-12)
        assert np.allclose(_rotation(data.xquat[i]), _rotation(body.orientation), atol=1e-12)
        if body.motion is Motion.FIXED:
            continue
        assert model.body_mass[i] == pytest.approx(body.mass, rel=1e-14)
        # Centre of mass in the body frame, and the inertia tensor about it in body axes:
        # MuJoCo stores principal moments (body_inertia) in the frame body_iquat; R D R^T
        # rebuilds the tensor (eigen-decomposition round-off: 1e-10 relative).
        assert np.allclose(model.body_ipos[i], body.center_of_mass, atol=1e-14)
        frame = _rotation(model.body_iquat[i])
        tensor = frame @ np.diag(model.body_inertia[i]) @ frame.T
        scale = np.max(np.abs(body.inertia))
        assert np.allclose(tensor, body.inertia, atol=1e-10 * scale)
        # The adapter's drivers raise the armature of driven joints only.
        driven = {d.dof_address for d in built.driven}
        others = [k for k in range(model.nv) if k not in driven]
        assert np.all(model.dof_armature[others] == 0.0)


@pytest.mark.parametrize("name", SUPPORTED)
def test_first_sample_reproduces_initial_twists(name):
    scene = get_scene(name)
    trajectory = create("default").run(scene, RunSettings(horizon=scene.time_step))
    for index, body in enumerate(scene.bodies):
        if body.motion is Motion.FIXED:
            continue
        # The library's initial twists are consistent with its joints: the least-squares
        # joint velocities reproduce them to round-off (1e-12 of speeds up to 150 rad/s).
        assert np.allclose(trajectory.velocities[0, index], body.velocity, atol=1e-9)
        assert np.allclose(trajectory.angular_velocities[0, index], body.angular_velocity,
                           atol=1e-9)
        assert np.allclose(trajectory.positions[0, index], body.position, atol=1e-12)
    assert trajectory.metadata["initial_velocity_residual"] < 1e-9


def test_slider_crank_tree_and_loop_closure():
    scene = get_scene("slider-crank")
    topology = plan_topology(scene)
    kinds = {link.body: (link.parent, link.kind, link.joint) for link in topology.links}
    # Prismatic joints are preferred as tree edges (a prismatic loop closure is not
    # expressible); the remaining revolute joint closes the loop with two connects.
    assert kinds["slider"] == ("ground", "slide", "slide")
    assert kinds["crank"] == ("ground", "hinge", "crank_pivot")
    assert kinds["rod"] == ("crank", "hinge", "crank_pin")
    assert topology.closures == ("wrist_pin",)
    # The crank's rz driver is its own hinge to the fixed ground.
    (dof,) = topology.driven["crank"]
    assert dof.joint == "tree" and dof.sign == 1.0
    built = build_model(scene, resolve_settings("tuned"), 1e-3)
    assert built.model.neq == 2  # two connect equalities on the wrist-pin axis
    capabilities = create("tuned").capabilities(scene)
    assert capabilities["closed_loop"].support is Support.APPROXIMATED
    assert capabilities["drivers"].support is Support.APPROXIMATED
    assert "wrist_pin" in capabilities["ideal_joints"].detail


def _prismatic_loop_scene() -> Scene:
    """Two free bodies joined to the ground and to each other by prismatic joints only."""
    a = Body("a", mass=1.0, position=(0.0, 0.0, 0.0))
    b = Body("b", mass=1.0, position=(1.0, 0.0, 0.0))
    return Scene(
        name="prismatic-loop", bodies=(Body("ground", motion=Motion.FIXED), a, b),
        joints=(PrismaticJoint("p1", body_a="ground", body_b="a", axis=(1.0, 0, 0)),
                PrismaticJoint("p2", body_a="ground", body_b="b", axis=(1.0, 0, 0)),
                PrismaticJoint("p3", body_a="a", body_b="b", axis=(1.0, 0, 0))),
    )


def test_unsupported_scenes_get_a_verdict_with_the_reason():
    scene = _prismatic_loop_scene()
    engine = create("default")
    capabilities = engine.capabilities(scene)
    assert capabilities["closed_loop"].support is Support.UNSUPPORTED
    trajectory = engine.run(scene)
    assert trajectory.status.value == "unsupported"
    assert "prismatic joint 'p3' closes a loop" in trajectory.message
    # A rotation driver on a free body (other rotations free) has no MuJoCo joint.
    spinner = Scene(name="spinner", bodies=(Body("s", motion=Motion.DRIVEN),),
                    drivers=(Driver("spin", body="s", component="rz", times=(0.0,),
                                    values=(1.0,)),))
    assert engine.capabilities(spinner)["drivers"].support is Support.UNSUPPORTED
    assert engine.run(spinner).status.value == "unsupported"


@pytest.mark.parametrize("name", NAMES)
def test_every_feature_has_a_stated_capability(name):
    scene = get_scene(name)
    for preset in ("default", "tuned"):
        capabilities = create(preset).capabilities(scene)
        assert set(capabilities) == set(scene.features)
        for feature, capability in capabilities.items():
            assert capability.detail, f"{feature} has no explanation"
            if name in SUPPORTED:
                assert capability.support is not Support.UNSUPPORTED, capability.detail


def test_clearance_joint_rings_report_their_chord_error_next_to_the_clearance():
    scene = get_scene("clearance-pendulum")
    detail = create("tuned").capabilities(scene)["clearance_joints"].detail
    assert "chord error" in detail and "radial clearance" in detail
    built = build_model(scene, resolve_settings("tuned"), 1e-3)
    settings = resolve_settings("tuned")
    rings = {ring.shape: ring for ring in built.rings}
    bore = scene.clearance_joints[0].bore_radius
    ring = rings["pivot.ring_bottom"]
    assert ring.pieces == settings.ring_pieces
    assert ring.chord_error == pytest.approx(bore * (1 - math.cos(math.pi / 64)))
    # Sphere pieces: radius capped at half the radial clearance, compensated by the pair
    # margin so that the pair acts at the circle itself.
    assert ring.piece_radius == pytest.approx(0.5 * scene.clearance_joints[0].radial_clearance)
    model = built.model
    pair = model.pair("pivot.ring_bottom|bob/pivot.ring_bottom#0|ground/pivot.journal")
    assert model.pair_margin[pair.id] == pytest.approx(-ring.piece_radius)
    # Every geom collides only through the scene's explicit pairs.
    assert np.all(model.geom_contype == 0) and np.all(model.geom_conaffinity == 0)


def test_sphere_ring_holds_a_journal_at_the_clearance():
    """Static check of the ring geometry: a bearing shifted by e against a fixed journal has
    contacts from the first micrometre of overlap with the true circle, not before."""
    scene = get_scene("clearance-pendulum", initial_angle=0.0)
    built = build_model(scene, resolve_settings("tuned"), 1e-3)
    model, data = built.model, built.data
    clearance = scene.clearance_joints[0].radial_clearance
    free = model.joint("bob:free")
    for shift, expect_contact in ((0.99 * clearance, False), (1.01 * clearance, True)):
        mujoco.mj_resetData(model, data)
        data.qpos[free.qposadr[0]] = shift
        mujoco.mj_forward(model, data)
        distances = [data.contact[i].dist - data.contact[i].includemargin
                     for i in range(data.ncon)]
        assert (len(distances) > 0) == expect_contact
        if expect_contact:
            # Deepest signed gap of the ring against the journal: -(e - c), within 1e-3 of c
            # (the piece nearest the shift direction sits exactly on it).
            assert min(distances) == pytest.approx(-(shift - clearance), abs=1e-3 * clearance)


def test_revolute_joint_to_fixed_body_is_a_tree_hinge_without_equalities():
    scene = get_scene("pendulum")
    built = build_model(scene, resolve_settings("default"), 1e-3)
    assert built.model.neq == 0 and built.model.njnt == 1
    joint = built.model.joint("bob:hinge")
    assert joint.type[0] == mujoco.mjtJoint.mjJNT_HINGE
    # Axis in the bob frame: the world y axis seen from the tilted bob.
    expected = _rotation(scene.body("bob").orientation).T @ np.array([0.0, 1.0, 0.0])
    assert np.allclose(built.model.jnt_axis[joint.id], expected, atol=1e-12)


def test_revolute_with_parallel_axis_hinge_and_driver_sign():
    # A driver about -z realised by a hinge about +z: the hinge moves with sign -1.
    wheel = Body("wheel", mass=1.0, motion=Motion.DRIVEN)
    scene = Scene(name="wheel", bodies=(Body("ground", motion=Motion.FIXED), wheel),
                  joints=(RevoluteJoint("axle", body_a="ground", body_b="wheel",
                                        axis=(0.0, 0.0, -1.0)),),
                  drivers=(Driver("spin", body="wheel", component="rz", times=(0.0,),
                                  values=(2.0,)),), gravity=(0.0, 0.0, 0.0), horizon=0.5)
    (dof,) = plan_topology(scene).driven["wheel"]
    assert dof.sign == -1.0
    trajectory = create("default").run(scene)
    angle = 2 * np.arctan2(trajectory.orientations[:, 1, 3], trajectory.orientations[:, 1, 0])
    # Prescribed exactly at every sample (round-off of the quaternion, 1e-12 rad).
    assert np.allclose(np.unwrap(angle), 2.0 * trajectory.times, atol=1e-12)
