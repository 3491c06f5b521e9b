"""Driving a reference run: which loop steps it, and its record turned into the run's
samples and statistics. Both loops live in the solver (:mod:`clearbench.ref_solver.compiled`
and its Python oracle :mod:`clearbench.ref_solver.python_loop`) and fill one record.

``step_loop`` (an option of the engine): ``auto`` (default) steps in the compiled loop
(:mod:`clearbench.ref_solver.compiled`) when it supports every feature of the run, else in the
Python loop; ``python`` and ``compiled`` force one (``compiled`` on a run it does not support
is an error naming the missing feature). The run's metadata says which ran
(``step_loop``) and, for the Python loop under ``auto``, the feature the compiled loop lacks
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
from clearbench.ref_solver.python_loop import PythonLoopTotals, advance_python
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


def run_steps(loop: StepLoop, stepper, state, steps: int, recorder, com: np.ndarray,
              statistics) -> tuple[RunStatus, str, float, int]:
    """Step ``state`` (updated in place) ``steps`` times in the loop ``loop`` chose (the
    compiled :func:`~clearbench.ref_solver.compiled.loop.advance` or its Python oracle
    :func:`~clearbench.ref_solver.python_loop.advance_python`, one contract), filling
    ``recorder`` (its step-0 sample stored) and ``statistics`` (:class:`RunStatistics`).

    Returns (status, message, stepping seconds, steps taken): a kernel exception is a crash
    whose last sample is the failing step's start, a non-finite state a divergence."""
    schedule = np.asarray(recorder.schedule, dtype=np.int64)
    record = StepRecord.allocate(stepper.system.body_count, recorder.contact_force.shape[1],
                                 steps, len(schedule))
    totals = PythonLoopTotals(solver_seconds=float("nan")) if loop.compiled \
        else PythonLoopTotals()
    status, message = RunStatus.OK, ""
    tick = time.perf_counter()
    try:
        if loop.compiled:
            system, settings = compile_system(stepper)
            code, t_end = advance(system, settings, _memory(stepper, copy=False), state.t,
                                  state.x, state.p, state.v, state.omega, steps, schedule,
                                  record)
        else:
            code, t_end = advance_python(stepper, state, steps, schedule, record, totals)
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
        recorder.store(*body_sample(state, com))
    if code == NON_FINITE:
        status, message = RunStatus.DIVERGED, f"non-finite state at step {taken}"
    statistics.add_record(record, taken, totals)
    return status, message, stepping, taken


def body_sample(state: State, com: np.ndarray) -> tuple:
    """(t, body-frame origins (nb, 3), quaternions (nb, 4), velocities (nb, 3), angular
    velocities (nb, 3)) of a solver state, whose positions are centres of mass ``com``
    (nb, 3) [L] (body frame)."""
    return (state.t, state.x - quat_rotate_batch(state.p, com), state.p, state.v,
            state.omega)


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

    def add_record(self, record: StepRecord, taken: int, totals: PythonLoopTotals) -> None:
        """The statistics of the ``taken`` steps completed in ``record`` (solver seconds NaN
        when the loop was compiled: not timed inside it)."""
        steps_done = np.arange(1, taken + 1)
        converged = record.step_converged[:taken]
        self.solver_seconds = totals.solver_seconds
        self.split_steps = int(np.sum(record.step_split[:taken]))
        self.contact_sweeps = int(record.step_sweeps[:taken].sum())
        self.roundoff_steps = int(np.sum(converged & (record.step_residual[:taken]
                                                      > self.tolerance)))
        self.unconverged = steps_done[~converged].tolist()
        self.unconverged_projection = steps_done[
            ~record.step_projection_converged[:taken]].tolist()
