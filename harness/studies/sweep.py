"""Work–precision sweeps: every scene x engine over a ladder of time steps, error against
stepping time, and the Pareto front.

The error of a run is the analytic one where the scene has an analytic reference
(:func:`clearbench.harness.measure.figures.has_analytic_reference`); otherwise the run's named
outputs are compared with the reference solver's at a fine step (``fine_factor`` times the
smallest step of the ladder), which the sweep runs first.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from clearbench.harness.measure.figures import has_analytic_reference
from clearbench.harness.run.engine_choice import EngineChoice, RunInputError, resolve_engine
from clearbench.harness.run.runner import RunJob, Runner, SweepOutcome
from clearbench.harness.run.spec import DEFAULT_TIMEOUT, RunSpec, make_run_spec, resolve_scene
from clearbench.scenarios.scene import Scene

LOG = logging.getLogger(__name__)

#: Default ladder: the scene's comfortable step, then halved twice.
DEFAULT_LADDER = "1x,0.5x,0.25x"
#: Fine reference step, relative to the smallest step of the ladder.
FINE_FACTOR = 0.25
#: Engine that computes the fine reference trajectories.
REFERENCE_ENGINE = "reference"


@dataclass(frozen=True)
class LadderStep:
    """A time step: absolute [scene time unit] or relative to the scene's comfortable step."""

    value: float
    relative: bool

    def resolve(self, scene: Scene) -> float:
        return self.value * scene.time_step if self.relative else self.value

    def __str__(self) -> str:
        return f"{self.value:g}x" if self.relative else f"{self.value:g}"


def parse_ladder(text: str, field_name: str = "--dt") -> tuple[LadderStep, ...]:
    """``'1x,0.5x,1e-4'`` -> ladder steps (``x``: times the scene's comfortable step)."""
    steps = []
    for item in str(text).replace(" ", "").split(","):
        if not item:
            continue
        relative = item.endswith("x")
        number = item[:-1] if relative else item
        try:
            value = float(number)
        except ValueError:
            raise RunInputError(field_name, item, "expected a time step such as 1e-3, or a "
                                "factor of the scene's step such as 0.5x") from None
        if not math.isfinite(value) or value <= 0:
            raise RunInputError(field_name, item, "a time step must be finite and > 0")
        steps.append(LadderStep(value, relative))
    if not steps:
        raise RunInputError(field_name, text, "no time step given")
    return tuple(steps)


@dataclass
class SweepPlan:
    """Runs of a sweep: fine reference runs first (their keys per scene hash), then the rest."""

    references: dict[str, RunJob] = field(default_factory=dict)
    runs: list[RunJob] = field(default_factory=list)

    @property
    def all_specs(self) -> list[RunSpec]:
        return [j.spec for j in self.references.values()] + [j.spec for j in self.runs]


def resolve_engines(labels: Sequence[str], extra_modules: Mapping[str, str] | None = None,
                    options: Mapping | None = None) -> list[EngineChoice]:
    """Resolve each ``engine[preset]`` label (RunInputError naming the one at fault)."""
    return [resolve_engine(label, extra_modules, options, field=f"--engines {label}")
            for label in labels]


def plan_sweep(scenes: Sequence[str | Scene], engines: Sequence[EngineChoice],
               ladder: Sequence[LadderStep], *, scene_parameters: Mapping | None = None,
               horizon: float | None = None, record_every: int = 1,
               options: Mapping[str, Mapping] | None = None, timeout: float = DEFAULT_TIMEOUT,
               reference: EngineChoice | None = None, fine_factor: float = FINE_FACTOR,
               campaign: str = "sweep") -> SweepPlan:
    """Every scene x engine x step of the ladder, plus a fine reference run per scene that has
    named outputs but no analytic reference (when a ``reference`` engine is given).

    ``options`` maps an engine name to its option overrides.

    Every input is validated here, before any run (RunInputError naming the field).
    """
    plan = SweepPlan()
    for scene_input in scenes:
        scene, _ = resolve_scene(scene_input, scene_parameters)
        steps = sorted({step.resolve(scene) for step in ladder}, reverse=True)
        reference_key = None
        if reference is not None and scene.outputs and not has_analytic_reference(scene):
            fine = make_run_spec(scene_input, reference.label, scene_parameters=scene_parameters,
                                 time_step=fine_factor * min(steps), horizon=horizon,
                                 record_every=record_every, timeout=timeout,
                                 engine_choice=reference, campaign=f"{campaign}:fine-reference")
            plan.references[scene.content_hash] = RunJob(fine)
            reference_key = fine.key
        for engine in engines:
            for dt in steps:
                spec = make_run_spec(scene_input, engine.label, scene_parameters=scene_parameters,
                                     time_step=dt, horizon=horizon, record_every=record_every,
                                     options=(options or {}).get(engine.name),
                                     timeout=timeout, engine_choice=engine, campaign=campaign)
                plan.runs.append(RunJob(spec, reference_key))
    return plan


def execute_plan(plan: SweepPlan, runner: Runner, rerun: bool = False,
                 before: Sequence[RunSpec | RunJob] = ()) -> SweepOutcome:
    """Run ``before`` (runs of their own, started first: warm-up jobs, the longest runs of a
    batch), the fine references and the sweep in one batch, skipping runs already stored; a
    run measured against a fine reference starts once that reference is stored
    (:class:`Runner`)."""
    return runner.run_all([*before, *plan.references.values(), *plan.runs], rerun=rerun)


def pareto_front(times: np.ndarray, errors: np.ndarray) -> np.ndarray:
    """Mask of the points no other point beats in both time and error (lower is better).

    Parameters
    ----------
    times, errors : (n,) arrays; non-finite points are never on the front.
    """
    times = np.asarray(times, dtype=float)
    errors = np.asarray(errors, dtype=float)
    finite = np.isfinite(times) & np.isfinite(errors)
    front = np.zeros(len(times), dtype=bool)
    for i in np.nonzero(finite)[0]:
        better_or_equal = finite & (times <= times[i]) & (errors <= errors[i])
        strictly = better_or_equal & ((times < times[i]) | (errors < errors[i]))
        front[i] = not strictly.any()
    return front


def work_precision_points(frame, scene_name: str):
    """Work–precision points of one scene from a store DataFrame: one row per run with an
    error, sorted by engine and step, with a ``pareto`` column over all engines: the front
    of the runs that finished (status ok); a run that diverged (its error up to where it
    stopped) is never on it.

    Columns: ``label``, ``time_step``, ``error``, ``stepping_seconds_per_simulated_second``,
    ``status``, ``campaign``, ``pareto``.
    """
    rows = frame[(frame["scene_name"] == scene_name)
                 & ~frame["campaign"].fillna("").str.endswith(":fine-reference")].copy()
    rows = rows[np.isfinite(rows["error"].astype(float))
                & np.isfinite(rows["stepping_seconds_per_simulated_second"].astype(float))]
    rows = rows.sort_values(["label", "time_step"])
    finished = (rows["status"] == "ok").to_numpy()
    front = np.zeros(len(rows), dtype=bool)
    if finished.any():
        front[finished] = pareto_front(
            rows["stepping_seconds_per_simulated_second"].to_numpy()[finished],
            rows["error"].to_numpy()[finished])
    rows["pareto"] = front
    return rows[["label", "time_step", "error", "stepping_seconds_per_simulated_second",
                 "status", "campaign", "pareto", "key"]]
