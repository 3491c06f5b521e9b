"""The records of a PyBullet world built from a scene (:mod:`.build`): where each scene body
and each side of each contact pair lives, which joints are driven, and what the run loop needs.
Pure data: no ``pybullet`` import."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from clearbench.adapters.force_elements import ForceElements
from clearbench.adapters.pybullet.settings import PybulletSettings
from clearbench.adapters.pybullet.topology import Topology
from clearbench.scenarios.scene import Scene


@dataclass
class BodyHandle:
    """Where a scene body lives in PyBullet.

    ``kind``: 'static', 'rigid', 'base' (floating base of a multibody) or 'link'. ``inertial``
    is the inertial frame (centre of mass, principal axes) in the body frame, so that the body
    frame's world pose is the inertial frame's world pose composed with its inverse.
    """

    name: str
    kind: str
    pb_body: int
    link: int
    inertial: tuple
    mass: float
    principal_moments: np.ndarray


@dataclass
class CollisionObject:
    """One PyBullet collision object standing in for (part of) one side of a pair."""

    pair: int
    side: str
    body: str
    pb_body: int
    link: int
    pieces: tuple
    shape: int = -1


@dataclass
class DrivenJoint:
    """A driven joint coordinate: its multibody, joint index, sign, driver and motor limit."""

    pb_body: int
    joint: int
    sign: float
    driver: object
    max_force: float


@dataclass
class BuiltWorld:
    """A built PyBullet world and what the run loop needs to drive and read it."""

    client: int
    scene: Scene
    settings: PybulletSettings
    time_step: float
    topology: Topology
    bodies: list                       # BodyHandle per scene body, scene order
    objects: list                      # CollisionObject
    pair_objects: list                 # per scene pair: (A objects, B objects)
    driven: list                       # DrivenJoint
    free_joints: list                  # (pb body, joint index, kind) with motors switched off
    closures: list = field(default_factory=list)   # PyBullet constraint ids
    loads: ForceElements | None = None
    margin: float | None = None
    warnings: list = field(default_factory=list)
    initial_velocity_residual: float = 0.0
    side_notes: dict = field(default_factory=dict)
    rebuild_overlap: dict = field(default_factory=dict)  # contact name -> [L] (pair_overlap)
    holders: list = field(default_factory=list)   # static bodies holding link shapes' margins


