"""One Exudyn run as the shared step loop drives it (:mod:`clearbench.adapters.stepping`):
solver settings, recording, guards, read-out.

Exudyn is stepped by its own ``MainSolverImplicitSecondOrder`` (``InitializeSolver`` in
:meth:`Runner.start`, ``SolveSteps`` in :meth:`Runner.advance`, ``FinalizeSolver`` in
:meth:`Runner.finish`). Its solver may reduce its step on its own, so the runner reports each
accepted step to the monitor from Exudyn's PostStep callback (``MONITORS_OWN_STEPS``). Option
``step_loop``: 'horizon' makes one ``SolveSteps`` call over the whole run (the loop's first
step; the later ones return at once), as ``exu.SolveDynamic`` does, and leaves Exudyn's step
control alone: after a step reduced to a contact instant it keeps the short steps through the
impact and grows them back after ``adaptiveStepRecoverySteps`` good steps; a sample is the
first step end at or after its time, so sample times can leave the grid by less than a step.
'grid' (the presets) makes one call per nominal step ending on the grid; each call restarts
at the nominal step (``SolveSteps`` resets ``currentStepSize``), so impacts are integrated
with full steps (measured in docs/engines/exudyn.md). A PostStep user function (called
after every accepted step, after the discontinuous iterations, and once more at the start of
each call: skipped) records samples and runs the guards, and stops the solver by returning
False. A PreStep function applies explicit law loads.

Guards:
- files: ``solution.file.write``, ``solution.sensors.active``, restart files, verbose files
  off (Exudyn writes ``solution/coordinatesSolution.txt`` by default);
- stdout: Exudyn prints through Python's ``sys.stdout`` (not file descriptor 1), e.g. its
  "DYNAMIC SOLVER FAILED" banner: ``exudyn.config.printToConsole`` is switched off and
  ``sys.stdout`` redirected during the solve; anything caught goes to the metadata;
- solver failure: ``SolveSteps`` returning False or raising ``SolverError`` /
  ``ExudynError`` (Newton failure after the step reductions, singular Jacobian) stops the run
  as DIVERGED with the reason read from the solver's flags (:mod:`.failure`: which of Newton,
  the discontinuous iteration or step reduction failed, step size, residual; CRASHED for other
  exceptions);
- non-finite state, and energy gain on scenes whose energy may not grow
  (:class:`~clearbench.adapters.energy_guard.EnergyGuard`, shared): DIVERGED.
"""

from __future__ import annotations

import contextlib
import io
import time

import numpy as np

from clearbench.adapters.exudyn.build import BuiltSystem, load_exudyn
from clearbench.adapters.exudyn.failure import failed_loop, failure_reason
from clearbench.adapters.exudyn.idle_connectors import IdleConnectors, culling_wanted
from clearbench.adapters.exudyn.settings import ExudynSettings
from clearbench.adapters.stepping import BodyState, ContactForces, StepFailure, StepRunner
from clearbench.adapters.trajectory import RunStatus
from clearbench.kernels.quaternion import quat_from_matrix_batch
from clearbench.scenarios.bodies import Motion
from clearbench.scenarios.energy import mechanical_energy, rigid_spring_points
from clearbench.scenarios.loads import LinearSpringDamper, PointForce
from clearbench.scenarios.scene import Scene

#: Exudyn's timers kept in the metadata (``solver.timer``; wall seconds).
TIMERS = ("jacobianODE2", "jacobianAE", "ODE2RHS", "AERHS", "massMatrix", "factorization",
          "postNewton", "python", "reactionForces")


