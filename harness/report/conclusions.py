"""Conclusions first: one line per engine and preset of the store (the C-60's FC-1 against
the reference and the latch, each trip event against the reference's, the cheapest step
within 1 % on FC-1 with its run's cost, the library scenes passed, the stiff suite passed) and
the model's standing against the paper in one sentence."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from clearbench.harness.c60.cross_engine import ON_SCENE, REFERENCE_LABEL, TRIP_SCENE
from clearbench.harness.measure.headline import format_value
from clearbench.harness.report import c60_motion
from clearbench.harness.report.c60_section import C60Section, run_summary
from clearbench.harness.report.overview import row_verdict
from clearbench.scenarios.tags import STIFF

#: The error budget the conclusions quote (the table has every one).
CONCLUSION_BUDGET = 0.01
HEAD = ["engine[preset]", "C-60 ON: FC-1 against the reference, latch",
        "C-60 trip: strike, release, opening [ms] against the reference",
        "cheapest step within 1 % on FC-1 (run's cost)", "library scenes", "stiff suite"]


@dataclass(frozen=True)
class Conclusion:
    label: str
    on: str
    trip: str
    budget: str
    library: str
    stiff: str

    def cells(self) -> list[str]:
        return [self.label, self.on, self.trip, self.budget, self.library, self.stiff]


def _finest(runs, label: str, scene_name: str):
    """The label's finest finished run of the scene on the comparison's horizon, else its
    finest run of any status (an unsupported one last)."""
    horizon = c60_motion.comparison_horizon(runs, scene_name)
    mine = [r for r in runs if r.label == label and r.scene_name == scene_name
            and r.horizon == horizon]
    finished = [r for r in mine if r.status == "ok"]
    built = [r for r in mine if r.status != "unsupported"]
    return min(finished or built or mine, key=lambda r: r.time_step) if mine else None


def _status(run) -> str:
    text = run.status
    if math.isfinite(run.simulated_until) and run.simulated_until < run.horizon:
        text += f" at {run.simulated_until:.3g} ms"
    return text


def c60_text(section: C60Section | None, label: str, scene_name: str) -> str:
    """The label's finest finished run of the scene (c60-on: FC-1 against the reference's
    and the latch; c60-trip: each event against the reference's), or how it ended."""
    run = _finest(section.runs, label, scene_name) if section else None
    if run is None:
        return "not run"
    if run.status == "unsupported":
        return "unsupported"
    if run.status != "ok":
        return f"{_status(run)} (dt {run.time_step:g} ms)"
    return f"{run_summary(section, run)} (dt {run.time_step:g} ms)"


def budget_text(section: C60Section | None, label: str) -> str:
    steps = [s for s in (section.budgets if section else []) if s.label == label
             and s.quantity == "FC-1" and s.budget == CONCLUSION_BUDGET]
    if not steps:
        return "not run"
    step = steps[0]
    runs = [r for r in section.runs if r.label == label and r.scene_name == ON_SCENE]
    if runs and all(r.status == "unsupported" for r in runs):
        return "unsupported"
    if step.time_step is None:
        return f"not met: {step.reason}"
    return f"dt {step.time_step:g} ms ({format_value(step.wall_seconds)} s per run)"


def pass_count(sections: Sequence, label: str) -> str:
    """How many of ``sections`` (report SceneSections) the label's run at the scene's step
    passes, with the other verdicts counted."""
    verdicts = [row_verdict(s.representative[label]) for s in sections
                if label in s.representative]
    if not verdicts:
        return "not run"
    passed = verdicts.count("pass")
    others = {v: verdicts.count(v) for v in sorted(set(verdicts)) if v != "pass"}
    detail = ", ".join(f"{n} {v}" for v, n in others.items())
    return f"{passed} of {len(verdicts)} pass" + (f" ({detail})" if detail else "")


def conclusions(labels: Sequence[str], sections: Sequence, c60: C60Section | None
                ) -> list[Conclusion]:
    """One line per engine label (the reference first). ``sections``: the report's scene
    sections (the C-60 scenes and the stiff suite are counted apart from the library)."""
    library = [s for s in sections if s.name not in (ON_SCENE, TRIP_SCENE)
               and not (s.scene is not None and STIFF in s.scene.tags)]
    stiff = [s for s in sections if s.scene is not None and STIFF in s.scene.tags]
    ordered = sorted(labels, key=lambda label: (label != REFERENCE_LABEL, label))
    return [Conclusion(label, c60_text(c60, label, ON_SCENE), c60_text(c60, label, TRIP_SCENE),
                       budget_text(c60, label), pass_count(library, label),
                       pass_count(stiff, label) if stiff else "not run")
            for label in ordered]


def standing(validation: dict | None) -> str:
    """The model's standing against the paper in one sentence, from ``clearbench c60
    validate``'s rows (the model's own, not a variant's): FC-1 at the prototype's clearances
    and the trip test's peak force against the paper's."""
    if not validation:
        return ""
    rows = [r for r in validation.get("rows", []) if "not the model" not in (r.get("note") or "")]
    fc1 = next((r for r in rows if r["quantity"].startswith("FC-1")), None)
    peak = next((r for r in rows if r["quantity"].startswith("Trip test: peak force")), None)
    parts = []
    for row, name in ((fc1, "FC-1"), (peak, "the trip test's peak force")):
        if row is None or row.get("ours") is None:
            continue
        paper = [f"{row[k]:g} N {w}" for k, w in (("paper_simulated", "simulated"),
                                                   ("paper_measured", "measured"))
                 if row.get(k) is not None]
        difference = row.get("difference")
        change = f" ({100 * difference:+.0f} %)" if difference is not None else ""
        parts.append(f"{name} {row['ours']:.3g} N against the paper's {' and '.join(paper)}"
                     f"{change}")
    if not parts:
        return ""
    return ("The C-60 model as its source gives it (the reference engine) has "
            + "; ".join(parts) + ": the section 'C-60 against the paper' gives the measured "
            "cause of each difference and the documented variants nearest the paper.")
