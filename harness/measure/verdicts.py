"""Pass/fail criteria: of each expectation in the harness's results and report, which
expectation figure is a run's analytic error, and the one verdict of a run that the overview
matrix and the CLI show (:func:`run_verdict`, from the run's status and its expectations).
(The run's status, ok or diverged, is :func:`clearbench.harness.measure.figures.measure`'s.)

The verdict of a run (:data:`VERDICTS`: label -> symbol, colour, meaning):

==================  ======  ===============================================================
verdict             symbol  when
==================  ======  ===============================================================
pass                ✓       finished (status ok) and every expectation judged passed
physics failed      ✗       finished, but an expectation of the scene failed
unseen penetration  ◐       finished, but the geometry instrument witnesses a penetration the
                            kernel's figure misses (:mod:`.geometry_check`)
no check            ○       finished, and the scene has no expectation that could be judged
diverged            ↯       NaN, energy gain, escape, tunnelling, a joint or driver broken
crashed             ☠       the engine or its worker died or raised
timed out           ⌛      the wall-clock limit was reached
unsupported         ∅       the engine cannot represent the scene (it says why)
==================  ======  ===============================================================

:func:`clearbench.harness.measure.expectation_figures.evaluate` states figures, not verdicts.
The harness's criteria, each relative to a scale of the scene so that they hold in any unit
system, are those of the expectation kinds (:mod:`.kinds`: what passes, in words, and the
rule that judges it); :func:`criteria` reads them and :func:`criteria_table` writes them for
the docs and the report.

The headline error of a run where the scene has an analytic reference is the largest of its
expectations' :func:`analytic_error` (each kind names its figure; a relative number).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from clearbench.harness.measure.criteria import Case, Criterion
from clearbench.harness.measure.kinds import KINDS
from clearbench.scenarios.scene import Scene


def analytic_error(kind: str, figures: dict) -> float:
    """|relative error| against the analytic solution (the kind's ``analytic_error``
    figure), NaN when the kind has none or the figure is missing."""
    declared = KINDS.get(kind)
    for name, normaliser in (declared.analytic_error if declared is not None else ()):
        value = figures.get(name)
        if value is None or not math.isfinite(value):
            continue
        if normaliser is not None:
            scale = figures.get(normaliser)
            if not scale:
                continue
            value = value / scale
        return abs(float(value))
    return math.nan


def has_analytic_error(kind: str) -> bool:
    """Whether ``kind`` measures an error against an analytic solution."""
    return kind in KINDS and bool(KINDS[kind].analytic_error)


@dataclass(frozen=True)
class Judgement:
    """Verdict of one expectation: ``passed`` (None when the figures allow none), the
    ``criterion`` in words, and ``detail``: the measured figure against its bound, with
    units and the place (``"0.639 mm > 0.1 mm (ball1-ball2)"``)."""

    passed: bool | None
    criterion: str
    detail: str


def judge(scene: Scene, kind: str, body: str | None, figures: dict) -> tuple[bool | None, str]:
    """(passed, criterion) of one expectation result; passed is None when the figures do not
    allow a verdict (no samples, event not reached). :func:`judgement` adds the detail."""
    result = judgement(scene, kind, body, figures)
    return result.passed, result.criterion


def criteria() -> dict[str, Criterion]:
    """Expectation kind -> its criterion, every registered kind (implied ones included)."""
    return {name: kind.criterion for name, kind in KINDS.items()}


def criteria_table() -> str:
    """:func:`criteria` as a Markdown table (kinds with the same criterion on one row)."""
    rows: dict[str, list[str]] = {}
    for kind, criterion in criteria().items():
        rows.setdefault(criterion.passes_when, []).append(kind)
    lines = ["| expectation | passes when |", "|---|---|"]
    lines += [f"| {', '.join(f'`{k}`' for k in kinds)} | {text.replace('|', chr(92) + '|')} |"
              for text, kinds in rows.items()]
    return "\n".join(lines)


def judgement(scene: Scene, kind: str, body: str | None, figures: dict,
              where: str = "", expectation=None) -> Judgement:
    """Pass/fail, criterion and detail of one expectation result of ``kind`` about ``body``
    with ``figures`` (:mod:`.expectation_figures`), by its kind's criterion; ``where`` names
    the place of the judged figure (a contact pair, a body) for the detail; ``expectation``
    (the scene's :class:`~clearbench.scenarios.expectations.Expectation`, if any) gives its
    parameters."""
    declared = KINDS.get(kind)
    if declared is None:
        return Judgement(None, "no criterion", "no criterion")
    passed, detail, words = declared.criterion.judge(Case(scene, body, figures, expectation))
    if where and passed is not None:
        detail += f" ({where})"
    return Judgement(passed, words, detail)


@dataclass(frozen=True)
class VerdictStyle:
    """How a verdict is shown: a symbol (readable in print and without colour vision), a
    background colour, and what it means."""

    symbol: str
    colour: str
    meaning: str


#: Every verdict of :func:`run_verdict`, best first. Colours are light tints told apart by
#: lightness as well as hue; the symbol carries the verdict on its own.
VERDICTS: dict[str, VerdictStyle] = {
    "pass": VerdictStyle("✓", "#cde9d0", "finished; every expectation of the scene passed"),
    "physics failed": VerdictStyle("✗", "#ffd98a", "finished, but an expectation of the scene "
                                   "failed (wrong physics)"),
    "unseen penetration": VerdictStyle("◐", "#f7c6a3", "finished, but the independent geometry "
                                       "instrument witnesses a penetration the kernel's figure "
                                       "does not show (harness/measure/geometry_check.py)"),
    "no check": VerdictStyle("○", "#f2f2f2", "finished; no expectation of the scene could be "
                             "judged"),
    "diverged": VerdictStyle("↯", "#f2a08f", "stopped or judged broken: NaN, energy gain, "
                             "escape, tunnelling, a joint or driver broken"),
    "crashed": VerdictStyle("☠", "#c9a3d9", "the engine or its worker died or raised"),
    "timed out": VerdictStyle("⌛", "#a9c8ec", "the wall-clock limit was reached"),
    "unsupported": VerdictStyle("∅", "#d6d6d6", "the engine cannot represent the scene"),
}

#: Run status (:class:`~clearbench.adapters.trajectory.RunStatus` value) -> verdict, for every
#: status but ok (whose verdict depends on the expectations).
_STATUS_VERDICTS = {"diverged": "diverged", "crashed": "crashed", "timed_out": "timed out",
                    "unsupported": "unsupported"}


def run_verdict(status: str, expectations_passed, figures: dict | None = None) -> str:
    """The verdict of a run (a key of :data:`VERDICTS`) from its stored status and its
    ``expectations_passed`` (1 all judged passed, 0 one failed, None or NaN none judged);
    ``figures`` (the run's stored figures): an ok run with an ``unseen_penetration`` > 0 is
    "unseen penetration" (the run-wide geometry check)."""
    if status != "ok":
        if status not in _STATUS_VERDICTS:
            raise ValueError(f"unknown run status {status!r}")
        return _STATUS_VERDICTS[status]
    if figures and (figures.get("unseen_penetration") or 0.0) > 0.0:
        return "unseen penetration"
    if expectations_passed is None or (isinstance(expectations_passed, float)
                                       and math.isnan(expectations_passed)):
        return "no check"
    return "pass" if int(expectations_passed) else "physics failed"


def verdict_text(verdict: str) -> str:
    """Symbol and name of a verdict, e.g. ``"✗ physics failed"``."""
    return f"{VERDICTS[verdict].symbol} {verdict}"
