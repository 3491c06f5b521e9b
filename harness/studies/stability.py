"""The stiff and extreme suite: every scene tagged ``stiff`` (see
:mod:`clearbench.scenarios.library.stiff`) in each engine at the scene's own step, with a
verdict and the metrics that matter for each case."""

from __future__ import annotations

import json
from collections.abc import Sequence

from clearbench.adapters import all_availability
from clearbench.harness.measure.headline import scene_metric_names
from clearbench.harness.run.engine_choice import EngineChoice, resolve_engine
from clearbench.harness.run.spec import DEFAULT_TIMEOUT, RunSpec, make_run_spec
from clearbench.scenarios.library import get_entry, scene_names
from clearbench.scenarios.tags import STIFF


def available_engines(extra_modules=None) -> list[EngineChoice]:
    """The default preset of every engine available on this machine."""
    return [resolve_engine(a.engine, extra_modules) for a in all_availability() if a.available]


def plan_stability(engines: Sequence[EngineChoice], scenes: Sequence[str] | None = None,
                   timeout: float = DEFAULT_TIMEOUT, campaign: str = "stability") -> list[RunSpec]:
    """One run per stiff case and engine, at the case's own (hard) time step."""
    names = list(scenes) if scenes else scene_names(STIFF)
    return [make_run_spec(name, engine.label, engine_choice=engine, timeout=timeout,
                          campaign=campaign) for name in names for engine in engines]


def stability_rows(frame, specs: Sequence[RunSpec]) -> list[dict]:
    """Per case and engine: verdict, reason, expectations, and the case's metrics."""
    by_key = frame.set_index("key")
    rows = []
    for spec in specs:
        if spec.key not in by_key.index:
            continue
        row = by_key.loc[spec.key]
        figures = json.loads(row["metrics"] or "{}")
        names = [n for n in scene_metric_names(spec.scene) if n in figures]
        rows.append({
            "case": spec.scene.name,
            "summary": get_entry(spec.scene.name).summary if spec.source.registry_name else "",
            "engine": spec.engine.label,
            "status": row["status"],
            "reason": row["message"],
            "expectations_passed": row["expectations_passed"],
            "metrics": {n: figures[n] for n in names},
            "verdict_figures": figures,
            "stepping_seconds_per_step": row["stepping_seconds_per_step"],
        })
    return rows
