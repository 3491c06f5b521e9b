"""Comparing a fresh run of the suite with the baseline: every regression, named.

A regression is a status or expectations verdict not seen when the baseline was measured
(under any of its perturbations), a figure its check does not allow
(:class:`~.tolerance.Check`), or a figure that disappeared. Each line names the run (engine
and scene), the figure, the values, the criterion and whether the engine's version changed.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

from clearbench.harness.studies.regress.tolerance import Check


@dataclass
class RegressOutcome:
    """What a check found: regressions (one line each), notes, and the number of runs."""

    regressions: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    runs: int = 0
    compared_figures: int = 0


def version_note(base: dict, new: dict) -> str:
    """`` [engine X unchanged]`` or `` [engine version changed: X -> Y]`` ('' when the
    baseline recorded no version)."""
    old, now = base.get("engine_version") or "", new.get("engine_version") or ""
    if not old:
        return ""
    if not now:   # a run that timed out or crashed before the engine said its version
        return f" [engine {old} in the baseline; this run reported no version]"
    if old == now:
        return f" [engine {old} unchanged]"
    return f" [engine version changed: {old} -> {now or 'unknown'}]"


def _number(value) -> float:
    return float("nan") if value is None else float(value)


def _run_regressions(ident: str, base: dict, new: dict) -> tuple[list[str], int]:
    """Regression lines of one run and the number of figures compared."""
    lines = []
    statuses = base.get("statuses_seen") or [base["status"]]
    if new["status"] not in statuses:
        lines.append(f"{ident}: status {base['status']} -> {new['status']}"
                     + (f" ({new['message']})" if new.get("message") else ""))
    verdicts = base.get("expectations_seen") or [base.get("expectations_passed")]
    if new["expectations_passed"] not in verdicts:
        lines.append(f"{ident}: expectations passed {base.get('expectations_passed')} -> "
                     f"{new['expectations_passed']}")
    if not new["metrics"] and new["status"] != base["status"]:
        return lines, 0   # the changed status says it: no figure was measured
    compared = 0
    checks = base.get("checks", {})
    for metric in sorted(base.get("metrics", {})):
        if metric not in new["metrics"]:
            lines.append(f"{ident}: {metric} no longer computed")
            continue
        value = _number(new["metrics"][metric])
        if metric not in checks:
            lines.append(f"{ident}: {metric} has no measured tolerance in the baseline (run "
                         "clearbench regress --update)")
            continue
        check = Check.from_dict(checks[metric])
        compared += 1
        if not check.allows(value):
            lines.append(f"{ident}: {metric} {check.base:.6g} -> {value:.6g} "
                         f"({check.describe()})")
    return lines, compared


def compare(baseline: dict, results: dict[str, dict],
            skipped: Mapping[str, str] | None = None) -> RegressOutcome:
    """Every regression of ``results`` against ``baseline['results']`` (``skipped``: run ids
    not run here and why, reported as notes)."""
    outcome = RegressOutcome(runs=len(results))
    base_results = baseline.get("results", {})
    for ident, why in (skipped or {}).items():
        outcome.notes.append(f"{ident}: not run ({why})")
    for ident, new in results.items():
        base = base_results.get(ident)
        if base is None:
            outcome.regressions.append(f"{ident}: no baseline result (run with --update)")
            continue
        if base.get("scene_hash") and new.get("scene_hash") != base["scene_hash"]:
            outcome.notes.append(f"{ident}: the scene definition changed since the baseline "
                                 f"({base['scene_hash'][:12]} -> {new['scene_hash'][:12]}): "
                                 "differences may come from the scene, not the solver")
        lines, compared = _run_regressions(ident, base, new)
        changed = version_note(base, new)
        outcome.regressions += [line + changed for line in lines]
        outcome.compared_figures += compared
        added = sorted(set(new["metrics"]) - set(base.get("metrics", {})))
        if added:
            outcome.notes.append(f"{ident}: new metrics not in the baseline: {', '.join(added)}")
    for ident in sorted(set(base_results) - set(results) - set(skipped or {})):
        outcome.notes.append(f"{ident}: in the baseline results but not in the suite")
    return outcome
