"""The reference engine's runs of the C-60 studies (``clearbench c60 validate``, ``clearbench c60
identify``), made through the one run pipeline: each run is a
:class:`~clearbench.harness.run.spec.RunSpec` run by a
:class:`~clearbench.harness.run.runner.Runner` in an isolated worker process with a wall-clock
limit and recorded in a :class:`~clearbench.harness.run.store.ResultsStore` under its run key
(the scene's content, which records the model variant, the engine and preset, the settings and
the package's code), like every other run: a repeated study serves its runs from the store, a
changed scene, preset or code runs them again. A run that crashed, timed out or diverged is a
recorded outcome the studies report with its status, not an error.

A study first asks for every run it knows it needs (:meth:`StudyRuns.make`: one batch, run in
parallel with the runner's ``jobs``), then reads each one (:meth:`StudyRuns.get`), which makes
a run the batch did not hold (one that depends on the others' figures) on its own.
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field

from clearbench.adapters.trajectory import Trajectory
from clearbench.harness.run.engine_choice import EngineChoice, resolve_engine
from clearbench.harness.run.runner import Runner
from clearbench.harness.run.spec import RunSpec, make_run_spec
from clearbench.harness.run.store import ResultsStore
from clearbench.scenarios.scene import Scene

#: Wall-clock limit of one run of the studies when none is given [s]. The longest run, the
#: contact-force test (52,600 steps), steps in 634 s on this 2-core machine
#: (reports/c60_validation.json, ``stepping_seconds``); a shared machine slows a run by up to
#: 10 times (a c60-trip of 58 s of CPU took more than 600 s under a load of 15 on 2 cores,
#: :mod:`clearbench.harness.studies.c60_comparison`), so the limit is 11 times that run.
DEFAULT_TIMEOUT = 7200.0


@dataclass(frozen=True)
class RunRequest:
    """One run a study asks for: its name in the study's report (``on_nominal``), the
    registered scene, the scene factory's parameters and one recorded sample every
    ``record_every`` steps."""

    name: str
    scene_name: str
    parameters: Mapping = field(default_factory=dict)
    record_every: int = 10


@dataclass(frozen=True)
class Run:
    """One run of a study as the store holds it.

    ``status`` and ``message``: the run's outcome as recorded (ok, diverged, crashed,
    timed_out, unsupported; :class:`~clearbench.harness.run.store.RunRecord`);
    ``trajectory``: None when the run left none (crashed, timed out, unsupported);
    ``figures``: the harness's figures of the run (:mod:`clearbench.harness.measure.figures`);
    ``store_key``: its key in the store (its trajectory is ``trajectories/KEY.npz`` there).
    """

    key: str
    scene: Scene
    trajectory: Trajectory | None
    status: str
    message: str
    store_key: str
    figures: Mapping = field(default_factory=dict)

    @property
    def ok(self) -> bool:
        return self.status == "ok"

    @property
    def ended(self) -> str:
        """``ended STATUS``, with the message when there is one."""
        return f"ended {self.status}" + (f" ({self.message})" if self.message else "")

    @property
    def usable(self) -> bool:
        """The run left a trajectory of at least two samples to measure."""
        return self.trajectory is not None and len(self.trajectory.times) >= 2

    @property
    def unconverged(self) -> list:
        """Steps whose contact problem did not converge (the first 1,000)."""
        if self.trajectory is None:
            return []
        return list(self.trajectory.unconverged_steps)

    @property
    def unconverged_count(self) -> int:
        """How many steps' contact problem did not converge (all of them)."""
        return 0 if self.trajectory is None else int(self.trajectory.unconverged_count)

    @property
    def unconverged_projections(self) -> list:
        """Steps whose projection did not reach its tolerance."""
        if self.trajectory is None:
            return []
        return list(self.trajectory.metadata.get("unconverged_projections", []))

    @property
    def steps(self) -> int:
        return self.trajectory.steps if self.trajectory is not None else 0

    @property
    def stepping_seconds(self) -> float:
        """Wall time of stepping [s] (NaN without a trajectory)."""
        return self.trajectory.stepping_seconds if self.trajectory is not None else math.nan

    @property
    def penetration(self) -> float:
        """Largest contact penetration over the recorded states [mm]: the harness's figure
        ``penetration_max`` (0 for a scene without contacts, NaN when not measured)."""
        if not self.scene.expanded.contacts:
            return 0.0
        return float(self.figures.get("penetration_max", math.nan))


