"""The step loops of a reference run: which one steps it, the compiled loop and the Python
step, recording into the run's samples and statistics.

``step_loop`` (an option of the engine): ``auto`` (default) steps in the compiled loop
(:mod:`clearbench.ref_solver.compiled`) when it supports every feature of the run, else in the
Python step; ``python`` and ``compiled`` force one (``compiled`` on a run it does not support
is an error naming the missing feature). The run's metadata says which ran
(``step_loop``) and, for the Python step under ``auto``, the feature the compiled loop lacks
(``step_loop_fallback``).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from clearbench.adapters.options import OptionError
from clearbench.adapters.trajectory import RunStatus
from clearbench.kernels.quaternion import quat_rotate_batch
from clearbench.ref_solver.compiled.loop import NON_FINITE, StepRecord, advance
from clearbench.ref_solver.compiled.support import unsupported_feature
from clearbench.ref_solver.compiled.system_arrays import compile_system
from clearbench.ref_solver.system import State

STEP_LOOPS = ("auto", "python", "compiled")


@dataclass(frozen=True)
class StepLoop:
    """The loop chosen for a run: ``compiled`` or not, and why not (``fallback``)."""

    compiled: bool
    fallback: str = ""

    def metadata(self) -> dict:
        return {"step_loop": "compiled" if self.compiled else "python",
                "step_loop_fallback": self.fallback}


def choose_step_loop(option: str, stepper) -> StepLoop:
    """The loop of a run of ``stepper`` under the ``step_loop`` option (see the module
    docstring); a compiled choice compiles the loop now (or loads numba's cache), by one
    untimed step of copies of the stepper's state."""
    if option == "python":
        return StepLoop(False, "step_loop = python")
    missing = unsupported_feature(stepper)
    if missing is not None:
        if option == "compiled":
            raise OptionError("reference", "step_loop", option,
                              f"the compiled loop lacks a feature of this run: {missing}")
        return StepLoop(False, f"the compiled loop lacks {missing}")
    _warm_up(stepper)
    return StepLoop(True)


def _memory(stepper, copy: bool) -> tuple:
    """The stepper's warm starts and angle memory as the compiled loop takes them."""
    arrays = (stepper.previous_impulse, stepper.previous_bilateral,
              np.zeros(1, dtype=np.int64), stepper.angle_memory)
    return tuple(a.copy() for a in arrays) if copy else arrays


def _warm_up(stepper) -> None:
    """Compile (or load) the loop for this system's array types: a run of no step (numba
    compiles a function for its argument types, whatever it then does; later calls with the
    same types reuse it)."""
    system, settings = compile_system(stepper)
    nb, npair = stepper.system.body_count, stepper.system.pair_count
    record = StepRecord.allocate(nb, npair, 1, 2)
    zeros = np.zeros((nb, 3))
    p = np.zeros((nb, 4))
    p[:, 0] = 1.0
    advance(system, settings, _memory(stepper, copy=True), 0.0, zeros.copy(), p,
            zeros.copy(), zeros.copy(), 0, np.array([0]), record)


def run_compiled(stepper, state, steps: int, recorder, com: np.ndarray, statistics
                 ) -> tuple[RunStatus, str, float, int]:
    """Step ``state`` (updated in place) ``steps`` times in the compiled loop, filling
    ``recorder`` (its step-0 sample stored) and ``statistics`` (:class:`RunStatistics`).

    Returns (status, message, stepping seconds, steps taken), as the engine's Python loop
    ends them: a kernel exception is a crash whose last sample is the failing step's start, a
    non-finite state a divergence."""
    system, settings = compile_system(stepper)
    schedule = np.asarray(recorder.schedule, dtype=np.int64)
    record = StepRecord.allocate(system.fixed.shape[0], recorder.contact_force.shape[1],
                                 steps, len(schedule))
    status, message = RunStatus.OK, ""
    tick = time.perf_counter()
    try:
        code, t_end = advance(system, settings, _memory(stepper, copy=False), state.t,
                              state.x, state.p, state.v, state.omega, steps, schedule, record)
    except (ArithmeticError, ValueError, np.linalg.LinAlgError) as error:
        code, t_end = None, float(record.clock[0])
        k = int(record.progress[1]) + 1
        status = RunStatus.CRASHED
        message = (f"{type(error).__name__} in step {k} (from t = {t_end:.9g}; the last sample "
                   f"is that step's start): {error}")
    stepping = time.perf_counter() - tick
    state.t = t_end
    taken = int(record.progress[1])
    count = int(record.progress[0])
    for name in ("times", "orientations", "velocities", "angular_velocities",
                 "contact_normal_force", "contact_force", "active_contacts",
                 "solver_iterations", "solver_residual", "solver_converged"):
        getattr(recorder, name)[1:count] = getattr(record, name)[1:count]
    recorder.positions[1:count] = record.positions[1:count] - quat_rotate_batch(
        record.orientations[1:count], com)
    recorder.count = count
    if code is None and not recorder.is_full:
        recorder.store(state.t, state.x - quat_rotate_batch(state.p, com), state.p, state.v,
                       state.omega)
    if code == NON_FINITE:
        status, message = RunStatus.DIVERGED, f"non-finite state at step {taken}"
    steps_done = np.arange(1, taken + 1)
    converged = record.step_converged[:taken]
    statistics.solver_seconds = float("nan")  # not timed inside the compiled loop
    statistics.contact_sweeps = int(record.step_sweeps[:taken].sum())
    statistics.roundoff_steps = int(np.sum(converged & (record.step_residual[:taken]
                                                        > statistics.tolerance)))
    statistics.unconverged = steps_done[~converged].tolist()
    statistics.unconverged_projection = steps_done[
        ~record.step_projection_converged[:taken]].tolist()
    return status, message, stepping, taken


def run_python(stepper, state, steps: int, recorder, com: np.ndarray, statistics
               ) -> tuple[RunStatus, str, float, int]:
    """Step ``state`` ``steps`` times with the Python step (:meth:`Stepper.step`), filling
    ``recorder`` (its step-0 sample stored) and ``statistics`` (:class:`RunStatistics`).

    Returns (status, message, stepping seconds, steps taken): a kernel exception is a crash
    whose last sample is the failing step's start, a non-finite state a divergence."""
    h = stepper.settings.time_step
    pair_count = stepper.system.pair_count
    status, message = RunStatus.OK, ""
    stepping = 0.0
    taken = 0
    for k in range(1, steps + 1):
        tick = time.perf_counter()
        try:
            result = stepper.step(state)
        except (ArithmeticError, ValueError, np.linalg.LinAlgError) as error:
            # A failure inside a kernel is an outcome of the run: the state the step
            # started from is kept as the last sample, to reproduce it.
            if not recorder.is_full:
                recorder.store(*body_sample(state, com))
            status = RunStatus.CRASHED
            message = (f"{type(error).__name__} in step {k} (from t = {state.t:.9g}; the "
                       f"last sample is that step's start): {error}")
            break
        finally:
            stepping += time.perf_counter() - tick
        state = result.state
        taken = k
        finite = np.isfinite(state.x).all() and np.isfinite(state.v).all() and \
            np.isfinite(state.omega).all()
        stats = result.statistics
        recorder.accumulate(stats.solver_iterations, stats.solver_converged,
                            stats.solver_residual)
        statistics.add(k, stats)
        if recorder.is_due(k) or (not finite and not recorder.is_full):
            recorder.store(*body_sample(state, com), contacts=_contact_sample(
                result, h, pair_count))
        if not finite:
            status, message = RunStatus.DIVERGED, f"non-finite state at step {k}"
            break
    return status, message, stepping, taken


def body_sample(state: State, com: np.ndarray) -> tuple:
    """(t, body-frame origins (nb, 3), quaternions (nb, 4), velocities (nb, 3), angular
    velocities (nb, 3)) of a solver state, whose positions are centres of mass ``com``
    (nb, 3) [L] (body frame)."""
    return (state.t, state.x - quat_rotate_batch(state.p, com), state.p, state.v,
            state.omega)


def _contact_sample(result, h: float, pair_count: int) -> tuple:
    """Per pair, the normal force (np,) and the world force on body B (np, 3) [F], averaged
    over the step of length ``h`` [T], and the count of active contacts of the step."""
    pairs, slots = np.nonzero(result.contact_active)
    impulse = result.contact_impulse[pairs, slots]          # (k, 3) in contact frames
    world = np.einsum("kr,krj->kj", impulse, result.contact_frame[pairs, slots])
    normal = np.bincount(pairs, impulse[:, 0], pair_count) / h
    force = np.zeros((pair_count, 3))
    for axis in range(3):
        force[:, axis] = np.bincount(pairs, world[:, axis], pair_count) / h
    return normal, force, result.statistics.active_contacts


@dataclass
class RunStatistics:
    """The reference's own statistics of a run, over every step (recorded or not)."""

    tolerance: float
    roundoff_steps: int = 0  # accepted on the round-off floor (residual above tolerance)
    solver_seconds: float = 0.0
    contact_sweeps: int = 0
    split_steps: int = 0  # computed in substeps (localised impacts)
    unconverged: list[int] = field(default_factory=list)
    unconverged_projection: list[int] = field(default_factory=list)

    def add(self, step: int, stats) -> None:
        """Count the statistics of step ``step`` (1-based)."""
        self.solver_seconds += stats.solver_seconds
        self.contact_sweeps += stats.contact_sweeps
        self.split_steps += stats.substeps > 1
        if stats.solver_converged and stats.solver_residual > self.tolerance:
            self.roundoff_steps += 1
        if not stats.solver_converged:
            self.unconverged.append(step)
        if not stats.projection_converged:
            self.unconverged_projection.append(step)
