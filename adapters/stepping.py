"""The step loop of every engine that steps in this process, and the runner protocol it drives.

:func:`step_loop` owns the loop of a run: the initial sample and energy, the engine's steps one
by one, the wall time spent in them, the steps taken, the solver statistics, the samples due
(:class:`~clearbench.adapters.recording.SampleRecorder`), the guards (a non-finite state, the
energy guard, the engine's own) and how a run that stops ends (diverged or crashed, the state
where it stopped kept as its last sample). An engine supplies a :class:`StepRunner`: what one
step, one state read-out and one contact read-out mean for it, in its internal units.

:class:`~clearbench.adapters.base.SteppingEngine` calls :func:`step_loop`; an engine's
``run.py`` holds its runner and no loop of its own. An engine whose own integrator takes
steps inside one call (Exudyn's reduced steps after a contact instant) reports each of them to
the monitor from its callback (:attr:`StepRunner.MONITORS_OWN_STEPS`: the loop then leaves
recording and guards to it).
"""

from __future__ import annotations

import contextlib
import logging
import time
from abc import ABC, abstractmethod
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any, ClassVar, NamedTuple

import numpy as np

from clearbench.adapters.energy_guard import EnergyGuard
from clearbench.adapters.step_monitor import StepMonitor
from clearbench.adapters.trajectory import RunStatus
from clearbench.scenarios.scene import Scene

__all__ = ["BodyState", "ContactForces", "SolverStep", "StepFailure", "StepRunner",
           "step_loop"]

logger = logging.getLogger(__name__)


class BodyState(NamedTuple):
    """The state of every scene body as an engine reads it (internal units): body-frame
    origins (nb, 3) [L], unit quaternions w,x,y,z (nb, 4), centre-of-mass velocities (nb, 3,
    world) [L/T], angular velocities (nb, 3, body axes) [1/T]; and, where the engine's reading
    gives them on the way, centres of mass (nb, 3) [L] and body rotations (nb, 3, 3) for its
    energy (None otherwise)."""

    positions: np.ndarray
    orientations: np.ndarray
    velocities: np.ndarray
    angular_velocities: np.ndarray
    centres_of_mass: np.ndarray | None = None
    rotations: np.ndarray | None = None


class ContactForces(NamedTuple):
    """Per scene contact pair: the sum of its normal forces (np,) and the total force on its
    body B (np, 3, world) [F, internal units] of the step just taken; and the number of
    contact points with a normal force."""

    normal: np.ndarray
    total: np.ndarray
    active: int


class SolverStep(NamedTuple):
    """The one-step problem's statistics of a step: iterations, whether it converged and its
    residual (None: the engine reports the residual per sample,
    :meth:`StepRunner.sample_residual`)."""

    iterations: int
    converged: bool
    residual: float | None = None


@dataclass(frozen=True)
class StepFailure:
    """Why the engine stopped the run: its status (diverged: the solver failed; crashed: the
    engine raised otherwise), the message, and whether the state where it stopped is kept as
    the last sample (when the engine's time moved past the last one)."""

    status: RunStatus
    message: str
    keep_state: bool = False


