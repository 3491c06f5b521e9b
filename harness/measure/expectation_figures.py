"""Evaluate a scene's physics expectations on a trajectory: one implementation for every engine.

:func:`evaluate` returns, per expectation of the scene, named figures (errors against the
analytic reference, drifts, creep) in the scene's units, and a headline figure used by the
report, by the figure handler of each expectation's kind (:mod:`.kinds`); :func:`evaluate_implied`
does the same for the implied checks that apply to a run. Neither states pass/fail: that is
each kind's criterion (:mod:`.verdicts`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from clearbench.adapters.trajectory import Trajectory
from clearbench.harness.measure.kinds import implied_kinds, measured_kind
from clearbench.scenarios.scene import Scene


@dataclass(frozen=True)
class ExpectationResult:
    """Figures of one expectation. ``headline`` names the figure summarising it."""

    name: str
    kind: str
    figures: dict = field(default_factory=dict)
    headline: str = ""
    note: str = ""
    where: str = ""


def evaluate(scene: Scene, trajectory: Trajectory) -> list[ExpectationResult]:
    """Figures of every expectation of ``scene`` on ``trajectory`` (empty trajectories give
    NaN figures)."""
    results = []
    for expectation in scene.expectations:
        handler = measured_kind(expectation.kind).figures
        if len(trajectory.times) < 2:
            results.append(ExpectationResult(expectation.name, expectation.kind,
                                              note="no samples"))
            continue
        results.append(_result(expectation.name, expectation.kind,
                               handler(scene, trajectory, expectation)))
    return results


def evaluate_implied(scene: Scene, trajectory: Trajectory,
                     run_figures: dict) -> list[ExpectationResult]:
    """Figures of every implied check (:func:`~.kinds.implied_kinds`) that applies to the run,
    from the trajectory and the run's figures measured so far (``run_figures``)."""
    results = []
    for kind in implied_kinds():
        answer = kind.figures(scene, trajectory, run_figures)
        if answer is not None:
            results.append(_result(kind.name, kind.name, answer))
    return results


def _result(name: str, kind: str, answer) -> ExpectationResult:
    figures, headline, note = answer
    figures = dict(figures)
    where = figures.pop("where", "")
    return ExpectationResult(name, kind, {k: float(v) for k, v in figures.items()}, headline,
                             note, where)
