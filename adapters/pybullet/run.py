"""One PyBullet run as the shared step loop drives it (:mod:`clearbench.adapters.stepping`):
drivers, loads, guards, read-out into trajectory samples.

Works on a world built by :mod:`.build`, in its internal units (the engine converts the samples
back to the scene's units). A step is the drivers and loads of the step start
(:meth:`Runner.apply_loads`) and ``stepSimulation``.

Read-out (docs/engines/pybullet.md): PyBullet reports the INERTIAL frame (centre of mass,
principal axes) of a base (``getBasePositionAndOrientation``) or link
(``getLinkState[0:2]``); the scene's body frame is that frame composed with the inverse of the
inertial frame in the body. Velocities
(``getBaseVelocity``, ``getLinkState[6:8]``) are the centre of mass's and the angular velocity,
world axes; the trajectory wants the angular velocity in body axes. Contact forces: for each
pair, ``getContactPoints(A object, B object)`` of every A and B collision object; a point's
normal (field 7) points from B toward A, its normal force (9) and friction forces (10, 12
along 11, 13) act on A; the trajectory keeps the force on B.

Guards: a non-finite state, a joint motor left on (a free joint's motor torque after the first
step) and, on scenes whose energy may only decrease, an energy gain above
``energy_gain_tolerance`` of the energy scale stop the run as DIVERGED.
"""

from __future__ import annotations

import numpy as np

from clearbench.adapters.pybullet.frames import from_pb
from clearbench.adapters.pybullet.library import pb
from clearbench.adapters.pybullet.settings import PybulletSettings
from clearbench.adapters.pybullet.world import BuiltWorld
from clearbench.adapters.stepping import BodyState, ContactForces, SolverStep, StepRunner
from clearbench.kernels.quaternion import quat_conjugate, quat_multiply, quat_to_matrix
from clearbench.scenarios.bodies import Motion
from clearbench.scenarios.energy import mechanical_energy, rigid_spring_points
from clearbench.scenarios.scene import Scene


