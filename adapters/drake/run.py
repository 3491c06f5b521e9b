"""One Drake run as the shared step loop drives it (:mod:`clearbench.adapters.stepping`):
drivers, loads, guards, read-out into trajectory samples.

Works on a plant built by :mod:`.build` (SI; the engine converts the samples back to the
scene's units). Each step is ``Simulator.AdvanceTo`` of one period of the discrete plant.

- Drivers: the driven coordinate is reset to its profile (position, rate) at each step start;
  the actuator's reflected inertia holds it during the step.
- Loads: the shared force elements (:mod:`clearbench.adapters.force_elements`) evaluated at the
  step start and applied as ``ExternallyAppliedSpatialForce`` at each centre of mass (explicit,
  one step lag), through the plant's applied-spatial-force input port.
- Read-out: ``EvalBodyPoseInWorld`` (the body frame), ``EvalBodySpatialVelocityInWorld`` (the
  body-frame origin's velocity, turned into the centre of mass's), and the contact results of
  the step just taken (sampled output port): per point pair, its geometries give the scene
  pair; ``contact_force()`` acts on Drake's body B, normal ``nhat_BA_W`` from B to A; a
  hydroelastic surface's ``F_Ac_W`` acts on geometry M's body, face normals from N into M.
- Guards: a non-finite state, an exception from Drake's solver (recorded with its message) and,
  on scenes whose energy may only decrease, an energy gain above ``energy_gain_tolerance`` of
  the energy scale stop the run as DIVERGED.

Drake's Python API does not expose the discrete solver's iterations: the samples keep 0
iterations, residual NaN and "converged" (a solver failure raises and stops the run).
"""

from __future__ import annotations

import numpy as np
from pydrake.multibody.math import SpatialForce
from pydrake.multibody.plant import ExternallyAppliedSpatialForce

from clearbench.adapters.drake.build import BuiltPlant
from clearbench.adapters.drake.settings import DrakeSettings
from clearbench.adapters.stepping import BodyState, ContactForces, StepFailure, StepRunner
from clearbench.adapters.trajectory import RunStatus
from clearbench.kernels.quaternion import quat_normalize, quat_to_matrix
from clearbench.scenarios.bodies import Motion
from clearbench.scenarios.energy import mechanical_energy, rigid_spring_points
from clearbench.scenarios.scene import Scene

__all__ = ["Runner"]


