"""The time loop in Python: N steps of :meth:`MoreauJeanStepper.step`, recorded into the
:class:`~clearbench.ref_solver.compiled.loop.StepRecord` the compiled loop fills.

:func:`advance_python` has the contract of the compiled :func:`~.compiled.loop.advance`
(state arrays updated in place, status codes, samples and per-step statistics, an exception
inside a kernel propagating with ``record.progress`` and the state of the last completed step)
so that one adapter drives either loop and the compiled loop is checked against this one, its
oracle (tests/test_compiled_loop.py). It also steps the features the compiled loop lacks
(:func:`~.compiled.support.unsupported_feature`), and measures what only Python can:
the contact solver's own seconds and the steps split by localised impacts
(:class:`PythonLoopTotals`).

The recording here is written with numpy (``np.bincount``), not with the compiled loop's
kernels, so that the oracle shares no recording code with what it checks.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from clearbench.ref_solver.compiled.loop import NON_FINITE, OK, UNCONVERGED, StepRecord
from clearbench.ref_solver.system import State

__all__ = ["PythonLoopTotals", "advance_python"]


@dataclass
class PythonLoopTotals:
    """What the Python loop measures beyond :class:`StepRecord`, over the steps completed:
    ``solver_seconds`` [s] wall time in the contact solver."""

    solver_seconds: float = 0.0


def advance_python(stepper, state: State, steps: int, schedule: np.ndarray,
                   record: StepRecord, totals: PythonLoopTotals) -> tuple[int, float]:
    """Advance ``state`` (its arrays updated in place after every completed step, ``t``
    left to the caller as with the compiled loop) by ``steps`` steps of ``stepper``
    (:class:`~clearbench.ref_solver.stepper.MoreauJeanStepper`), recording the steps of
    ``schedule`` (S,) (its first entry, step 0, is the caller's) into ``record`` and the
    Python-only totals into ``totals``.

    Returns (status code ``OK`` / ``UNCONVERGED`` / ``NON_FINITE``, the time at the end [T]).
    """
    h = stepper.settings.time_step
    pair_count = stepper.system.pair_count
    record.progress[0] = 1
    record.clock[0] = state.t
    sample = 1
    iterations, residual, converged = 0, 0.0, True
    status = OK
    current = state.copy()
    for k in range(1, steps + 1):
        result = stepper.step(current)
        current = result.state
        stats = result.statistics
        for mine, new in ((state.x, current.x), (state.p, current.p), (state.v, current.v),
                          (state.omega, current.omega)):
            mine[:] = new
        record.clock[0] = current.t
        record.step_iterations[k - 1] = stats.solver_iterations
        record.step_residual[k - 1] = stats.solver_residual
        record.step_converged[k - 1] = stats.solver_converged
        record.step_projection_converged[k - 1] = stats.projection_converged
        record.step_sweeps[k - 1] = stats.contact_sweeps
        record.step_split[k - 1] = stats.substeps > 1
        record.progress[1] = k
        totals.solver_seconds += stats.solver_seconds
        if not (stats.solver_converged and stats.projection_converged):
            status = UNCONVERGED
        iterations += stats.solver_iterations
        residual = max(residual, stats.solver_residual)
        converged = converged and stats.solver_converged
        finite = bool(np.isfinite(current.x).all() and np.isfinite(current.v).all()
                      and np.isfinite(current.omega).all())
        due = sample < schedule.shape[0] and k == schedule[sample]
        if due or (not finite and sample < schedule.shape[0]):
            _store_sample(record, sample, current, result, h, pair_count)
            record.solver_iterations[sample] = iterations
            record.solver_residual[sample] = residual
            record.solver_converged[sample] = converged
            iterations, residual, converged = 0, 0.0, True
            sample += 1
            record.progress[0] = sample
        if not finite:
            return NON_FINITE, current.t
    return status, current.t


def _store_sample(record: StepRecord, i: int, state: State, result, h: float,
                  pair_count: int) -> None:
    """Sample ``i``: the state, and per pair the normal force (np,) and the world force on
    body B (np, 3) [F], the step's impulses over its length ``h`` [T], and the count of
    active contacts of the step."""
    record.times[i] = state.t
    record.positions[i] = state.x
    record.orientations[i] = state.p
    record.velocities[i] = state.v
    record.angular_velocities[i] = state.omega
    pairs, slots = np.nonzero(result.contact_active)
    impulse = result.contact_impulse[pairs, slots]          # (k, 3) in contact frames
    world = np.einsum("kr,krj->kj", impulse, result.contact_frame[pairs, slots])
    record.contact_normal_force[i] = np.bincount(pairs, impulse[:, 0], pair_count) / h
    for axis in range(3):
        record.contact_force[i, :, axis] = np.bincount(pairs, world[:, axis], pair_count) / h
    record.active_contacts[i] = result.statistics.active_contacts
