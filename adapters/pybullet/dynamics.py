"""Dynamics of the built objects (``changeDynamics``), the mass-property guard and joint
motors, each call shaped around PyBullet's traps (NOTES in docs/engines/pybullet.md)."""

from __future__ import annotations

import math

import numpy as np

from clearbench.adapters.pybullet.library import pb
from clearbench.adapters.pybullet.world import BuiltWorld


def motor_off(client: int, pb_body: int, joint: int, kind: str) -> None:
    if kind == "spherical":
        pb.setJointMotorControlMultiDof(pb_body, joint, pb.POSITION_CONTROL,
                                        targetPosition=[0, 0, 0, 1], positionGain=0.0,
                                        velocityGain=0.0, force=[0.0, 0.0, 0.0],
                                        physicsClientId=client)
    else:
        pb.setJointMotorControl2(pb_body, joint, pb.VELOCITY_CONTROL, targetVelocity=0.0,
                                 force=0.0, physicsClientId=client)


def check_mass_properties(built: BuiltWorld, relative: float = 1e-9) -> None:
    """Guard: every moving body's mass and principal moments as PyBullet reads them back.

    ``changeDynamics(localInertiaDiagonal=...)`` without ``mass=`` in the same call makes a
    rigid body's mass unusable (read back 0, the first step non-finite:
    docs/engines/pybullet.md); a multibody
    link whose inertia was never set keeps the collision shape's. RuntimeError naming the body.
    """
    for handle in built.bodies:
        if handle.kind == "static":
            continue
        info = pb.getDynamicsInfo(handle.pb_body, handle.link, physicsClientId=built.client)
        mass, moments = info[0], np.asarray(info[2], dtype=float)
        scale = max(float(np.max(handle.principal_moments)), 1e-300)
        if not (math.isfinite(mass) and abs(mass - handle.mass) <= relative * handle.mass
                and np.all(np.abs(moments - handle.principal_moments) <= relative * scale)):
            raise RuntimeError(
                f"body {handle.name!r}: PyBullet reads back mass {mass!r} and principal "
                f"moments {tuple(moments)}, the scene has {handle.mass!r} and "
                f"{tuple(handle.principal_moments)} (mass and localInertiaDiagonal must be set "
                "in the same changeDynamics call)")


def object_dynamics(built: BuiltWorld) -> None:
    """Friction, restitution (A: the pair's, B: 1), anchors, processing threshold, margins.

    Margins go in calls of their own: PyBullet's C API writes link index -1 for
    ``collisionMargin`` (``b3ChangeDynamicsInfoSetCollisionMargin``), so in a call on a link
    the margin and every field set before it would land on the base
    (docs/engines/pybullet.md). A link's
    margin is set through the base of a static holder body sharing its collision shape (shapes
    are shared objects); the holder collides with nothing.
    """
    client, settings = built.client, built.settings
    contacts = built.scene.expanded.contacts
    for obj in built.objects:
        contact = contacts[obj.pair]
        a_side = obj.side == "a"
        kwargs = dict(lateralFriction=contact.friction if a_side else 1.0,
                      restitution=contact.restitution if a_side else 1.0,
                      rollingFriction=0.0, spinningFriction=0.0,
                      frictionAnchor=int(settings.friction_anchor))
        if settings.contact_processing_threshold is not None:
            kwargs["contactProcessingThreshold"] = settings.contact_processing_threshold
        pb.changeDynamics(obj.pb_body, obj.link, physicsClientId=client, **kwargs)
        if built.margin is None or len(obj.pieces) != 1 or obj.pieces[0].kind not in (
                "box", "cylinder", "plane"):
            continue
        target = obj.pb_body
        if obj.link >= 0:
            shape = obj.shape
            target = pb.createMultiBody(0.0, shape, physicsClientId=client)
            pb.setCollisionFilterGroupMask(target, -1, 0, 0, physicsClientId=client)
            built.holders.append(target)
        pb.changeDynamics(target, -1, collisionMargin=built.margin, physicsClientId=client)


def body_dynamics(built: BuiltWorld) -> None:
    """Damping and the joint speed clamp, where set."""
    client, settings = built.client, built.settings
    kwargs = {}
    if settings.linear_damping is not None:
        kwargs["linearDamping"] = settings.linear_damping
    if settings.angular_damping is not None:
        kwargs["angularDamping"] = settings.angular_damping
    seen = set()
    for handle in built.bodies:
        if handle.kind == "static" or handle.pb_body in seen:
            continue
        seen.add(handle.pb_body)
        extra = dict(kwargs)
        if settings.max_joint_velocity is not None and handle.kind != "rigid":
            extra["maxJointVelocity"] = settings.max_joint_velocity
        if extra:
            pb.changeDynamics(handle.pb_body, -1, physicsClientId=client, **extra)


