"""One MuJoCo run as the shared step loop drives it (:mod:`clearbench.adapters.stepping`):
drivers, loads, guards, read-out into trajectory samples.

Works on a model built by :mod:`.build`, in the model's internal units (the engine converts the
samples back to the scene's units). Each sample's residual is MuJoCo's own for the recorded
step; iterations and convergence are accumulated over the steps between samples. A step is
``mj_step1``, the loads of the step start (:meth:`Runner.apply_loads`), ``mj_step2``.
"""

from __future__ import annotations

import contextlib
import logging
import math

import numpy as np

from clearbench.adapters.mujoco.settings import MujocoSettings
from clearbench.adapters.stepping import BodyState, ContactForces, SolverStep, StepRunner
from clearbench.kernels.poses import shifted_velocities
from clearbench.kernels.time_profiles import evaluate_profile_slope
from clearbench.scenarios.energy import mechanical_energy
from clearbench.scenarios.loads import LinearSpringDamper, Moment, PointForce, TorsionalSpringDamper
from clearbench.scenarios.scene import Scene

logger = logging.getLogger(__name__)


class Runner(StepRunner):
    """Drivers, loads, guards and read-out of one run (see the module docstring)."""

    #: MuJoCo's hinge springs and the explicit torsional springs keep their angles.
    COUNTS_TORSIONAL_SPRINGS = True

    def __init__(self, scene: Scene, built, config: MujocoSettings, steps: int,
                 record_every: int):
        import mujoco  # lazy import of the engine package (the adapter imports without it)

        super().__init__(scene, built, config, steps, record_every)
        self.mujoco = mujoco
        self.model, self.data = built.model, built.data
        model = self.model
        self.ids = built.body_ids
        self.warnings: list[str] = []
        self.mujoco_warnings: dict[str, int] = {}
        self.max_contacts = 0
        self._springs = [load for load in scene.loads if isinstance(load, LinearSpringDamper)]
        self._site_ids = [(model.site(f"{s.name}:a").id, model.site(f"{s.name}:b").id)
                          for s in self._springs]
        self._hinge_springs = built.hinge_springs
        step_times = np.arange(steps + 1) * self.dt
        self._drive = []
        for dof in built.driven:
            driver = dof.driver
            position = np.asarray(driver.displacement(step_times), dtype=float)
            velocity = np.asarray(driver.velocity(step_times), dtype=float)
            if driver.quantity == "position":
                acceleration = np.zeros_like(step_times)
            else:
                acceleration = evaluate_profile_slope(driver.times, driver.values, step_times)
            armature = model.dof_armature[dof.dof_address]
            self._drive.append((dof, dof.initial + dof.sign * position, dof.sign * velocity,
                                armature * dof.sign * acceleration))

    # ------------------------------------------------------------------ guards
    @contextlib.contextmanager
    def session(self):
        """MuJoCo's text warnings sent to logging (instead of MUJOCO_LOG.TXT in the working
        directory) and kept for the metadata; the previous handler restored."""
        mujoco = self.mujoco
        previous = mujoco.get_mju_user_warning()

        def handler(text: str) -> None:
            logger.warning("mujoco: %s", text)
            if len(self.warnings) < 100:
                self.warnings.append(f"mujoco: {text}")

        mujoco.set_mju_user_warning(handler)
        try:
            yield
        finally:
            mujoco.set_mju_user_warning(previous)

    def check(self, step: int) -> str | None:
        """A fatal MuJoCo warning, or a non-finite qpos or qvel, after step ``step``."""
        data = self.data
        self.max_contacts = max(self.max_contacts, int(data.ncon))
        problem = self._check_warnings()
        if problem is None and not (np.isfinite(data.qpos).all()
                                    and np.isfinite(data.qvel).all()):
            problem = f"non-finite state at step {step} (t = {data.time:.6g})"
        return problem

    def _check_warnings(self) -> str | None:
        counts = self.data.warning.number
        if not counts.any():
            return None
        names = {int(value): name for name, value in self.mujoco.mjtWarning.__members__.items()
                 if name != "mjNWARNING"}
        fatal = ("mjWARN_BADQPOS", "mjWARN_BADQVEL", "mjWARN_BADQACC", "mjWARN_CONTACTFULL",
                 "mjWARN_CNSTRFULL")
        message = None
        for index, count in enumerate(counts):
            if count and index in names:
                name = names[index]
                if count != self.mujoco_warnings.get(name, 0):
                    self.mujoco_warnings[name] = int(count)
                    if name in fatal and message is None:
                        message = f"MuJoCo warning {name} at t = {self.data.time:.6g}"
        return message

    # ------------------------------------------------------------------ state
    def refresh_kinematics(self) -> None:
        """Poses and velocities of the current qpos/qvel (mj_step leaves them one step old);
        contact and constraint arrays are left untouched."""
        mj = self.mujoco
        mj.mj_kinematics(self.model, self.data)
        mj.mj_comPos(self.model, self.data)
        mj.mj_comVel(self.model, self.data)

    def prepare(self) -> None:
        """Kinematics of the initial qpos/qvel."""
        self.refresh_kinematics()
        self.time = self.data.time

    def read_state(self) -> BodyState:
        """:meth:`body_state` after :meth:`refresh_kinematics` (the contact forces of the step
        are not touched by the refresh)."""
        self.refresh_kinematics()
        return self.body_state()

    def body_state(self) -> BodyState:
        """Body-frame poses, centre-of-mass velocities (world) and angular velocities (body
        axes) of every scene body: (nb, 3), (nb, 4), (nb, 3), (nb, 3)."""
        d, ids = self.data, self.ids
        rotation = d.xmat[ids].reshape(-1, 3, 3)
        omega = d.cvel[ids, :3]
        offset = d.xipos[ids] - d.subtree_com[self.model.body_rootid[ids]]
        velocity = shifted_velocities(d.cvel[ids, 3:], omega, offset)
        omega_body = np.einsum("bji,bj->bi", rotation, omega)
        return BodyState(d.xpos[ids].copy(), d.xquat[ids].copy(), velocity, omega_body)

    def energy(self, state: BodyState) -> tuple[float, float]:
        """(total, kinetic) mechanical energy of ``state``, the :meth:`body_state` of the
        current configuration (:func:`~clearbench.scenarios.energy.mechanical_energy`:
        kinetic, gravity, linear and torsional springs; internal units)."""
        d, ids = self.data, self.ids
        velocity, omega = state.velocities, state.angular_velocities
        sites = dict(zip((load.name for load in self._springs), self._site_ids, strict=True))

        def spring_points(load):
            site_a, site_b = sites[load.name]
            return d.site_xpos[site_a], d.site_xpos[site_b]

        torsion = {load.name: sign * d.qpos[qadr] for load, qadr, sign in self._hinge_springs}
        torsion.update({item.load.name: item.angle for item in self.built.python_loads
                        if isinstance(item.load, TorsionalSpringDamper)})
        energy = mechanical_energy(self.scene, d.xipos[ids], velocity, omega, spring_points,
                                   torsion)
        return float(energy.total), float(energy.kinetic)

    # ------------------------------------------------------------------ loads
    def apply_loads(self) -> None:
        """xfrc_applied of point forces, moments, explicit torsional springs and law loads at
        the state of the step start (kinematics from mj_step1)."""
        d = self.data
        laws = self.built.law_forces
        if not self.built.python_loads and laws is None:
            return
        d.xfrc_applied[:] = 0.0
        if laws is not None:
            laws.apply(d)
        t = d.time
        for item in self.built.python_loads:
            load = item.load
            b = item.body_id
            rotation = d.xmat[b].reshape(3, 3)
            if isinstance(load, PointForce | Moment):
                end = math.inf if load.end_time is None else load.end_time
                if not load.start_time <= t < end:
                    continue
                if isinstance(load, PointForce):
                    force = np.asarray(load.force, dtype=float)
                    force = rotation @ force if load.frame == "body" else force
                    point = d.xpos[b] + rotation @ np.asarray(load.point, dtype=float)
                    d.xfrc_applied[b, :3] += force
                    d.xfrc_applied[b, 3:] += np.cross(point - d.xipos[b], force)
                else:
                    moment = np.asarray(load.moment, dtype=float)
                    d.xfrc_applied[b, 3:] += rotation @ moment if load.frame == "body" \
                        else moment
                continue
            a_id, b_id = item.body_id, item.other_id
            rotation_a = d.xmat[a_id].reshape(3, 3)
            rotation_b = d.xmat[b_id].reshape(3, 3)
            axis = rotation_a @ item.axis_in_a
            ref_a = rotation_a @ item.reference_a
            ref_b = rotation_b @ item.reference_b
            angle = math.atan2(float(axis @ np.cross(ref_a, ref_b)), float(ref_a @ ref_b))
            previous = math.remainder(item.angle, 2.0 * math.pi)
            item.angle += math.remainder(angle - previous, 2.0 * math.pi)
            rate = float(axis @ (d.cvel[b_id, :3] - d.cvel[a_id, :3]))
            moment = -(load.preload + load.stiffness * (item.angle - load.rest_angle)
                       + load.damping * rate) * axis
            d.xfrc_applied[b_id, 3:] += moment
            d.xfrc_applied[a_id, 3:] -= moment

    # ------------------------------------------------------------------ steps
    def advance(self, step: int) -> None:
        """Drivers at their profile's values at the step start, ``mj_step1``, the loads,
        ``mj_step2``."""
        mj = self.mujoco
        model, data = self.model, self.data
        for dof, position, velocity, force in self._drive:
            data.qpos[dof.qpos_address] = position[step - 1]
            data.qvel[dof.dof_address] = velocity[step - 1]
            data.qfrc_applied[dof.dof_address] = force[step - 1]
        mj.mj_step1(model, data)
        self.apply_loads()
        mj.mj_step2(model, data)
        self.time = data.time
        return None

    def solver_step(self, step: int) -> SolverStep:
        """Iterations (largest over islands) of the step; converged below the cap."""
        data = self.data
        islands = min(max(int(data.nisland), 1), len(data.solver_niter))
        niter = int(data.solver_niter[:islands].max())
        return SolverStep(niter, niter < self.model.opt.iterations)

    # ------------------------------------------------------------------ read-out
    def contact_forces(self) -> ContactForces:
        """Per scene pair: normal force sum (npair,) and total force on body B, world
        (npair, 3), from the constraint forces of the step just taken; and active contacts."""
        mj = self.mujoco
        model, data = self.model, self.data
        npair = len(self.scene.all_contacts)
        normal = np.zeros(npair)
        total = np.zeros((npair, 3))
        active = 0
        wrench = np.zeros(6)
        for i in range(data.ncon):
            contact = data.contact[i]
            if contact.exclude != 0 or contact.efc_address < 0:
                continue
            key = tuple(sorted((int(contact.geom[0]), int(contact.geom[1]))))
            pair = self.built.pair_lookup.get(key)
            if pair is None:
                continue
            mj.mj_contactForce(model, data, i, wrench)
            if wrench[0] <= 0.0:
                continue
            active += 1
            frame = contact.frame.reshape(3, 3)
            world = frame.T @ wrench[:3]
            sign = 1.0 if model.geom_bodyid[contact.geom[1]] == self.built.contact_body_b[pair] \
                else -1.0
            normal[pair] += wrench[0]
            total[pair] += sign * world
        return ContactForces(normal, total, active)

    def sample_residual(self) -> float:
        """MuJoCo's own residual of the recorded step (the largest over islands)."""
        data = self.data
        islands = min(max(int(data.nisland), 1), len(data.solver_niter))
        worst = 0.0
        for island in range(islands):
            n = int(data.solver_niter[island])
            if n > 0:
                stat = data.solver[island * self.mujoco.mjNSOLVER + min(n, self.mujoco.mjNSOLVER)
                                   - 1]
                worst = max(worst, float(stat.gradient))
        return worst
