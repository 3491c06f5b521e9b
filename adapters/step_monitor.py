"""The bookkeeping after each step of a run, shared by every stepping engine.

The step loop (:func:`clearbench.adapters.stepping.step_loop`, or the engine's own callback
after each of its steps, as Exudyn's) calls one :class:`StepMonitor`: it records the due
samples (:class:`~clearbench.adapters.recording.SampleRecorder`), checks that the state is
finite, runs the energy guard (:class:`~clearbench.adapters.energy_guard.EnergyGuard`), keeps
the state that stopped the run as its last sample, counts the steps whose one-step problem did
not converge and the wall time spent stepping. The base class reads the run's statistics
from it into the :class:`~clearbench.adapters.trajectory.Trajectory`.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from clearbench.adapters.energy_guard import EnergyGuard
from clearbench.adapters.recording import SampleRecorder
from clearbench.scenarios.scene import Scene

#: Unconverged step numbers a trajectory keeps (their count is kept whole).
UNCONVERGED_KEPT = 1000


class StepMonitor:
    """Recorder, guards and solver statistics of one run (the engine's internal units).

    Parameters
    ----------
    scene : Scene
        The scene as run (internal units).
    steps, record_every : int
        The run's step count and sampling.
    guard : EnergyGuard
        The run's energy guard (its tolerance, interval and what the engine's energy counts).

    Attributes
    ----------
    recorder : SampleRecorder
    guard : EnergyGuard
    unconverged : list of int
        Steps (1-based, of the run) whose one-step problem did not converge.
    stepping_seconds : float
        Wall time inside the engine's step calls [s] (the loop adds it).
    steps_taken : int
        Steps completed.
    """

    def __init__(self, scene: Scene, steps: int, record_every: int, guard: EnergyGuard):
        self.recorder = SampleRecorder(len(scene.bodies), len(scene.all_contacts), steps,
                                       record_every)
        self.guard = guard
        self.unconverged: list[int] = []
        self.stepping_seconds = 0.0
        self.steps_taken = 0

    def solver_step(self, step: int, iterations: int, converged: bool,
                    residual: float | None = None) -> None:
        """The solver statistics of step ``step``: added to the next sample's, and the step
        counted when it did not converge."""
        self.recorder.accumulate(iterations, converged, residual)
        if not converged:
            self.unconverged.append(step)

    def after_step(self, step: int, time: float, read_state: Callable[[], Sequence],
                   energy: Callable[[Sequence], tuple[float, float]],
                   store: Callable[[Sequence], None], *, recording: bool | None = None,
                   checking: bool | None = None, problem: str | None = None) -> str | None:
        """Record, check and guard after step ``step`` ending at ``time`` [T]; the message
        that stops the run (non-finite state, energy gain, or the engine's own ``problem``),
        else None.

        Parameters
        ----------
        read_state : callable
            The current state as a sequence of arrays (None parts skipped; read only when
            needed).
        energy : callable
            (total, kinetic) mechanical energy of a state [internal energy unit].
        store : callable
            Stores a state as the next sample (with the step's contact forces).
        recording, checking : bool, optional
            Whether a sample is due, and whether the guard checks (default: the recorder's
            schedule and the guard's interval by ``step``; an engine whose steps leave the
            time grid decides them itself).
        problem : str, optional
            The engine's own reason to stop at this step (its state is still kept as the
            last sample).
        """
        recording = self.recorder.is_due(step) if recording is None else recording
        checking = self.guard.due(step) if checking is None else checking
        state = None
        if problem is None and (recording or checking):
            state = read_state()
            if not all(np.isfinite(part).all() for part in state if part is not None):
                problem = f"non-finite state at step {step} (t = {time:.6g})"
            elif self.guard.applies:
                problem = self.guard.check(*energy(state), time)
        if recording or (problem is not None and not self.recorder.is_full):
            store(state if state is not None else read_state())
        return problem

    def statistics(self) -> dict:
        """The typed fields of the run's trajectory this monitor knows: ``unconverged_steps``
        (the first :data:`UNCONVERGED_KEPT` step numbers), ``unconverged_count`` and
        ``energy_max_gain`` (the guard's largest gain over the energy scale; NaN where the
        guard is off)."""
        return {"unconverged_steps": tuple(self.unconverged[:UNCONVERGED_KEPT]),
                "unconverged_count": len(self.unconverged),
                "energy_max_gain": self.guard.max_gain if self.guard.applies else float("nan")}