class StepRunner(ABC):
    """One run of a built model, as :func:`step_loop` drives it (internal units).

    Parameters
    ----------
    scene : Scene
        The scene as run (internal units).
    built
        The engine's model (``SteppingEngine.build``).
    config
        The run's settings (an :class:`~clearbench.adapters.engine_settings.EngineSettings`:
        ``energy_gain_tolerance`` and ``guard_interval`` set its energy guard).
    steps, record_every : int
        The run's step count and sampling.

    Attributes
    ----------
    monitor : StepMonitor
        Recorder, energy guard and solver statistics of the run.
    time : float
        The engine's current time [T] (the sample times).
    dt : float
        The nominal step [T].
    bookkeeping_seconds : float
        Wall time the engine's own callbacks spent recording and guarding inside
        :meth:`advance` [s] (taken out of the stepping time).
    """

    #: Whether the engine's energy counts torsional springs (it measures their angles); if not,
    #: the energy guard is off on scenes with torsional springs.
    COUNTS_TORSIONAL_SPRINGS: ClassVar[bool] = False
    #: Whether the engine reports each of its accepted steps to the monitor itself (its own
    #: callback calls :meth:`after_step`): the loop then only steps, times and counts.
    MONITORS_OWN_STEPS: ClassVar[bool] = False

    def __init__(self, scene: Scene, built: Any, config: Any, steps: int, record_every: int):
        self.scene = scene
        self.built = built
        self.config = config
        self.steps = steps
        self.time = 0.0
        self.dt = float(built.time_step)
        self.bookkeeping_seconds = 0.0
        self.monitor = StepMonitor(scene, steps, record_every, EnergyGuard(
            scene, config.energy_gain_tolerance, config.guard_interval,
            counts_torsional_springs=self.COUNTS_TORSIONAL_SPRINGS))

    # ------------------------------------------------------------------ engine hooks
    def prepare(self) -> None:
        """Before the initial state is read (default: nothing)."""
        return None

    def start(self) -> None:
        """After the initial sample, before step 1 (default: nothing)."""
        return None

    @abstractmethod
    def advance(self, step: int) -> StepFailure | None:
        """Apply the scene's inputs (drivers, loads) at the start of step ``step`` (1-based)
        and take it, ending at :attr:`time`; the failure when the engine could not. An engine
        with :attr:`MONITORS_OWN_STEPS` may take several steps of its own, or the whole run,
        in one call (later calls then return at once)."""

    def solver_step(self, step: int) -> SolverStep | None:
        """The one-step problem's statistics of step ``step`` (default: None, the engine does
        not say)."""
        return None

    def check(self, step: int) -> str | None:
        """The engine's own reason to stop after step ``step`` (default: none)."""
        return None

    @abstractmethod
    def read_state(self) -> BodyState:
        """The current state of every scene body."""

    @abstractmethod
    def energy(self, state: BodyState) -> tuple[float, float]:
        """(total, kinetic) mechanical energy of ``state``
        (:func:`~clearbench.scenarios.energy.mechanical_energy`)."""

    @abstractmethod
    def contact_forces(self) -> ContactForces:
        """The contact forces of the step just taken."""

    def sample_residual(self) -> float | None:
        """The solver statistics the engine reports per sample, at a sample after a step: it
        may add them to the recorder (``monitor.recorder.accumulate``); returns the sample's
        own residual (default None: the largest of its steps')."""
        return None

    def finish(self) -> None:
        """After the last step, or after :meth:`advance` returned a failure (not after an
        exception; default: nothing)."""
        return None

    def failure_of(self, error: Exception) -> StepFailure | None:
        """The failure an exception raised inside the run stands for (default: None, the
        exception goes to the caller: the harness records the run as crashed)."""
        return None

    @contextlib.contextmanager
    def session(self) -> Iterator[None]:
        """Context around the run's steps (default: none; an engine's output redirected, its
        warning handler installed)."""
        yield

    # ------------------------------------------------------------------ recording
    def store_sample(self, state: BodyState, with_contacts: bool = True) -> None:
        """Store ``state`` at :attr:`time` as the next sample; ``with_contacts``: with the
        step's contact forces and solver statistics (off for the initial state)."""
        contacts = residual = None
        if with_contacts:
            contacts = tuple(self.contact_forces())
            residual = self.sample_residual()
        self.monitor.recorder.store(self.time, state.positions, state.orientations,
                                    state.velocities, state.angular_velocities,
                                    contacts=contacts, residual=residual)

    def after_step(self, step: int, *, problem: str | None = None,
                   recording: bool | None = None, checking: bool | None = None) -> str | None:
        """Record and guard after step ``step`` at :attr:`time`
        (:meth:`StepMonitor.after_step`); the message that stops the run, else None."""
        return self.monitor.after_step(step, self.time, self.read_state, self.energy,
                                       self.store_sample, recording=recording,
                                       checking=checking, problem=problem)


def step_loop(runner: StepRunner, steps: int) -> tuple[RunStatus, str]:
    """Run ``steps`` steps of ``runner``; (status, message) of the run's end.

    The initial state is the first sample and the energy guard's start. Each step:
    :meth:`~StepRunner.advance` (timed: the monitor's stepping time, less the engine's own
    callbacks' bookkeeping), the step counted, its solver statistics, the engine's own check,
    then the sample if due and the guards (:meth:`StepRunner.after_step`: a non-finite state,
    an energy gain). A guard or a check that fires stops the run as diverged, the state that
    fired kept as the last sample; a failure of the engine stops it with its status.
    """
    monitor = runner.monitor
    runner.prepare()
    state = runner.read_state()
    runner.store_sample(state, with_contacts=False)
    monitor.guard.start(*runner.energy(state))
    with runner.session():
        try:
            runner.start()
            for step in range(1, steps + 1):
                tick = time.perf_counter()
                bookkeeping = runner.bookkeeping_seconds
                failure = runner.advance(step)
                monitor.stepping_seconds += (time.perf_counter() - tick
                                             - (runner.bookkeeping_seconds - bookkeeping))
                if failure is not None:
                    runner.finish()
                    return _stopped(runner, failure)
                monitor.steps_taken = step
                if runner.MONITORS_OWN_STEPS:
                    continue
                solver = runner.solver_step(step)
                if solver is not None:
                    monitor.solver_step(step, *solver)
                problem = runner.after_step(step, problem=runner.check(step))
                if problem is not None:
                    logger.info("%s: stopped: %s", runner.scene.name, problem)
                    return RunStatus.DIVERGED, problem
            runner.finish()
        except Exception as error:
            failure = runner.failure_of(error)
            if failure is None:
                raise
            return _stopped(runner, failure)
    return RunStatus.OK, ""


def _stopped(runner: StepRunner, failure: StepFailure) -> tuple[RunStatus, str]:
    """The end of a run the engine stopped: the state where it stopped kept as the last
    sample when asked and when the engine's time moved past the last sample."""
    recorder = runner.monitor.recorder
    if failure.keep_state and not recorder.is_full \
            and recorder.times[recorder.count - 1] < runner.time:
        runner.store_sample(runner.read_state())
    logger.info("%s: stopped: %s", runner.scene.name, failure.message)
    return failure.status, failure.message