class Runner(StepRunner):
    """Drivers, loads, guards and read-out of one run (see the module docstring)."""

    def __init__(self, scene: Scene, built: BuiltWorld, config: PybulletSettings, steps: int,
                 record_every: int):
        super().__init__(scene, built, config, steps, record_every)
        self.client = built.client
        self.max_contacts = 0
        self._analytics = None
        # Static bodies never move: their poses are the scene's.
        self._static_pose = {i: (np.asarray(b.position, float),
                                 np.asarray(b.orientation, float) / np.linalg.norm(
                                     b.orientation))
                             for i, b in enumerate(scene.bodies) if b.motion is Motion.FIXED}
        self._links_of: dict[int, list[tuple[int, int]]] = {}
        for i, handle in enumerate(built.bodies):
            if handle.kind == "link":
                self._links_of.setdefault(handle.pb_body, []).append((i, handle.link))
        self._inertial_conjugate = np.array([quat_conjugate(np.asarray(h.inertial[1], float))
                                             for h in built.bodies])
        self._inertial_position = np.array([np.asarray(h.inertial[0], float)
                                            for h in built.bodies])
        step_times = np.arange(steps + 1) * self.dt
        self._drive = []
        for item in built.driven:
            driver = item.driver
            position = np.asarray(driver.displacement(step_times), dtype=float)
            velocity = np.asarray(driver.velocity(step_times), dtype=float)
            self._drive.append((item, item.sign * position, item.sign * velocity))

    # ------------------------------------------------------------------ state
    def inertial_state(self):
        """Inertial-frame positions (nb, 3) (centres of mass) and quaternions (nb, 4) (w, x, y,
        z), centre-of-mass velocities (nb, 3) and angular velocities (nb, 3), world axes."""
        nb = len(self.built.bodies)
        com = np.zeros((nb, 3))
        quat = np.zeros((nb, 4))
        velocity = np.zeros((nb, 3))
        omega = np.zeros((nb, 3))
        client = self.client
        for i, handle in enumerate(self.built.bodies):
            if handle.kind == "static":
                position, orientation = self._static_pose[i]
                com[i] = position
                quat[i] = orientation
            elif handle.link < 0:
                position, orientation = pb.getBasePositionAndOrientation(
                    handle.pb_body, physicsClientId=client)
                lin, ang = pb.getBaseVelocity(handle.pb_body, physicsClientId=client)
                com[i], quat[i], velocity[i], omega[i] = position, from_pb(orientation), lin, ang
        for pb_body, items in self._links_of.items():
            states = pb.getLinkStates(pb_body, [link for _, link in items],
                                      computeLinkVelocity=1, computeForwardKinematics=1,
                                      physicsClientId=client)
            for (i, _), state in zip(items, states, strict=True):
                com[i], quat[i] = state[0], from_pb(state[1])
                velocity[i], omega[i] = state[6], state[7]
        return com, quat, velocity, omega

    def read_state(self) -> BodyState:
        return self.body_state()

    def body_state(self) -> BodyState:
        """Body-frame positions (nb, 3) and quaternions (nb, 4), centre-of-mass velocities
        (nb, 3, world), angular velocities (nb, 3, BODY axes), centres of mass (nb, 3) and
        body rotations (nb, 3, 3)."""
        com, quat, velocity, omega = self.inertial_state()
        nb = com.shape[0]
        body_quat = np.zeros((nb, 4))
        rotation = np.zeros((nb, 3, 3))
        position = np.zeros((nb, 3))
        omega_body = np.zeros((nb, 3))
        for i in range(nb):
            if i in self._static_pose:
                body_quat[i] = quat[i]
                rotation[i] = quat_to_matrix(quat[i])
                position[i] = com[i]
                com[i] = position[i] + rotation[i] @ np.asarray(
                    self.scene.bodies[i].center_of_mass, float)
                continue
            q = quat_multiply(quat[i], self._inertial_conjugate[i])
            q = q / np.linalg.norm(q)
            body_quat[i] = q if q[0] >= 0 else -q
            rotation[i] = quat_to_matrix(body_quat[i])
            position[i] = com[i] - rotation[i] @ self._inertial_position[i]
            omega_body[i] = rotation[i].T @ omega[i]
        return BodyState(position, body_quat, velocity, omega_body, com, rotation)

    # ------------------------------------------------------------------ guards
    def energy(self, state: BodyState) -> tuple[float, float]:
        """(total, kinetic) mechanical energy of ``state`` (:meth:`body_state`):
        :func:`~clearbench.scenarios.energy.mechanical_energy` with linear springs (internal
        units)."""
        position, _, velocity, omega, com, rotation = state
        energy = mechanical_energy(self.scene, com, velocity, omega,
                                   rigid_spring_points(self.scene, position, rotation))
        return float(energy.total), float(energy.kinetic)

    def check(self, step: int) -> str | None:
        """A joint motor left on, after the first step."""
        return self.check_motors() if step == 1 else None

    def check_motors(self) -> str | None:
        """A free joint whose default motor was left on acts with a non-zero motor torque."""
        for pb_body, joint, kind in self.built.free_joints:
            if kind != "1dof":
                continue
            torque = pb.getJointState(pb_body, joint, physicsClientId=self.client)[3]
            if torque != 0.0:
                name = pb.getJointInfo(pb_body, joint, physicsClientId=self.client)[1].decode()
                return (f"joint motor left on: joint {joint} ({name or 'unnamed'}) of body "
                        f"{pb_body} applied {torque:.4g} (internal units) in the first step; "
                        "PyBullet's default velocity motor brakes every joint")
        return None

    # ------------------------------------------------------------------ steps
    def apply_loads(self, k: int) -> None:
        """Drivers reset to their profile at the step start; loads applied at the centre of
        mass (WORLD_FRAME: force world axes at a world point; moment world axes)."""
        client = self.client
        for item, position, velocity in self._drive:
            pb.resetJointState(item.pb_body, item.joint, float(position[k - 1]),
                               float(velocity[k - 1]), physicsClientId=client)
            pb.setJointMotorControl2(item.pb_body, item.joint, pb.VELOCITY_CONTROL,
                                     targetVelocity=float(velocity[k - 1]),
                                     force=item.max_force, physicsClientId=client)
        loads = self.built.loads
        if loads is None:
            return
        _, _, velocity, omega, com, rotation = self.body_state()
        wrench = loads.wrenches(self.time, com, rotation, velocity, omega)
        loads.remember(rotation)
        for i, handle in enumerate(self.built.bodies):
            if handle.kind == "static" or not np.any(wrench[i]):
                continue
            pb.applyExternalForce(handle.pb_body, handle.link, list(wrench[i, :3]),
                                  list(com[i]), pb.WORLD_FRAME, physicsClientId=client)
            pb.applyExternalTorque(handle.pb_body, handle.link, list(wrench[i, 3:]),
                                   pb.WORLD_FRAME, physicsClientId=client)

    def advance(self, step: int) -> None:
        """The drivers and loads of the step start, then ``stepSimulation``."""
        self.apply_loads(step)
        self._analytics = pb.stepSimulation(physicsClientId=self.client)
        self.time = step * self.dt
        return None

    def solver_step(self, step: int) -> SolverStep | None:
        """Iterations (largest over islands) and remaining residual of the step just taken;
        a step that used every iteration with its residual above the threshold did not
        converge."""
        analytics = self._analytics
        if not analytics:
            return None
        iterations = max(int(island["numIterationsUsed"]) for island in analytics)
        residual = max(float(island["remainingResidual"]) for island in analytics)
        converged = not (iterations >= self.config.num_solver_iterations
                         and residual > self.config.solver_residual_threshold)
        return SolverStep(iterations, converged, residual)

    # ------------------------------------------------------------------ read-out
    def contact_forces(self) -> ContactForces:
        """Per scene pair: normal force sum (npair,) and total force on body B, world
        (npair, 3), of the step just taken; and the number of points with a normal force."""
        client = self.client
        npair = len(self.scene.all_contacts)
        normal = np.zeros(npair)
        total = np.zeros((npair, 3))
        active = 0
        for pair, (a_objects, b_objects) in enumerate(self.built.pair_objects):
            for a in a_objects:
                for b in b_objects:
                    points = pb.getContactPoints(a.pb_body, b.pb_body, a.link, b.link,
                                                 physicsClientId=client)
                    for point in points:
                        if point[9] <= 0.0:
                            continue
                        active += 1
                        on_a = (point[9] * np.asarray(point[7]) + point[10] * np.asarray(
                            point[11]) + point[12] * np.asarray(point[13]))
                        normal[pair] += point[9]
                        total[pair] -= on_a
        self.max_contacts = max(self.max_contacts, active)
        return ContactForces(normal, total, active)
