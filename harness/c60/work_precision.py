"""Work-precision on the C-60: per engine, a ladder of time steps; the error of FC-1
(``c60-on``) and of the contacts' opening time (``c60-trip``) against the reference engine at
its finest step, against the wall time of stepping; the Pareto front over every engine; and per
error budget (1 %, 5 %) the cheapest step of each engine whose error and every finer step's
error stay within it, with its cost.

Errors are relative: |FC-1 - FC-1_ref| / FC-1_ref and |t_open - t_open_ref| / t_open_ref (the
opening time counted from t = 0, as the scene's events are). Wall times [s].
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from clearbench.harness.c60.cross_engine import (
    ON_SCENE,
    REFERENCE_LABEL,
    TRIP_SCENE,
    C60RunFigures,
)
from clearbench.harness.studies.sweep import pareto_front

#: Quantity of each scene's work-precision: (scene, attribute of C60RunFigures, label).
QUANTITIES = ((ON_SCENE, "fc1", "FC-1"), (TRIP_SCENE, "opening", "opening time"))


@dataclass(frozen=True)
class WorkPrecisionPoint:
    """One run on the work-precision plane (``error`` relative, ``wall_seconds`` of stepping
    for the whole run, ``on_front``: no other run of any engine is both faster and more
    accurate)."""

    quantity: str
    label: str
    time_step: float
    horizon: float
    value: float
    error: float
    wall_seconds: float
    wall_seconds_per_step: float
    on_front: bool = False


@dataclass(frozen=True)
class WorkPrecision:
    """Points of one quantity and the reference they are measured against."""

    quantity: str
    scene_name: str
    reference_value: float           # the reference engine's figure at its finest step
    reference_step: float            # [ms]
    horizon: float                   # [ms] of the runs compared
    points: tuple


def _ladder_horizon(runs: Sequence[C60RunFigures], scene_name: str) -> float:
    """The horizon at which the reference ran the most steps on the scene (a figure averaged
    over the last ms depends on the horizon, so only runs of one horizon are compared)."""
    horizons = [r.horizon for r in runs if r.scene_name == scene_name
                and r.label == REFERENCE_LABEL and r.status == "ok"]
    if not horizons:
        return math.nan
    values, counts = np.unique(horizons, return_counts=True)
    return float(values[np.argmax(counts)])


def work_precision(runs: Sequence[C60RunFigures]) -> list[WorkPrecision]:
    """One :class:`WorkPrecision` per quantity whose reference run exists (status ok and a
    finite figure)."""
    out = []
    for scene_name, attribute, quantity in QUANTITIES:
        horizon = _ladder_horizon(runs, scene_name)
        chosen = [r for r in runs if r.scene_name == scene_name and r.horizon == horizon]
        references = [r for r in chosen if r.label == REFERENCE_LABEL and r.status == "ok"
                      and math.isfinite(getattr(r, attribute))]
        if not references:
            continue
        reference = min(references, key=lambda r: r.time_step)
        target = getattr(reference, attribute)
        points = []
        for run in chosen:
            value = getattr(run, attribute)
            if run.key == reference.key or run.status != "ok" or not math.isfinite(value):
                continue
            points.append(WorkPrecisionPoint(
                quantity, run.label, run.time_step, run.horizon, value,
                abs(value - target) / abs(target), run.stepping_seconds,
                run.stepping_seconds_per_step))
        front = pareto_front(np.array([p.wall_seconds for p in points]),
                             np.array([p.error for p in points])) if points else []
        points = [WorkPrecisionPoint(**{**p.__dict__, "on_front": bool(f)})
                  for p, f in zip(points, front, strict=True)]
        out.append(WorkPrecision(quantity, scene_name, target, reference.time_step, horizon,
                                 tuple(sorted(points, key=lambda p: (p.label, p.time_step)))))
    return out


#: The error budgets of the report's table (relative errors: 1 % and 5 %).
BUDGETS = (0.01, 0.05)


@dataclass(frozen=True)
class BudgetStep:
    """One engine's answer to an error budget on one quantity: the cheapest step of its
    ladder whose error, and the error of every finer step of the ladder, stay within
    ``budget`` (relative), with that run's error and cost; None fields when no step does, and
    ``reason`` says why (the finer steps' errors, or which finer step did not finish).

    ``errors``: the ladder as (step [ms], relative error; inf for a run that did not finish
    or gave no value, 0 for the reference's own finest step, the yardstick)."""

    label: str
    quantity: str
    budget: float
    time_step: float | None
    error: float | None
    wall_seconds: float | None
    wall_seconds_per_step: float | None
    errors: tuple
    reason: str = ""

    def describe(self) -> str:
        goal = f"{100 * self.budget:g} %"
        if self.time_step is not None:
            return (f"within {goal} from dt = {self.time_step:g} ms down "
                    f"({100 * self.error:.3g} % there; {self.wall_seconds:.3g} s per run, "
                    f"{1e3 * self.wall_seconds_per_step:.3g} ms per step)")
        return f"{goal} not met: {self.reason}"


def error_budget(runs: Sequence[C60RunFigures], study: WorkPrecision,
                 budget: float) -> list[BudgetStep]:
    """Per engine label with a run on the study's scene and horizon, :class:`BudgetStep` for
    ``budget``. Every run of the ladder counts, finished or not: a finer step that diverged,
    or that drifts beyond the budget, disqualifies every coarser step (the step is only
    trusted when refining it keeps the error within the budget)."""
    attribute = next(a for scene, a, q in QUANTITIES if q == study.quantity)
    chosen = [r for r in runs if r.scene_name == study.scene_name and r.horizon == study.horizon]
    out = []
    for label in sorted({r.label for r in chosen}, key=lambda x: (x != REFERENCE_LABEL, x)):
        ladder = sorted((r for r in chosen if r.label == label), key=lambda r: r.time_step)
        rows = []   # (run, error)
        for run in ladder:
            value = getattr(run, attribute)
            if run.status != "ok" or not math.isfinite(value):
                error = math.inf
            elif label == REFERENCE_LABEL and run.time_step == study.reference_step:
                error = 0.0
            else:
                error = abs(value - study.reference_value) / abs(study.reference_value)
            rows.append((run, error))
        qualifying = []
        for k, (run, error) in enumerate(rows):
            if all(e <= budget for _, e in rows[:k + 1]):
                qualifying.append((run, error))
        errors = tuple((run.time_step, error) for run, error in rows)
        if qualifying:
            run, error = min(qualifying, key=lambda pair: pair[0].stepping_seconds)
            out.append(BudgetStep(label, study.quantity, budget, run.time_step, error,
                                  run.stepping_seconds, run.stepping_seconds_per_step, errors))
            continue
        finest, finest_error = rows[0]
        if math.isinf(finest_error):
            reason = (f"its finest step, dt = {finest.time_step:g} ms, "
                      f"{'gave no value' if finest.status == 'ok' else finest.status}")
        else:
            reason = (f"{100 * finest_error:.3g} % at its finest step, dt = "
                      f"{finest.time_step:g} ms")
        out.append(BudgetStep(label, study.quantity, budget, None, None, None, None, errors,
                              reason))
    return out