class Runner(StepRunner):
    """Drivers, loads, guards and read-out of one run (see the module docstring)."""

    def __init__(self, scene: Scene, built: BuiltPlant, config: DrakeSettings, steps: int,
                 record_every: int):
        super().__init__(scene, built, config, steps, record_every)
        self.plant = built.plant
        self.context = built.plant_context
        self.max_contacts = 0
        self.penetration_max = 0.0
        self._handles = [built.bodies.get(b.name) for b in scene.bodies]
        self._com_local = np.array([np.asarray(b.center_of_mass, float) for b in scene.bodies])
        self._fixed = {}
        for i, body in enumerate(scene.bodies):
            if body.motion is Motion.FIXED:
                q = quat_normalize(np.asarray(body.orientation, float))
                self._fixed[i] = (np.asarray(body.position, float), q, quat_to_matrix(q))
        step_times = np.arange(steps + 1) * self.dt
        self._drive = [(joint, dof.sign * np.asarray(dof.driver.displacement(step_times), float),
                        dof.sign * np.asarray(dof.driver.velocity(step_times), float),
                        dof.driver.is_rotation)
                       for joint, dof in built.driven]
        self._force_port = self.plant.get_applied_spatial_force_input_port()
        self._contact_port = self.plant.get_contact_results_output_port()
        if built.loads is None:
            self._force_port.FixValue(self.context, [])

    # ------------------------------------------------------------------ state
    def read_state(self) -> BodyState:
        return self.body_state()

    def body_state(self) -> BodyState:
        """Body-frame positions (nb, 3) and quaternions (nb, 4), centre-of-mass velocities
        (nb, 3, world), angular velocities (nb, 3, BODY axes), centres of mass (nb, 3) and
        body rotations (nb, 3, 3)."""
        nb = len(self._handles)
        position = np.zeros((nb, 3))
        quaternion = np.zeros((nb, 4))
        velocity = np.zeros((nb, 3))
        omega_body = np.zeros((nb, 3))
        rotation = np.zeros((nb, 3, 3))
        for i, handle in enumerate(self._handles):
            if handle is None:
                position[i], quaternion[i], rotation[i] = self._fixed[i]
                continue
            pose = self.plant.EvalBodyPoseInWorld(self.context, handle)
            rotation[i] = pose.rotation().matrix()
            position[i] = pose.translation()
            q = pose.rotation().ToQuaternion()
            q = quat_normalize(np.array([q.w(), q.x(), q.y(), q.z()]))
            quaternion[i] = q if q[0] >= 0 else -q
            twist = self.plant.EvalBodySpatialVelocityInWorld(self.context, handle)
            omega = twist.rotational()
            velocity[i] = twist.translational() + np.cross(omega, rotation[i] @ self._com_local[i])
            omega_body[i] = rotation[i].T @ omega
        com = position + np.einsum("bij,bj->bi", rotation, self._com_local)
        return BodyState(position, quaternion, velocity, omega_body, com, rotation)

    def energy(self, state: BodyState) -> tuple[float, float]:
        """(total, kinetic) mechanical energy of ``state`` (:meth:`body_state`), SI."""
        position, _, velocity, omega, com, rotation = state
        energy = mechanical_energy(self.scene, com, velocity, omega,
                                   rigid_spring_points(self.scene, position, rotation))
        return float(energy.total), float(energy.kinetic)

    # ------------------------------------------------------------------ steps
    def apply_inputs(self, k: int) -> None:
        """Drivers reset to their profile and loads evaluated at the start of step ``k``."""
        for joint, position, rate, rotation in self._drive:
            if rotation:
                joint.set_angle(self.context, float(position[k - 1]))
                joint.set_angular_rate(self.context, float(rate[k - 1]))
            else:
                joint.set_translation(self.context, float(position[k - 1]))
                joint.set_translation_rate(self.context, float(rate[k - 1]))
        loads = self.built.loads
        if loads is None:
            return
        _, _, velocity, omega, com, rotation = self.body_state()
        wrench = loads.wrenches(self.time, com, rotation, velocity, omega)
        loads.remember(rotation)
        applied = []
        for i, handle in enumerate(self._handles):
            if handle is None or not np.any(wrench[i]):
                continue
            force = ExternallyAppliedSpatialForce()
            force.body_index = handle.index()
            force.p_BoBq_B = self._com_local[i]
            force.F_Bq_W = SpatialForce(wrench[i, 3:], wrench[i, :3])
            applied.append(force)
        self._force_port.FixValue(self.context, applied)

    def start(self) -> None:
        self.built.simulator.Initialize()

    def advance(self, step: int) -> StepFailure | None:
        """The inputs of the step start, then ``AdvanceTo`` its end; a RuntimeError of Drake's
        solver stops the run as diverged, with Drake's message (its state is not kept)."""
        try:
            self.apply_inputs(step)
            self.built.simulator.AdvanceTo(step * self.dt)
        except RuntimeError as error:
            return StepFailure(RunStatus.DIVERGED, f"Drake stopped at step {step} "
                               f"(t = {step * self.dt:.6g} s): {error}")
        finally:
            self.time = step * self.dt
        return None

    # ------------------------------------------------------------------ read-out
    def contact_forces(self) -> ContactForces:
        """Per scene pair: normal force sum (npair,) and total force on scene body B, world
        (npair, 3), of the step just taken; and the number of points with a normal force."""
        npair = len(self.scene.all_contacts)
        normal = np.zeros(npair)
        total = np.zeros((npair, 3))
        active = 0
        results = self._contact_port.Eval(self.context)
        for i in range(results.num_point_pair_contacts()):
            info = results.point_pair_contact_info(i)
            pair = info.point_pair()
            found = self.built.geometry_pair.get(pair.id_B)
            if found is None:
                continue
            index, drake_b_side = found
            force_on_drake_b = np.asarray(info.contact_force())
            normal_force = -float(force_on_drake_b @ np.asarray(pair.nhat_BA_W))
            if normal_force <= 0.0:
                continue
            active += 1
            self.penetration_max = max(self.penetration_max, float(pair.depth))
            normal[index] += normal_force
            total[index] += force_on_drake_b if drake_b_side == "b" else -force_on_drake_b
        for i in range(results.num_hydroelastic_contacts()):
            info = results.hydroelastic_contact_info(i)
            surface = info.contact_surface()
            found = self.built.geometry_pair.get(surface.id_M())
            if found is None:
                continue
            index, drake_m_side = found
            # Face normals point out of N into M; the force acts on M's body at the centroid.
            direction = sum(surface.area(f) * np.asarray(surface.face_normal(f))
                            for f in range(surface.num_faces()))
            direction = direction / max(np.linalg.norm(direction), 1e-300)
            force_on_m = np.asarray(info.F_Ac_W().translational())
            normal_force = float(force_on_m @ direction)
            if normal_force <= 0.0:
                continue
            active += 1
            normal[index] += normal_force
            total[index] += force_on_m if drake_m_side == "b" else -force_on_m
        self.max_contacts = max(self.max_contacts, active)
        return ContactForces(normal, total, active)
