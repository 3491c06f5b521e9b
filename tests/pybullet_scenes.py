"""Small scenes of the PyBullet adapter's tests (not library scenes: each isolates one fact)."""

from __future__ import annotations

import math

import numpy as np

from clearbench.kernels.quaternion import quat_from_axis_angle, quat_to_matrix
from clearbench.scenarios.bodies import Body, Motion
from clearbench.scenarios.contacts import ContactPair
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.shapes import Box, Plane


def odd_body_scene() -> Scene:
    """A free body with a full inertia tensor (principal axes tilted), an off-centre centre of
    mass, a tilted pose and a twist, above a floor it does not reach (no gravity)."""
    rotation = quat_to_matrix(quat_from_axis_angle(np.array([1.0, 2.0, 3.0]) / math.sqrt(14),
                                                   0.7))
    inertia = rotation @ np.diag([0.01, 0.02, 0.025]) @ rotation.T
    orientation = quat_from_axis_angle(np.array([0.0, 0.6, 0.8]), 1.1)
    body = Body("odd", mass=2.5, inertia=tuple(map(tuple, inertia)),
                center_of_mass=(0.03, -0.02, 0.05), position=(0.3, -0.4, 1.2),
                orientation=tuple(orientation), velocity=(0.1, 0.2, -0.3),
                angular_velocity=(0.5, -0.4, 0.3),
                shapes=(Box("box", half_extents=(0.1, 0.05, 0.04)),))
    ground = Body("ground", motion=Motion.FIXED, shapes=(Plane("floor"),))
    return Scene("odd-body", gravity=(0.0, 0.0, 0.0), horizon=0.01, time_step=1e-3,
                 bodies=(ground, body),
                 contacts=(ContactPair("floor_odd", body_a="ground", shape_a="floor",
                                       body_b="odd", shape_b="box", friction=0.3),))


def resting_box() -> Scene:
    """A 2 kg box resting on a floor (mu 0.5), 0.3 s at 1 ms."""
    ground = Body("ground", motion=Motion.FIXED, shapes=(Plane("floor"),))
    box = Body("box", mass=2.0, inertia=((0.01, 0, 0), (0, 0.01, 0), (0, 0, 0.01)),
               position=(0.0, 0.0, 0.05), shapes=(Box("box", half_extents=(0.1, 0.1, 0.05)),))
    return Scene("resting-box", horizon=0.3, time_step=1e-3, bodies=(ground, box),
                 contacts=(ContactPair("box_floor", body_a="ground", shape_a="floor",
                                       body_b="box", shape_b="box", friction=0.5),))
