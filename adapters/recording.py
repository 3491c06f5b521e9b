"""Sampling a run into the arrays of the :class:`~clearbench.adapters.trajectory.Trajectory`
contract: the step count of a horizon, which steps are kept, and the recorder that keeps them.

A run of ``steps`` steps keeps step 0, every ``record_every``-th step and always the last
(:func:`record_schedule`). The solver statistics of the steps between two samples are
accumulated, not dropped: a sample carries the iterations summed, the largest residual and
"converged" only if every step since the previous sample converged, so that subsampling never
hides an unconverged step.

The reference and MuJoCo adapters record with :class:`SampleRecorder`. The Siconos worker keeps
its own few lines (``adapters/siconos/worker/engine.py``, in ``SiconosModel.run``): it runs
under Debian's Python 3 with numpy 1.24 and cannot import clearbench; loading this module
there by file path would tie the worker to the package's imports and Python version, for
a dozen lines of array bookkeeping whose output format the trajectory contract (and its tests)
already pins.
"""

from __future__ import annotations

import math

import numpy as np

from clearbench.adapters.trajectory import Trajectory, scene_fields
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.units import UnitSystem
from clearbench.scenarios.validation import ANGULAR_VELOCITY, FORCE, LENGTH, TIME, VELOCITY

__all__ = ["SampleRecorder", "record_schedule", "step_count"]


def step_count(horizon: float, time_step: float) -> int:
    """Steps of ``time_step`` that cover ``horizon`` (the last one may end past it; a horizon
    within 1e-9 steps of a whole number of steps is not rounded up)."""
    return int(math.ceil(horizon / time_step - 1e-9))


def record_schedule(steps: int, record_every: int) -> list[int]:
    """Steps kept as samples: 0, every ``record_every``-th step, and the last step."""
    schedule = list(range(0, steps + 1, record_every))
    if schedule[-1] != steps:
        schedule.append(steps)
    return schedule


class SampleRecorder:
    """Preallocated trajectory arrays filled sample by sample.

    Parameters
    ----------
    body_count, pair_count : int
        nb bodies and np contact pairs of the scene (its ``all_contacts``).
    steps, record_every : int
        The run's step count and sampling (see :func:`record_schedule`).

    Attributes
    ----------
    schedule : list of int
        The steps to keep; ``count`` samples are stored so far.
    times, positions, orientations, velocities, angular_velocities, contact_normal_force,
    contact_force, solver_iterations, solver_residual, solver_converged, active_contacts
        The arrays of the contract, (T, ...) with T = ``len(schedule)``, in the units the
        engine records in; a sample stored without contacts keeps 0 forces, 0 iterations,
        residual NaN, converged True and 0 active contacts.
    """

    def __init__(self, body_count: int, pair_count: int, steps: int, record_every: int):
        self.schedule = record_schedule(steps, record_every)
        samples = len(self.schedule)
        self.count = 0
        self.times = np.zeros(samples)
        self.positions = np.zeros((samples, body_count, 3))
        self.orientations = np.zeros((samples, body_count, 4))
        self.velocities = np.zeros((samples, body_count, 3))
        self.angular_velocities = np.zeros((samples, body_count, 3))
        self.contact_normal_force = np.zeros((samples, pair_count))
        self.contact_force = np.zeros((samples, pair_count, 3))
        self.solver_iterations = np.zeros(samples, dtype=np.int64)
        self.solver_residual = np.full(samples, np.nan)
        self.solver_converged = np.ones(samples, dtype=bool)
        self.active_contacts = np.zeros(samples, dtype=np.int64)
        self._iterations = 0
        self._residual = 0.0
        self._converged = True

    @property
    def is_full(self) -> bool:
        """True when every scheduled sample is stored."""
        return self.count >= len(self.schedule)

    def is_due(self, step: int) -> bool:
        """True when ``step`` is the next scheduled sample."""
        return not self.is_full and step == self.schedule[self.count]

    def accumulate(self, iterations: int, converged: bool, residual: float | None = None) -> None:
        """Add one step's solver statistics to those of the next sample (residual None: the
        engine reports it per sample, see :meth:`store`)."""
        self._iterations += iterations
        if residual is not None:
            self._residual = max(self._residual, residual)
        if not converged:
            self._converged = False

    def store(self, time: float, positions, orientations, velocities, angular_velocities,
              contacts: tuple | None = None, residual: float | None = None) -> None:
        """Store the next sample.

        Parameters
        ----------
        time : float [T]
        positions, orientations, velocities, angular_velocities : (nb, 3), (nb, 4), (nb, 3),
            (nb, 3)
            Body-frame origins (world), unit quaternions, centre-of-mass velocities (world) and
            angular velocities (body axes) [L, -, L/T, 1/T].
        contacts : (normal_force (np,), contact_force (np, 3), active_contacts int), optional
            Forces of the step just taken [F]; with them the accumulated solver statistics are
            stored and restarted. Without them (the initial state, the state a failed step
            started from) the statistics keep accumulating.
        residual : float, optional
            The recorded step's own residual, for engines that report it per sample (then it
            replaces the largest accumulated one).
        """
        i = self.count
        self.times[i] = time
        self.positions[i] = positions
        self.orientations[i] = orientations
        self.velocities[i] = velocities
        self.angular_velocities[i] = angular_velocities
        if contacts is not None:
            self.contact_normal_force[i], self.contact_force[i], self.active_contacts[i] = \
                contacts
            self.solver_iterations[i] = self._iterations
            self.solver_residual[i] = self._residual if residual is None else residual
            self.solver_converged[i] = self._converged
            self._iterations, self._residual, self._converged = 0, 0.0, True
        self.count = i + 1

    def trajectory(self, scene: Scene, time_step: float, recorded_units: UnitSystem | None = None,
                   **header) -> Trajectory:
        """The stored samples as the trajectory of a run of ``scene``.

        ``time_step`` and the samples are in ``recorded_units`` when given (an engine that runs
        in other units than the scene's: converted to the scene's here), else in the scene's
        units. ``header``: further Trajectory fields (engine, preset, status, ...).
        """
        n = self.count
        arrays = {name: getattr(self, name)[:n] for name in Trajectory.ARRAYS}
        if recorded_units is not None:
            for names, dimension in ((("times",), TIME), (("positions",), LENGTH),
                                     (("velocities",), VELOCITY),
                                     (("angular_velocities",), ANGULAR_VELOCITY),
                                     (("contact_normal_force", "contact_force"), FORCE)):
                factor = recorded_units.factor_to(scene.units, dimension)
                for name in names:
                    arrays[name] = arrays[name] * factor
            time_step = time_step * recorded_units.factor_to(scene.units, TIME)
        header.setdefault("engine", "")
        header.setdefault("preset", "")
        return Trajectory(**scene_fields(scene), time_step=time_step, **arrays, **header)