def simulation_settings(settings: ExudynSettings, time_step: float, steps: int,
                        closed_loop: bool = False):
    """``exu.SimulationSettings`` of a run: the preset's solver options, every output off
    (``closed_loop``: the scene's joints close a loop, see ``closed_loop_full_pivot``)."""
    exu = load_exudyn()
    s = exu.SimulationSettings()
    ti = s.timeIntegration
    ti.numberOfSteps = steps
    ti.endTime = steps * time_step
    ti.startTime = 0.0
    ti.verboseMode = 0
    ti.verboseModeFile = 0
    ti.adaptiveStep = settings.adaptive_step
    ti.minimumStepSize = settings.minimum_step_fraction * time_step
    ti.generalizedAlpha.spectralRadius = settings.spectral_radius
    index2 = settings.solver == "TrapezoidalIndex2"
    ti.generalizedAlpha.useNewmark = index2
    ti.generalizedAlpha.useIndex2Constraints = index2
    ti.newton.useModifiedNewton = settings.modified_newton
    ti.newton.relativeTolerance = settings.newton_relative_tolerance
    ti.newton.absoluteTolerance = settings.newton_absolute_tolerance
    ti.newton.maxIterations = settings.newton_max_iterations
    ti.discontinuous.maxIterations = settings.discontinuous_max_iterations
    ti.discontinuous.iterationTolerance = settings.discontinuous_tolerance
    ti.discontinuous.useRecommendedStepSize = settings.recommended_step
    full_pivot = closed_loop and settings.closed_loop_full_pivot
    solver = "EigenDense" if full_pivot else settings.linear_solver
    s.linearSolver.solverType = getattr(exu.LinearSolverType, solver)
    s.linearSolver.ignoreSingularJacobian = full_pivot or settings.ignore_singular_jacobian
    s.solution.file.write = False
    s.solution.file.writeInitialValues = False
    s.solution.sensors.active = False
    s.solution.restart.write = False
    s.show.computationTime = False
    # Exudyn's timers (Jacobians, residuals, Python user functions; read into the metadata)
    # run only with this flag; it also prints them at the end, into the captured stdout.
    s.displayComputationTime = True
    s.show.statistics = False
    return s