class StudyRuns:
    """The runs of a C-60 study in ``store``, made by ``runner`` with ``engine`` (default the
    reference engine's default preset).

    Parameters
    ----------
    store : ResultsStore
    runner : Runner, optional
        Makes the runs (None: a runner of the default parallelism on ``store``).
    engine : EngineChoice or str
        The engine and preset of every run (``reference[PRESET]``).
    timeout : float
        Wall-clock limit of each run [s].
    run_missing : bool
        False: make no run; a run the store does not hold is None (:meth:`get`).
    rerun : bool
        Run every run again once, even when the store holds it.
    campaign : str
        Recorded with each run (which command asked for it).
    options : Mapping, optional
        The engine's run options of every run (``clearbench run --option``), for instance a
        scheme variant of the reference to validate (checked with the first run's spec).
    """

    def __init__(self, store: ResultsStore, runner: Runner | None = None,
                 engine: EngineChoice | str = "reference", timeout: float = DEFAULT_TIMEOUT,
                 run_missing: bool = True, rerun: bool = False, campaign: str = "c60",
                 options: Mapping | None = None):
        self.store = store
        self.runner = runner if runner is not None else Runner(store)
        self.engine = resolve_engine(engine) if isinstance(engine, str) else engine
        self.timeout = timeout
        self.run_missing = run_missing
        self.rerun = rerun
        self.campaign = campaign
        self.options = dict(options or {})
        #: Store keys of the runs made by this object, and of those served from the store.
        self.made: list[str] = []
        self.reused: list[str] = []
        self._done: set[str] = set()
        self._specs: dict[tuple, RunSpec] = {}

    @property
    def preset(self) -> str:
        return self.engine.preset

    @property
    def settings_label(self) -> str:
        """The preset and the options of the runs, as a report names them
        (``default`` or ``default; options activation=predicted``)."""
        if not self.options:
            return self.preset
        given = ", ".join(f"{key}={value}" for key, value in sorted(self.options.items()))
        return f"{self.preset}; options {given}"

    def spec(self, request: RunRequest) -> RunSpec:
        """The run spec of ``request`` (validated: an unknown scene or parameter raises
        :class:`~clearbench.harness.run.engine_choice.RunInputError`)."""
        identity = (request.scene_name, json.dumps(dict(request.parameters), sort_keys=True),
                    request.record_every)
        if identity not in self._specs:
            self._specs[identity] = make_run_spec(
                request.scene_name, self.engine.label, scene_parameters=request.parameters,
                record_every=request.record_every, options=self.options,
                timeout=self.timeout, engine_choice=self.engine, campaign=self.campaign)
        return self._specs[identity]

    def make(self, requests: Iterable[RunRequest]) -> None:
        """Make, in one batch, every run of ``requests`` the store cannot serve (with
        ``rerun``: every one not made yet by this object); nothing when not ``run_missing``."""
        specs = [self.spec(request) for request in requests]
        specs = [spec for spec in specs if spec.key not in self._done]
        if not specs or not self.run_missing:
            return
        outcome = self.runner.run_all(specs, rerun=self.rerun)
        self.made += outcome.ran
        self.reused += outcome.skipped
        self._done.update(spec.key for spec in specs)

    def get(self, request: RunRequest) -> Run | None:
        """The run of ``request`` from the store, made first if needed (:meth:`make`); None
        when it is not stored and not ``run_missing``."""
        spec = self.spec(request)
        self.make([request])
        row = self.store.get(spec.key)
        if row is None:
            return None
        trajectory = self.store.load_trajectory(spec.key) if row["trajectory"] else None
        if trajectory is not None and trajectory.scene_hash != spec.scene.content_hash:
            trajectory = None
        return Run(request.name, spec.scene, trajectory, row["status"], row["message"] or "",
                   spec.key, json.loads(row["metrics"] or "{}"))
