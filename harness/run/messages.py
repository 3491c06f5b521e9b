"""The messages of a run between the runner, its worker process and the results store.

The runner sends a :class:`WorkerRequest`; the worker answers with a :class:`RanMessage` (the
engine's outcome, as the engine reported it, and the trajectory written to disk) and then a
:class:`MeasuredMessage` (the run's figures, its expectations and its status after the
harness's own checks); the store assembles its row from the spec and both
(:meth:`clearbench.harness.run.store.RunRecord.from_messages`). A request that only measures
(``measure_only``: a stored trajectory whose measuring code changed) gets the second answer
alone.

Two statuses, named apart:

- the engine's status (``RanMessage.status``): what the engine or the worker reported
  (:class:`~clearbench.adapters.trajectory.RunStatus`), stored as ``engine_status``;
- the run's status (``MeasuredMessage.status``): the engine's, unless the harness's checks of
  the trajectory (non-finite values, tunnelling, a joint come apart, a journal out of its
  bore) find it diverged; stored as ``status``. The run's verdict (pass, physics failed, ...,
  :func:`clearbench.harness.measure.verdicts.run_verdict`) follows from it and the
  expectations.

Each message is a frozen dataclass of plain data (it crosses a process boundary by pickle);
its defaults are those of a run that produced nothing, stated once here.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from clearbench.adapters.trajectory import RunStatus
from clearbench.harness.run.spec import RunSpec
from clearbench.scenarios.serialization import scene_to_dict

__all__ = ["MeasuredMessage", "RanMessage", "WorkerRequest"]


@dataclass(frozen=True)
class WorkerRequest:
    """One run (or one measurement) asked of a worker.

    Attributes
    ----------
    key : str
        The run key.
    scene : dict
        The scene as plain data (:func:`~clearbench.scenarios.serialization.scene_to_dict`).
    module, preset : str
        The engine's adapter module and preset.
    engine_version : str
        The engine and its version, as its availability probe stated them for the spec.
    time_step, horizon : float
        [scene time unit].
    record_every : int
    options : dict
        Checked when the spec was made.
    capabilities : dict
        Feature -> [support, detail], computed once from the spec.
    trajectory_path : str
        Where the worker writes the trajectory (or, ``measure_only``, the stored one it reads).
    reference_path, reference_label : str
        The trajectory the run's error is measured against ('' when none) and its name.
    measure_only : bool
        Measure the stored trajectory at ``trajectory_path``; run nothing.
    """

    key: str
    scene: dict
    module: str
    preset: str
    engine_version: str
    time_step: float
    horizon: float
    record_every: int
    options: dict
    capabilities: dict
    trajectory_path: str
    reference_path: str = ""
    reference_label: str = ""
    measure_only: bool = False

    @classmethod
    def of(cls, spec: RunSpec, trajectory_path: str, reference_path: str = "",
           reference_label: str = "", measure_only: bool = False) -> WorkerRequest:
        """The request of run ``spec`` (its capabilities computed, once, unless
        ``measure_only``)."""
        return cls(key=spec.key, scene=scene_to_dict(spec.scene), module=spec.engine.module,
                   preset=spec.engine.preset, engine_version=spec.engine.detail,
                   time_step=spec.time_step, horizon=spec.horizon,
                   record_every=spec.record_every, options=spec.options_dict,
                   capabilities={} if measure_only else spec.capabilities,
                   trajectory_path=str(trajectory_path), reference_path=reference_path,
                   reference_label=reference_label, measure_only=measure_only)


@dataclass(frozen=True)
class RanMessage:
    """The worker's first answer: how the engine's run ended (wall times [s]).

    ``status`` is the engine's own (or, when the worker died or raised, the worker's:
    crashed, timed out); ``trajectory_saved`` says whether the trajectory was written.
    """

    status: str = RunStatus.CRASHED.value
    message: str = ""
    engine_version: str = ""
    capabilities: dict = field(default_factory=dict)
    worker_seconds: float = math.nan
    build_seconds: float = math.nan
    stepping_seconds: float = math.nan
    steps: int = 0
    samples: int = 0
    trajectory_saved: bool = False


@dataclass(frozen=True)
class MeasuredMessage:
    """The worker's second answer: the run's measurement.

    ``status`` is the run's status after the harness's checks of the trajectory (None: nothing
    was measured: no trajectory, or the measuring phase died), ``reason`` why it differs from
    the engine's; ``figures`` name -> value (scene units), ``expectations`` one dict per
    judged expectation, ``error_source`` what the headline error is measured against,
    ``metrics_error`` the figures that could not be computed and why, ``seconds`` the
    measuring phase's wall time [s].
    """

    status: str | None = None
    reason: str = ""
    figures: dict = field(default_factory=dict)
    expectations: list = field(default_factory=list)
    error_source: str = ""
    metrics_error: str = ""
    seconds: float = 0.0
