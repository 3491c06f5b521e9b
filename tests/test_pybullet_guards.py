"""Each guard of the PyBullet adapter firing, and the PyBullet traps it guards against shown on
the raw engine (docs/engines/pybullet.md, "Traps guarded against"). About 20 s."""

from __future__ import annotations

import dataclasses
import subprocess
import sys

import numpy as np
import pytest

from clearbench.adapters.base import RunSettings
from clearbench.adapters.pybullet import create
from clearbench.adapters.pybullet.build import build_world, disconnect
from clearbench.adapters.pybullet.dynamics import check_mass_properties
from clearbench.adapters.pybullet.geometry import (
    Piece,
    check_compound,
    collision_groups,
    side_geometry,
)
from clearbench.adapters.pybullet.library import pb
from clearbench.adapters.pybullet.settings import resolve_settings
from clearbench.adapters.pybullet.shapes import create_shape
from clearbench.adapters.trajectory import RunStatus
from clearbench.scenarios.bodies import Body
from clearbench.scenarios.library import get_scene
from clearbench.scenarios.loads import Moment
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.shapes import Box

from .pybullet_scenes import odd_body_scene, resting_box


def _spheres(count: int) -> tuple:
    return tuple(Piece("sphere", (0.01,), (float(k), 0.0, 0.0), (1.0, 0.0, 0.0, 0.0))
                 for k in range(count))


# ---------------------------------------------------------------------------- 16 children
def test_pybullet_drops_compound_children_beyond_16():
    """The trap: 17 children asked, 16 kept, without a word."""
    client = pb.connect(pb.DIRECT)
    try:
        pieces = _spheres(17)
        shape = pb.createCollisionShapeArray(
            shapeTypes=[pb.GEOM_SPHERE] * 17, radii=[0.01] * 17,
            collisionFramePositions=[list(p.position) for p in pieces], physicsClientId=client)
        body = pb.createMultiBody(0.0, shape, physicsClientId=client)
        assert len(pb.getCollisionShapeData(body, -1, physicsClientId=client)) == 16
    finally:
        pb.disconnect(client)


def test_compound_guard_refuses_more_than_16_children():
    with pytest.raises(ValueError, match="17 children"):
        check_compound(_spheres(17))
    client = pb.connect(pb.DIRECT)
    try:
        with pytest.raises(ValueError, match="17 children"):
            create_shape(client, _spheres(17))
    finally:
        pb.disconnect(client)


def test_rings_are_split_into_compounds_of_at_most_16():
    scene = get_scene("clearance-pendulum")
    index = [c.name for c in scene.all_contacts].index("pivot.ring_top")
    side = side_geometry(scene, index, "a", resolve_settings("tuned"), 1.0)
    assert len(side.pieces) == 64
    assert [len(g) for g in collision_groups(side)] == [16, 16, 16, 16]


# ---------------------------------------------------------------------------- inertia
def test_inertia_without_mass_is_caught():
    """The trap: ``localInertiaDiagonal`` without ``mass`` in the same call (mass read back 0,
    the first step non-finite)."""
    built = build_world(odd_body_scene(), resolve_settings("tuned"), 1e-3)
    try:
        handle = built.bodies[1]
        pb.changeDynamics(handle.pb_body, -1, localInertiaDiagonal=[0.01, 0.02, 0.03],
                          physicsClientId=built.client)
        with pytest.raises(RuntimeError, match="same changeDynamics call"):
            check_mass_properties(built)
    finally:
        disconnect(built)


def test_a_link_field_landing_on_the_base_is_caught():
    """The trap: ``changeDynamics(body, link, mass=..., linearDamping=...)`` applies every field
    to the BASE (linearDamping's C setter writes link index -1)."""
    built = build_world(odd_body_scene(), resolve_settings("default"), 1e-3)  # multibody
    try:
        handle = built.bodies[1]
        assert handle.kind == "base"  # its collision object is link 0
        pb.changeDynamics(handle.pb_body, 0, mass=0.5, linearDamping=0.0,
                          physicsClientId=built.client)
        assert pb.getDynamicsInfo(handle.pb_body, -1, physicsClientId=built.client)[0] == 0.5
        with pytest.raises(RuntimeError, match="reads back mass 0.5"):
            check_mass_properties(built)
    finally:
        disconnect(built)


def _spin_up(warm_up: bool) -> np.ndarray:
    """Angular velocity (world) of a rigid box at rest after one step of a moment (1, 1, 1)
    N m, its inertia (1, 2, 3) set by changeDynamics after creation (a unit cube's own
    inertia is m / 6 = 0.1667)."""
    client = pb.connect(pb.DIRECT)
    try:
        pb.setGravity(0, 0, 0, physicsClientId=client)
        pb.setPhysicsEngineParameter(fixedTimeStep=1e-3, physicsClientId=client)
        shape = pb.createCollisionShape(pb.GEOM_BOX, halfExtents=[0.5] * 3,
                                        physicsClientId=client)
        body = pb.createMultiBody(1.0, shape, useMaximalCoordinates=True,
                                  physicsClientId=client)
        pb.changeDynamics(body, -1, mass=1.0, localInertiaDiagonal=[1.0, 2.0, 3.0],
                          physicsClientId=client)
        if warm_up:
            pb.stepSimulation(physicsClientId=client)
        pb.applyExternalTorque(body, -1, [1.0, 1.0, 1.0], pb.WORLD_FRAME,
                               physicsClientId=client)
        pb.stepSimulation(physicsClientId=client)
        return np.array(pb.getBaseVelocity(body, physicsClientId=client)[1])
    finally:
        pb.disconnect(client)


