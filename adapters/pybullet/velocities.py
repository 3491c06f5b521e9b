"""Initial velocities of a built PyBullet world: the scene's centre-of-mass twists reproduced
through the velocity coordinates of rigid bodies, floating bases and joints."""

from __future__ import annotations

import numpy as np

from clearbench.adapters.pybullet.library import pb
from clearbench.adapters.pybullet.world import BuiltWorld
from clearbench.kernels.quaternion import quat_to_matrix


def body_twists(built: BuiltWorld) -> tuple[np.ndarray, np.ndarray]:
    """Centre-of-mass velocities (nb, 3) and angular velocities (nb, 3), both world axes."""
    client = built.client
    nb = len(built.bodies)
    v = np.zeros((nb, 3))
    w = np.zeros((nb, 3))
    for i, handle in enumerate(built.bodies):
        if handle.kind == "static":
            continue
        if handle.link < 0:
            lin, ang = pb.getBaseVelocity(handle.pb_body, physicsClientId=client)
        else:
            state = pb.getLinkState(handle.pb_body, handle.link, computeLinkVelocity=1,
                                    physicsClientId=client)
            lin, ang = state[6], state[7]
        v[i], w[i] = lin, ang
    return v, w


def _dofs(built: BuiltWorld) -> list[tuple]:
    """Velocity coordinates of the world: ('base', body, k) for floating bases and rigid
    bodies, ('joint', body, joint, k) for multibody joints (spherical: 3)."""
    out = []
    seen = set()
    for handle in built.bodies:
        if handle.kind in ("rigid", "base") and handle.pb_body not in seen:
            out += [("base", handle.pb_body, k) for k in range(6)]
        if handle.kind in ("base", "link") and handle.pb_body not in seen:
            seen.add(handle.pb_body)
            for j in range(pb.getNumJoints(handle.pb_body, physicsClientId=built.client)):
                kind = pb.getJointInfo(handle.pb_body, j, physicsClientId=built.client)[2]
                if kind in (pb.JOINT_REVOLUTE, pb.JOINT_PRISMATIC):
                    out.append(("joint", handle.pb_body, j, -1))
                elif kind == pb.JOINT_SPHERICAL:
                    out += [("joint", handle.pb_body, j, k) for k in range(3)]
    return out


def _set_dof(client: int, dof: tuple, value: float) -> None:
    if dof[0] == "base":
        lin, ang = pb.getBaseVelocity(dof[1], physicsClientId=client)
        twist = list(lin) + list(ang)
        twist[dof[2]] = value
        pb.resetBaseVelocity(dof[1], twist[:3], twist[3:], physicsClientId=client)
    elif dof[3] < 0:
        position = pb.getJointState(dof[1], dof[2], physicsClientId=client)[0]
        pb.resetJointState(dof[1], dof[2], position, value, physicsClientId=client)
    else:
        state = pb.getJointStateMultiDof(dof[1], dof[2], physicsClientId=client)
        velocity = list(state[1])
        velocity[dof[3]] = value
        pb.resetJointStateMultiDof(dof[1], dof[2], targetValue=list(state[0]),
                                   targetVelocity=velocity, physicsClientId=client)


def initial_velocities(built: BuiltWorld, body_poses) -> None:
    """Velocities reproducing each body's initial centre-of-mass twist: driven coordinates at
    their profile's rate, the others by least squares over the Jacobian measured by setting
    one velocity coordinate at a time (PyBullet gives no Jacobian of floating bases)."""
    client, scene = built.client, built.scene
    dofs = _dofs(built)
    driven_keys = {(item.pb_body, item.joint): item for item in built.driven}
    for dof in dofs:
        _set_dof(client, dof, 0.0)
    moving = [i for i, h in enumerate(built.bodies) if h.kind != "static"]
    if not moving or not dofs:
        return
    targets = []
    for i in moving:
        body = scene.bodies[i]
        rotation = quat_to_matrix(body_poses[body.name][1])
        targets += [np.asarray(body.velocity, float), rotation @ np.asarray(
            body.angular_velocity, float)]
    target = np.concatenate(targets)
    columns = []
    for dof in dofs:
        _set_dof(client, dof, 1.0)
        v, w = body_twists(built)
        columns.append(np.concatenate([np.concatenate([v[i], w[i]]) for i in moving]))
        _set_dof(client, dof, 0.0)
    jacobian = np.array(columns).T
    values = np.zeros(len(dofs))
    free = np.ones(len(dofs), dtype=bool)
    for k, dof in enumerate(dofs):
        item = driven_keys.get((dof[1], dof[2])) if dof[0] == "joint" else None
        if item is not None:
            values[k] = item.sign * float(item.driver.velocity(0.0))
            free[k] = False
    rest = target - jacobian[:, ~free] @ values[~free]
    if free.any():
        values[free] = np.linalg.lstsq(jacobian[:, free], rest, rcond=None)[0]
    for dof, value in zip(dofs, values, strict=True):
        _set_dof(client, dof, float(value))
    v, w = body_twists(built)
    achieved = np.concatenate([np.concatenate([v[i], w[i]]) for i in moving])
    built.initial_velocity_residual = float(np.linalg.norm(achieved - target))
