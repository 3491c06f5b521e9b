"""Contacts in the reference engine: the offset is taken on body A's side (a closed contact
acts at one point on both bodies, friction exerts no spurious moment), and a contact whose
candidate vanishes (sliding off a bounded face) is dropped by the projection."""

from __future__ import annotations

import numpy as np
import pytest

from clearbench.adapters.base import RunSettings
from clearbench.adapters.reference.engine import create
from clearbench.harness.measure import series as metrics
from clearbench.scenarios.bodies import Body
from clearbench.scenarios.contacts import ContactPair
from clearbench.scenarios.inertia import diagonal
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.shapes import Sphere


def test_oblique_frictional_impact_with_an_offset_conserves_angular_momentum():
    # Two free spheres (radius 0.1) in zero gravity meet obliquely; the contact offset 0.05
    # makes them collide 0.05 apart. Friction (mu 0.5) acts at the impact: linear and angular
    # momentum of the pair must be conserved (equal and opposite impulses at one point).
    inertia = diagonal(4e-3, 4e-3, 4e-3)
    a = Body("a", mass=1.0, inertia=inertia, position=(0.0, 0.0, 0.0), velocity=(1.0, 0.0, 0.0),
             shapes=(Sphere("s", radius=0.1),))
    b = Body("b", mass=2.0, inertia=2 * np.asarray(inertia), position=(0.5, 0.12, 0.0),
             velocity=(-0.5, 0.0, 0.0), angular_velocity=(0.0, 0.0, 3.0),
             shapes=(Sphere("s", radius=0.1),))
    scene = Scene("offset-impact", gravity=(0.0, 0.0, 0.0), horizon=0.5, time_step=1e-3,
                  bodies=(a, b),
                  contacts=(ContactPair("ab", body_a="a", shape_a="s", body_b="b", shape_b="s",
                                        friction=0.5, offset=0.05),))
    # theta = 1 without projection: x_{k+1} = x_k + h v_{k+1}, so the discrete angular momentum
    # sum m x x v + R J omega changes only by the moments of the impulses about the points
    # where they act (with theta = 1/2 it also changes by h/2 v_k x v_{k+1} at an impact, and
    # the projection moves positions at fixed velocity).
    trajectory = create().run(scene, RunSettings(options={"theta": 1.0, "projection": False}))
    assert trajectory.contact_normal_force.max() > 0.0  # they did collide
    com = metrics.centre_of_mass_positions(scene, trajectory)
    masses = np.array([1.0, 2.0])
    linear = np.einsum("b,tbi->ti", masses, trajectory.velocities)
    rotation = metrics.rotation_matrices(trajectory)
    spin = np.einsum("tbij,bjk,tbk->tbi", rotation, np.array([np.asarray(inertia)] * 2)
                     * masses[:, None, None], trajectory.angular_velocities)
    angular = (np.einsum("b,tbi->ti", masses, np.cross(com, trajectory.velocities))
               + spin.sum(axis=1))
    # Linear momentum of order 1: conserved to round-off.
    assert np.max(np.abs(linear - linear[0])) < 1e-12
    # Angular momentum: the impulses act where the candidates were computed, at q_k, when the
    # (offset) gap g is at most h |u_N| / 2 (Moreau's activation g + h u_N / 2 <= 0): points
    # g n apart, so the friction impulse J_t leaves a moment of at most h |u| J_t. Taking the
    # offset on one side only would leave offset x J_t, 33 times more (measured 4.0e-3 against
    # 8.0e-6 here).
    step = scene.time_step
    force = trajectory.contact_force[:, 0]
    normal = trajectory.contact_normal_force[:, 0]
    tangential_impulse = step * np.sum(np.sqrt(np.maximum(
        0.0, np.sum(force**2, axis=1) - normal**2)))
    assert tangential_impulse > 1e-2  # friction did act
    bound = step * 1.5 * tangential_impulse  # relative speed 1.5
    assert np.max(np.abs(angular - angular[0])) < bound


def test_a_contact_that_slides_off_a_bounded_face_is_dropped_not_projected():
    # A ball slides off the edge of a rectangle face: at some step its contact is active at
    # q_k and has no candidate any more at q_{k+1} (its point is beyond the face). The
    # projection must drop it, not project onto an empty slot (infinite gap -> NaN state).
    from clearbench.scenarios.bodies import Motion
    from clearbench.scenarios.shapes import Rectangle

    scene = Scene(
        "off-the-edge", horizon=0.2, time_step=1e-3,
        bodies=(Body("table", motion=Motion.FIXED, shapes=(Rectangle("top", half_extents=(
            0.5, 0.5)),)),
                Body("ball", mass=1.0, inertia=diagonal(4e-3, 4e-3, 4e-3),
                     position=(0.45, 0.0, 0.1), velocity=(1.0, 0.0, 0.0),
                     shapes=(Sphere("s", radius=0.1),))),
        contacts=(ContactPair("ball_top", body_a="table", shape_a="top", body_b="ball",
                              shape_b="s", friction=0.0),))
    trajectory = create().run(scene, RunSettings())
    assert trajectory.status.value == "ok", trajectory.message
    x = trajectory.positions[:, 1]
    assert np.isfinite(x).all()
    # Supported until its centre passes the edge (0.05 s at 1 m/s), then it falls under
    # gravity: 0.5 g t^2 = 0.011 m over the remaining 0.15 s, within the step's O(g h t).
    # Horizontally it flies at 1 m/s to x = 0.65 m, but for the face's edge, which is part of
    # the face's solid: in the step the centre crosses the edge the contact normal there tilts
    # by at most v h / r = 1e-2 rad, so the edge's impulse (at most m g h) changes v_x by at most
    # g h v h / r = 9.8e-5 m/s, i.e. x by at most 1.5e-5 m over the remaining 0.15 s.
    assert x[-1, 0] == pytest.approx(0.65, abs=1.5e-5)
    assert x[-1, 2] == pytest.approx(0.1 - 0.5 * 9.81 * 0.15**2, abs=2e-3)