def test_inertia_acts_only_from_the_second_step_hence_the_warm_up_step():
    expected = np.array([1.0, 0.5, 1.0 / 3.0]) * 1e-3  # I^-1 M dt
    assert not np.allclose(_spin_up(warm_up=False), expected, rtol=0.01)  # the trap
    np.testing.assert_allclose(_spin_up(warm_up=True), expected, rtol=1e-9)


def test_the_adapters_first_step_uses_the_scenes_inertia():
    """Through the adapter (which takes the warm-up step): a moment on a body at rest gives
    omega = I^-1 M dt in body axes at the first step (I = diag(1, 2, 3) kg m^2)."""
    body = Body("cube", mass=1.0, inertia=((1.0, 0, 0), (0, 2.0, 0), (0, 0, 3.0)),
                shapes=(Box("box", half_extents=(0.5, 0.5, 0.5)),))
    scene = Scene("spin-up", gravity=(0.0, 0.0, 0.0), horizon=1e-3, time_step=1e-3,
                  bodies=(body,), loads=(Moment("m", body="cube", moment=(1.0, 1.0, 1.0)),))
    for preset in ("default", "tuned"):
        trajectory = create(preset).run(scene)
        np.testing.assert_allclose(trajectory.angular_velocities[1, 0],
                                   np.array([1.0, 0.5, 1.0 / 3.0]) * 1e-3, rtol=1e-9)


# ---------------------------------------------------------------------------- run guards
def test_joint_motors_left_on_stop_the_run():
    scene = get_scene("pendulum")
    trajectory = create("tuned").run(scene, RunSettings(
        horizon=0.01, options={"switch_off_joint_motors": False}))
    assert trajectory.status is RunStatus.DIVERGED
    assert "joint motor left on" in trajectory.message
    assert create("tuned").run(scene, RunSettings(horizon=0.01)).status is RunStatus.OK


def test_non_finite_state_stops_the_run():
    scene = get_scene("torque-free-flip")
    blow_up = Moment("kick", body="body", moment=(1e30, 1e30, 1e30))
    # 1e308 N m makes PyBullet's state overflow; scene validation refuses magnitudes beyond
    # 1e30, so the value is put in after the checks, as a corrupted scene would carry it.
    object.__setattr__(blow_up, "moment", (1e308, 1e308, 1e308))
    scene = dataclasses.replace(scene, loads=(blow_up,), horizon=0.05)
    trajectory = create("tuned").run(scene, RunSettings(options={"internal_units": "SI"}))
    assert trajectory.status is RunStatus.DIVERGED
    assert "non-finite" in trajectory.message


def test_energy_gain_stops_the_run():
    """The stiff spring (omega dt = 10) is explicit here and gains energy at once."""
    trajectory = create("tuned").run(get_scene("stiff-spring"))
    assert trajectory.status is RunStatus.DIVERGED
    assert "energy gain" in trajectory.message


# ---------------------------------------------------------------------------- global state
def _contacts_seen_at(distance: float) -> int:
    """Contact points PyBullet keeps for a 0.1 m sphere ``distance`` above a plane (the
    breaking threshold 0.02 is a factor on its bounding radius sqrt(3) 0.1: 3.46 mm)."""
    client = pb.connect(pb.DIRECT)
    try:
        plane = pb.createMultiBody(0, pb.createCollisionShape(pb.GEOM_PLANE,
                                                              physicsClientId=client),
                                   physicsClientId=client)
        sphere = pb.createMultiBody(1.0, pb.createCollisionShape(
            pb.GEOM_SPHERE, radius=0.1, physicsClientId=client),
            basePosition=[0, 0, 0.1 + distance], physicsClientId=client)
        pb.performCollisionDetection(physicsClientId=client)
        return len(pb.getContactPoints(plane, sphere, physicsClientId=client))
    finally:
        pb.disconnect(client)


def test_breaking_threshold_is_set_by_every_run():
    scene = resting_box()
    create("tuned").run(scene, RunSettings(horizon=0.002,
                                           options={"contact_breaking_threshold": 0.1}))
    assert _contacts_seen_at(0.006) == 1     # the 0.1 survived the run's disconnect
    create("tuned").run(scene, RunSettings(horizon=0.002))
    assert _contacts_seen_at(0.006) == 0     # the next run set 0.02 again
    assert _contacts_seen_at(0.003) == 1


def test_fixed_bodies_are_not_moved_by_the_guards():
    """A fixed body never counts in the mass check (static objects have mass 0)."""
    built = build_world(resting_box(), resolve_settings("default"), 1e-3)
    try:
        assert built.bodies[0].kind == "static"
        check_mass_properties(built)
    finally:
        disconnect(built)


def test_importing_the_adapter_prints_nothing():
    """PyBullet prints its build time when first imported; the adapter's import drops it (a
    fresh interpreter, since this one has imported pybullet already)."""
    code = ("from clearbench.adapters.pybullet import availability, create; "
            "from clearbench.adapters.pybullet.library import pb; "
            "assert availability()[0]; create('tuned')")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=120, check=False)
    assert done.returncode == 0, done.stderr
    assert done.stdout == ""
    assert "build time" not in done.stderr