class Runner(StepRunner):
    """Solver settings, callbacks, recording and guards of one run (model units; see the
    module docstring)."""

    MONITORS_OWN_STEPS = True

    def __init__(self, scene: Scene, built: BuiltSystem, config: ExudynSettings, steps: int,
                 record_every: int):
        super().__init__(scene, built, config, steps, record_every)
        self.recorder = self.monitor.recorder
        # Reduced steps make Exudyn's time leave the grid: a sample is the first step end at
        # or after its time.
        self.record_times = np.asarray(self.recorder.schedule, dtype=float) * self.dt
        self.min_normal_force = 0.0
        self.solver_steps = 0
        self.problem: str | None = None
        self._simulation = None
        self._finalized = False
        self.captured_stdout = ""
        self.error_string = ""
        self.exudyn_error_string = ""
        self.force_scale_value: float | None = None
        self._call_start = False
        self.newton_absolute_tolerance = config.newton_absolute_tolerance
        self.failed_loop = ""
        self.mass = np.array([b.mass for b in scene.bodies])
        self.movable = np.array([b.motion is not Motion.FIXED for b in scene.bodies])
        self.gravity = np.asarray(scene.gravity, dtype=float)
        self._springs = [(load, scene.body_index(load.body_a), scene.body_index(load.body_b))
                         for load in scene.loads if isinstance(load, LinearSpringDamper)]
        self._newton_count = 0
        self._last_newton = 0
        self._discontinuous_failures = 0
        self.discontinuous_failures_total = 0
        self._solver = None
        self._last_time = 0.0
        self._law_cache: tuple[bytes, np.ndarray] | None = None
        self.idle: IdleConnectors | None = None
        if culling_wanted(config.cull_idle_connectors, len(built.connectors)):
            self.idle = IdleConnectors.from_plans(
                scene, built.pair_plans, [ref.object for ref in built.connectors],
                built.bodies.com)
        self._idle_acceleration = 0.0

    # ------------------------------------------------------------------ state
    def state(self):
        """Origins (nb, 3), quaternions (nb, 4), rotations (nb, 3, 3), centre-of-mass
        velocities (nb, 3) and body-axis angular velocities (nb, 3) of the current state."""
        bodies = self.built.bodies
        if not bodies.euler_parameters:
            position, rotation, velocity, omega = bodies.node_state(self.built.mbs)
            return position, quat_from_matrix_batch(rotation), rotation, velocity, omega
        data = self.built.mbs.systemData
        return bodies.euler_parameter_state(data.GetODE2Coordinates(),
                                            data.GetODE2Coordinates_t())

    def read_state(self) -> BodyState:
        """:meth:`state` as a :class:`~clearbench.adapters.stepping.BodyState` (rotations
        kept)."""
        position, quaternion, rotation, velocity, omega = self.state()
        return BodyState(position, quaternion, velocity, omega, None, rotation)

    def energy(self, state: BodyState) -> tuple[float, float]:
        """(total, kinetic) mechanical energy of ``state`` (:meth:`read_state`):
        :func:`~clearbench.scenarios.energy.mechanical_energy` with linear springs (model
        units)."""
        position, rotation = state.positions, state.rotations
        velocity, omega = state.velocities, state.angular_velocities
        com = position + np.einsum("bij,bj->bi", rotation, self.built.bodies.com)
        energy = mechanical_energy(self.scene, com, velocity, omega,
                                   rigid_spring_points(self.scene, position, rotation))
        return float(energy.total), float(energy.kinetic)

    def force_scale(self, state: BodyState) -> float:
        """The scene's force scale [F, model units]: the largest applied force in the
        configuration ``state`` (weights, point forces, linear springs with their preload, the
        forces of the law loads); moments are left out (a moment has no force scale without a
        lever)."""
        position, rotation = state.positions, state.rotations
        forces = [self.mass[self.movable] * float(np.linalg.norm(self.gravity))]
        forces += [[float(np.linalg.norm(load.force))] for load in self.scene.loads
                   if isinstance(load, PointForce)]
        for load, a, b in self._springs:
            pa = position[a] + rotation[a] @ np.asarray(load.point_a)
            pb = position[b] + rotation[b] @ np.asarray(load.point_b)
            stretch = np.linalg.norm(pb - pa) - load.rest_length
            forces.append([abs(load.preload + load.stiffness * stretch)])
        laws = self.built.law_forces
        if laws is not None:
            com = position + np.einsum("bij,bj->bi", rotation, self.built.bodies.com)
            wrench = laws.wrenches(0.0, com, rotation)
            forces.append(np.linalg.norm(wrench[:, :3], axis=1))
        return float(max((np.max(f, initial=0.0) for f in forces), default=0.0))

    # ------------------------------------------------------------------ read-out
    def contact_forces(self) -> ContactForces:
        """Per scene pair: normal force sum (npair,) and total force on body B (npair, 3,
        world) of the current state; and the number of connectors in contact (gap < 0, as
        stored by Exudyn's last PostNewton). Keeps the most negative normal force sum (Exudyn
        does not clip it at zero)."""
        exu = load_exudyn()
        mbs = self.built.mbs
        npair = len(self.scene.all_contacts)
        normal = np.zeros(npair)
        total = np.zeros((npair, 3))
        if not self.built.connectors:
            self.min_normal_force = min(self.min_normal_force, 0.0)
            return ContactForces(normal, total, 0)
        gaps = np.asarray(mbs.systemData.GetDataCoordinates())
        active = 0
        for ref in self.built.connectors:
            if gaps[ref.data_index] >= 0.0:
                continue
            force = np.asarray(mbs.GetObjectOutput(ref.object, exu.OutputVariableType.Force))
            if not force.any():
                continue
            n0 = np.asarray(mbs.GetObjectOutput(ref.object,
                                                exu.OutputVariableType.Director1))
            active += 1
            normal[ref.pair] += -float(force @ n0)  # Force acts on the sphere; n0 points away
            total[ref.pair] += ref.sign * force
        self.min_normal_force = min(self.min_normal_force, float(np.min(normal, initial=0.0)))
        return ContactForces(normal, total, active)

    @property
    def count(self) -> int:
        """Samples stored so far."""
        return self.recorder.count

    def sample_residual(self) -> float | None:
        """Exudyn's Newton iterations since the previous sample and whether every
        discontinuous iteration since then succeeded, added to the recorder; the solver's
        residual of the recorded step."""
        solver = self._solver
        if solver is None:
            return None
        count = int(solver.it.newtonStepsCount)
        self.recorder.accumulate(count - self._last_newton, self._discontinuous_failures == 0)
        self._last_newton = count
        self._discontinuous_failures = 0
        return float(solver.conv.residual)

    # ------------------------------------------------------------------ user functions
    def _pre_step(self, mbs, t: float) -> bool:
        if self._call_start:
            self._call_start = False
            solver = self._solver
            if self.config.keep_jacobian and solver is not None and \
                    int(solver.it.newtonJacobiCount) > 0:
                # SolveSteps requests a Jacobian at the start of every call; the grid loop's
                # calls continue one run, so the previous call's Jacobian is kept, as within
                # one call (modified Newton updates it when it stops contracting).
                solver.conv.jacobianUpdateRequested = False
        laws = self.built.law_forces
        explicit_laws = laws is not None and self.config.law_loads == "explicit"
        if self.idle is None and not explicit_laws:
            return True
        state = self.read_state()  # read once for both uses below
        if self.idle is not None:
            self._switch_idle_connectors(mbs, t, state)
        if not explicit_laws:
            return True
        position, rotation = state.positions, state.rotations
        com = position + np.einsum("bij,bj->bi", rotation, self.built.bodies.com)
        wrench = laws.wrenches(t, com, rotation)
        for b, force, torque in self.built.law_loads:
            mbs.SetLoadParameter(force, "loadVector", wrench[b, :3].tolist())
            mbs.SetLoadParameter(torque, "loadVector", wrench[b, 3:].tolist())
        return True

    def _switch_idle_connectors(self, mbs, t: float, state) -> None:
        """Switch the connectors that cannot touch within the margin off and the others on
        for the coming step (:mod:`.idle_connectors`); ``state`` as :meth:`read_state`."""
        position, rotation = state.positions, state.rotations
        velocity, omega = state.velocities, state.angular_velocities
        idle = self.idle
        margin = idle.margin(velocity, omega, self._idle_acceleration, self.dt)
        for index in idle.update(position, rotation, margin, t):
            mbs.SetObjectParameter(int(idle.objects[index]), "activeConnector",
                                   bool(idle.active[index]))

    def _law_wrench(self, mbs, t: float) -> np.ndarray:
        """Law wrenches at the current Newton iterate, cached per state vector."""
        q = np.asarray(mbs.systemData.GetODE2Coordinates())
        key = q.tobytes()
        if self._law_cache is None or self._law_cache[0] != key:
            position, _, rotation, _, _ = self.state()
            com = position + np.einsum("bij,bj->bi", rotation, self.built.bodies.com)
            self._law_cache = (key, self.built.law_forces.wrenches(t, com, rotation))
        return self._law_cache[1]

    def _install_implicit_laws(self) -> None:
        mbs = self.built.mbs
        for b, force, torque in self.built.law_loads:
            def force_function(mbs, t, load, b=b):
                return self._law_wrench(mbs, t)[b, :3].tolist()

            def torque_function(mbs, t, load, b=b):
                return self._law_wrench(mbs, t)[b, 3:].tolist()

            mbs.SetLoadParameter(force, "loadVectorUserFunction", force_function)
            mbs.SetLoadParameter(torque, "loadVectorUserFunction", torque_function)
            self.built.keep_alive += [force_function, torque_function]

    def _post_step(self, mbs, t: float) -> bool:
        if t <= self._last_time:  # the call of SolveSteps at the start of each nominal step
            return True
        self._last_time = t
        self.time = t
        tick = time.perf_counter()
        self.solver_steps += 1
        solver = self._solver
        if solver is not None and not solver.conv.discontinuousIterationSuccessful:
            self._discontinuous_failures += 1
            self.discontinuous_failures_total += 1
        data = mbs.systemData
        q = np.asarray(data.GetODE2Coordinates())
        problem = None
        if not (np.isfinite(q).all() and np.isfinite(np.asarray(data.GetODE2Coordinates_t()))
                .all()):
            problem = f"non-finite state at t = {t:.6g}"
        if self.built.law_forces is not None:
            self.built.law_forces.remember(self.state()[2])
        recording = (self.count < len(self.record_times)
                     and t >= self.record_times[self.count] - 1e-6 * self.dt)
        problem = self.after_step(self.solver_steps, recording=recording,
                                  checking=self.monitor.guard.due(self.solver_steps),
                                  problem=problem)
        self.bookkeeping_seconds += time.perf_counter() - tick
        if problem is not None:
            self.problem = problem
            return False
        return True

    # ------------------------------------------------------------------ steps
    def prepare(self) -> None:
        """The solver's settings, with Newton's absolute tolerance from the force scale of the
        initial state where asked, and the idle connectors' acceleration bound."""
        closed_loop = "closed_loop" in self.scene.features
        s = simulation_settings(self.config, self.dt, self.steps, closed_loop)
        self._simulation = s
        if closed_loop and self.config.closed_loop_full_pivot:
            self.monitor.guard.notes.append("closed loop: EigenDense full-pivot LU with "
                                            "ignoreSingularJacobian (redundant constraints)")
        state = self.read_state()
        if self.config.newton_force_tolerance is not None:
            self.force_scale_value = self.force_scale(state)
            if self.force_scale_value > 0.0:
                s.timeIntegration.newton.absoluteTolerance = (
                    self.config.newton_force_tolerance * self.force_scale_value)
        self.newton_absolute_tolerance = s.timeIntegration.newton.absoluteTolerance
        if self.idle is not None:
            # A body at rest that starts to move: the applied-force scale over the lightest
            # moving mass bounds its acceleration (idle_connectors.IdleConnectors.margin).
            lightest = float(np.min(self.mass[self.movable], initial=np.inf))
            if np.isfinite(lightest) and lightest > 0.0:
                self._idle_acceleration = self.force_scale(state) / lightest

    @contextlib.contextmanager
    def session(self):
        """Exudyn's console output off and ``sys.stdout`` captured (kept for the metadata)."""
        exu = load_exudyn()
        previous = exu.config.printToConsole
        exu.config.printToConsole = False
        buffer = io.StringIO()
        try:
            with contextlib.redirect_stdout(buffer):
                yield
        finally:
            exu.config.printToConsole = previous
            self.captured_stdout = buffer.getvalue()

    def start(self) -> None:
        """The user functions installed, the solver initialised."""
        exu = load_exudyn()
        mbs = self.built.mbs
        mbs.SetPostStepUserFunction(self._post_step)
        if self.built.law_forces is not None and self.config.law_loads == "implicit":
            self._install_implicit_laws()
        if (self.built.law_forces is not None and self.config.law_loads == "explicit") or (
                self.config.keep_jacobian and self.config.step_loop == "grid") or \
                self.idle is not None:
            mbs.SetPreStepUserFunction(self._pre_step)
        solver = exu.MainSolverImplicitSecondOrder()
        self._solver = solver
        if not solver.InitializeSolver(mbs, self._simulation):
            raise exu.SolverError("InitializeSolver failed: " + solver.GetErrorString())
        self._last_newton = int(solver.it.newtonStepsCount)

    def advance(self, step: int) -> StepFailure | None:
        """``SolveSteps`` to the end of nominal step ``step`` ('grid'), or over the whole run
        at the first step ('horizon'); the stop a callback asked for, or the solver's
        failure, with the reason read from its flags."""
        mbs, solver, s = self.built.mbs, self._solver, self._simulation
        if self.config.step_loop == "horizon":
            if step > 1:
                return None
            success = solver.SolveSteps(mbs, s)
        else:
            solver.it.endTime = step * self.dt
            self._call_start = True
            success = solver.SolveSteps(mbs, s)
        if self.problem is None and success:
            return None
        self.finish()
        self.time = mbs.systemData.GetTime()
        if self.problem is not None:
            return StepFailure(RunStatus.DIVERGED, self.problem, keep_state=True)
        self._read_failure(solver, s)
        return StepFailure(RunStatus.DIVERGED, f"Exudyn solver failed at t = "
                           f"{mbs.systemData.GetTime():.6g}: {self.error_string}",
                           keep_state=True)

    def finish(self) -> None:
        if not self._finalized:
            self._finalized = True
            self._solver.FinalizeSolver(self.built.mbs, self._simulation)

    def failure_of(self, error: Exception) -> StepFailure | None:
        """An Exudyn error (a SolverError: diverged; another: crashed) or an exception of a
        Python user function or of the adapter (crashed), with the solver's flags read."""
        exu = load_exudyn()
        mbs = self.built.mbs
        if isinstance(error, exu.ExudynError):  # SolverError and the other Exudyn errors
            if self._solver is not None:
                self._read_failure(self._solver, self._simulation)
            status = RunStatus.DIVERGED if isinstance(error, exu.SolverError) \
                else RunStatus.CRASHED
            message = (f"Exudyn {type(error).__name__} at t = {mbs.systemData.GetTime():.6g}: "
                       f"{error} ({self.error_string})")
        else:
            status, message = RunStatus.CRASHED, f"{type(error).__name__}: {error}"
        self.time = mbs.systemData.GetTime()
        return StepFailure(status, message, keep_state=True)

    def solver_statistics(self) -> dict:
        """Exudyn's counters and timers of the run [s, wall]: Newton iterations, Jacobians,
        discontinuous iterations, and the time in Jacobians, residuals and Python user
        functions (``solver.timer``)."""
        solver = self._solver
        if solver is None:
            return {}
        timer = solver.timer
        return {"newton_iterations": int(solver.it.newtonStepsCount),
                "jacobians": int(solver.it.newtonJacobiCount),
                "discontinuous_iterations": int(solver.it.discontinuousIterationsCount),
                "timers": {name: float(getattr(timer, name)) for name in TIMERS},
                "idle_connectors": None if self.idle is None else self.idle.statistics()}

    def _read_failure(self, solver, simulation) -> None:
        """The failure's reason from the solver's flags (:mod:`.failure`; Exudyn's own error
        string, whose Newton and discontinuous-iteration flags are printed inverted, is kept
        as it is in ``exudyn_error_string``)."""
        self.exudyn_error_string = solver.GetErrorString()
        self.failed_loop = failed_loop(solver.conv)
        self.error_string = failure_reason(solver, simulation)
