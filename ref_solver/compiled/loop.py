"""The time loop compiled whole: N steps of :func:`.step.single_step`, recorded into
preallocated arrays, one numba call per run.

:func:`advance` is the loop; :class:`StepRecord` holds what it records: the samples of the
run's schedule (state, contact forces, the solver statistics accumulated since the previous
sample, as ``adapters.recording.SampleRecorder`` keeps them) and every step's statistics.
The loop stops at the first non-finite state (status ``NON_FINITE``); a step whose contact
problem or projection did not converge is recorded and the loop goes on (status
``UNCONVERGED`` at the end), as the Python path does. An exception inside a kernel (a
singular matrix) leaves the arrays as they were after the last completed step:
``progress`` says how far the loop got.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from clearbench.ref_solver.compiled.step import single_step
from clearbench.ref_solver.compiled.system_arrays import (
    CompiledSystem,
    LoopSettings,
    history_length,
)
from clearbench.ref_solver.forces import remember_angles, rotation_matrices
from clearbench.ref_solver.projection_kernel import candidates

#: Status codes of :func:`advance`.
OK, UNCONVERGED, NON_FINITE = 0, 1, 2
STATUS_NAMES = {OK: "ok", UNCONVERGED: "unconverged", NON_FINITE: "non-finite"}


@dataclass
class StepRecord:
    """What :func:`advance` records, preallocated for ``steps`` steps and ``samples`` samples.

    Samples (index 0 is the initial state, filled by the caller): ``times`` (S,) [T],
    ``positions`` (S, nb, 3) centres of mass [L], ``orientations`` (S, nb, 4),
    ``velocities`` (S, nb, 3) [L/T], ``angular_velocities`` (S, nb, 3) [1/T] body axes,
    ``contact_normal_force`` (S, np) and ``contact_force`` (S, np, 3) world, on body B [F]
    (the step's impulse over h), ``active_contacts`` (S,), and the solver statistics of the
    steps since the previous sample: ``solver_iterations`` (S,) summed, ``solver_residual``
    (S,) largest, ``solver_converged`` (S,) all. Steps (index k - 1 for step k):
    ``step_iterations``, ``step_residual``, ``step_converged``, ``step_projection_converged``,
    ``step_sweeps`` (iterations x contacts, summed over the step's solves), ``step_split``
    (computed in substeps: a localised impact). ``progress`` (2,): samples stored, steps
    completed; ``clock`` (1,): the time after the last completed step [T].
    """

    times: np.ndarray
    positions: np.ndarray
    orientations: np.ndarray
    velocities: np.ndarray
    angular_velocities: np.ndarray
    contact_normal_force: np.ndarray
    contact_force: np.ndarray
    active_contacts: np.ndarray
    solver_iterations: np.ndarray
    solver_residual: np.ndarray
    solver_converged: np.ndarray
    step_iterations: np.ndarray
    step_residual: np.ndarray
    step_converged: np.ndarray
    step_projection_converged: np.ndarray
    step_sweeps: np.ndarray
    progress: np.ndarray
    clock: np.ndarray
    step_split: np.ndarray

    @classmethod
    def allocate(cls, body_count: int, pair_count: int, steps: int, samples: int) -> StepRecord:
        nb, npair, s = body_count, pair_count, samples
        return cls(
            times=np.zeros(s), positions=np.zeros((s, nb, 3)),
            orientations=np.zeros((s, nb, 4)), velocities=np.zeros((s, nb, 3)),
            angular_velocities=np.zeros((s, nb, 3)), contact_normal_force=np.zeros((s, npair)),
            contact_force=np.zeros((s, npair, 3)), active_contacts=np.zeros(s, np.int64),
            solver_iterations=np.zeros(s, np.int64), solver_residual=np.full(s, np.nan),
            solver_converged=np.ones(s, np.bool_), step_iterations=np.zeros(steps, np.int64),
            step_residual=np.zeros(steps), step_converged=np.ones(steps, np.bool_),
            step_projection_converged=np.ones(steps, np.bool_),
            step_sweeps=np.zeros(steps, np.int64), progress=np.zeros(2, np.int64),
            clock=np.zeros(1), step_split=np.zeros(steps, np.bool_))

    def arrays(self) -> tuple:
        """The arrays in the argument order of :func:`_advance`."""
        return (self.times, self.positions, self.orientations, self.velocities,
                self.angular_velocities, self.contact_normal_force, self.contact_force,
                self.active_contacts, self.solver_iterations, self.solver_residual,
                self.solver_converged, self.step_iterations, self.step_residual,
                self.step_converged, self.step_projection_converged, self.step_sweeps,
                self.progress, self.clock, self.step_split)


@njit(cache=True)
def _store_state(rec, i, t, x, p, v, omega):
    rec[0][i] = t
    rec[1][i] = x
    rec[2][i] = p
    rec[3][i] = v
    rec[4][i] = omega


@njit(cache=True)
def _store_contacts(rec, i, h, impulses, frames, active):
    """Per pair the normal force and the world force on body B [F] of the step's impulses
    (``engine._contact_sample``), the active count and the accumulated statistics."""
    normal, force = rec[5][i], rec[6][i]
    normal[:] = 0.0
    force[:] = 0.0
    count = 0
    for pair in range(active.shape[0]):
        for k in range(active.shape[1]):
            if active[pair, k]:
                count += 1
                normal[pair] += impulses[pair, k, 0]
                for j in range(3):
                    force[pair, j] += (impulses[pair, k, 0] * frames[pair, k, 0, j]
                                       + impulses[pair, k, 1] * frames[pair, k, 1, j]
                                       + impulses[pair, k, 2] * frames[pair, k, 2, j])
    normal /= h
    force /= h
    rec[7][i] = count


@njit(cache=True)
def _advance(s, cfg, memory, t, x, p, v, omega, steps, schedule, history, rec):
    """Steps 1..``steps`` from (t, x, p, v, omega) (updated in place after every completed
    step); the samples of ``schedule`` (S,) (steps, 0 first) into ``rec`` (see
    :class:`StepRecord`). Returns (status code, t at the end)."""
    progress = rec[16]
    sample = np.int64(1)  # np.int64: a literal 1 would compile the _store_* kernels twice
    iterations, residual, converged = 0, 0.0, True
    status = OK
    # The candidates at the step's start: the previous step's closing test computed them.
    cand = candidates(s.geometry, x, rotation_matrices(p))
    for k in range(1, steps + 1):
        (x1, p1, v1, omega1, impulses, frames, active, its, res, ok, projection_ok,
         sweeps, cand, split) = single_step(s, cfg, memory, t, x, p, v, omega, history, cand)
        remember_angles(rotation_matrices(p1), s.force_kind, s.force_body_a, s.force_body_b,
                        s.force_parameters, memory[3])
        t = t + cfg.time_step
        rec[17][0] = t
        x[:] = x1
        p[:] = p1
        v[:] = v1
        omega[:] = omega1
        rec[11][k - 1] = its
        rec[12][k - 1] = res
        rec[13][k - 1] = ok
        rec[14][k - 1] = projection_ok
        rec[15][k - 1] = sweeps
        rec[18][k - 1] = split
        progress[1] = k
        if not (ok and projection_ok):
            status = UNCONVERGED
        iterations += its
        residual = max(residual, res)
        converged = converged and ok
        finite = np.isfinite(x).all() and np.isfinite(v).all() and np.isfinite(omega).all()
        due = sample < schedule.shape[0] and k == schedule[sample]
        if due or (not finite and sample < schedule.shape[0]):
            _store_state(rec, sample, t, x, p, v, omega)
            _store_contacts(rec, sample, cfg.time_step, impulses, frames, active)
            rec[8][sample] = iterations
            rec[9][sample] = residual
            rec[10][sample] = converged
            iterations, residual, converged = 0, 0.0, True
            sample += 1
            progress[0] = sample
        if not finite:
            return NON_FINITE, t
    return status, t


def advance(system: CompiledSystem, settings: LoopSettings, memory: tuple, t: float,
            x: np.ndarray, p: np.ndarray, v: np.ndarray, omega: np.ndarray, steps: int,
            schedule: np.ndarray, record: StepRecord) -> tuple[int, float]:
    """Advance the state (t [T], x (nb, 3) [L], p (nb, 4), v (nb, 3) [L/T], omega (nb, 3)
    [1/T], arrays updated in place) by ``steps`` steps, recording the steps of ``schedule``
    (S,) int64 (its first entry, step 0, is the caller's) into ``record``.

    ``memory``: (previous impulses (npair, K, 3), previous bilateral impulses (nbil,),
    newton_first (1,) int64, angle memory (nf, 2)), the stepper's warm starts and angle
    memory, updated in place. Returns (status code ``OK`` / ``UNCONVERGED`` / ``NON_FINITE``,
    the time at the end [T]). Kernel exceptions (``ValueError``, ``ZeroDivisionError``,
    ``np.linalg.LinAlgError``) propagate, with ``record.progress`` and the state those of the
    last completed step.
    """
    record.progress[0] = 1
    record.clock[0] = t
    history = np.empty(history_length(settings))
    status, t_end = _advance(system, settings, memory, float(t), x, p, v, omega, int(steps),
                             np.ascontiguousarray(schedule, dtype=np.int64), history,
                             record.arrays())
    return int(status), float(t_end)
