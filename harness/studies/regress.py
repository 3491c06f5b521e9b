"""Regression check: a quick suite compared with a committed baseline, with stated tolerances.

A baseline file (JSON, under ``reports/baselines/``) holds

- ``suite``: the runs (id, scene, scene parameters, engine[preset], time step, horizon);
- ``tolerances``: per engine name (``reference``, ``mujoco``, ...), per metric name (and
  ``default``) an absolute and a relative tolerance with the reason for them: a figure passes
  when |new - base| <= abs + rel |base|. A table without engine names (metric names at the
  top) holds for every engine;
- ``results``: per run id the baseline status, expectations verdict, metrics and the engine's
  version;
- ``recorded``: revision, machine and engine versions the results were recorded on.

A regression is a changed status, a changed expectations verdict, a metric outside its
tolerance, or a metric that disappeared; each line names the run (engine and scene), the
figure and whether the engine's version changed since the baseline. A suite entry whose engine
is not available here is skipped with a note. ``update`` rewrites ``results`` (and
``recorded``) from a fresh run, keeping the suite and tolerances.
"""

from __future__ import annotations

import json
import math
import tempfile
from collections.abc import Mapping
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path

from clearbench.adapters import ENGINES, engine_availability
from clearbench.harness.run.engine_choice import RunInputError, parse_engine_label
from clearbench.harness.run.runner import Runner
from clearbench.harness.run.spec import RunSpec, make_run_spec
from clearbench.harness.run.store import ResultsStore, machine_info, revision_info

DEFAULT_BASELINE = Path("reports/baselines/quick.json")

#: Suite of the reference engine (smoke scenes, short horizons).
REFERENCE_SUITE = [
    {"id": "bouncing-ball-e0.5", "scene": "bouncing-ball-e0.5", "engine": "reference",
     "horizon": 1.0},
    {"id": "incline-stick", "scene": "incline-stick", "engine": "reference", "horizon": 0.3},
    {"id": "sliding-box", "scene": "sliding-box", "engine": "reference", "horizon": 0.5},
    {"id": "pendulum", "scene": "pendulum", "engine": "reference", "horizon": 1.0},
    # 0.1 s: covers the first impacts in the clearance, before the rattling motion amplifies
    # round-off (a baseline must not depend on the last bit of the machine's arithmetic).
    {"id": "clearance-pendulum", "scene": "clearance-pendulum", "engine": "reference",
     "horizon": 0.1},
]

#: Quick scenes every other engine runs (scene, horizon [s]): a bounce (restitution, contact),
#: stick on an incline (friction) and a pendulum (an ideal joint).
ENGINE_SCENES = (("bouncing-ball-e0.5", 1.0), ("incline-stick", 0.3), ("pendulum", 1.0))
#: The preset each other engine is checked in (the one the docs measure the C-60 with).
ENGINE_PRESETS = {"mujoco": "tuned", "pybullet": "tuned", "exudyn": "tuned",
                  "siconos": "default"}
#: The short c60-on of each engine: (horizon [ms], step [ms]). 0.2 ms covers the first settling
#: impacts of the joints; Exudyn stops at 0.11 ms in the full run (docs/engines/exudyn.md), so
#: its run ends before; Siconos steps 10 us (36 ms of wall time per 1 us step).
C60_SHORT = {"reference": (0.2, 1e-3), "mujoco": (0.2, 1e-3), "pybullet": (0.2, 1e-3),
             "exudyn": (0.05, 1e-3), "siconos": (0.2, 1e-2)}


def _engine_suite() -> list[dict]:
    suite = []
    for name, preset in ENGINE_PRESETS.items():
        label = f"{name}[{preset}]"
        suite += [{"id": f"{label} {scene}", "scene": scene, "engine": label,
                   "horizon": horizon} for scene, horizon in ENGINE_SCENES]
    for name, (horizon, step) in C60_SHORT.items():
        label = f"{name}[{ENGINE_PRESETS.get(name, 'default')}]"
        suite.append({"id": f"{label} c60-on", "scene": "c60-on", "engine": label,
                      "parameters": {"horizon": horizon}, "time_step": step,
                      "record_every": 10})
    return suite


#: Suite written into a new baseline.
DEFAULT_SUITE = REFERENCE_SUITE + _engine_suite()

#: Tolerances of the reference engine.
REFERENCE_TOLERANCES = {
    "default": {"abs": 1e-12, "rel": 1e-6,
                "why": "the reference solver is deterministic; 1e-6 relative leaves room for "
                "round-off differences of BLAS and compilers between machines of one kind"},
    "solver_iterations_mean": {"abs": 0.5, "rel": 0.05,
                               "why": "iteration counts move with round-off near the "
                               "stopping tolerance"},
    "solver_residual_max": {"abs": 1e-10, "rel": 10.0,
                            "why": "residuals at convergence are round-off sized; only an "
                            "order-of-magnitude change matters"},
}

def _deterministic(why: str) -> dict:
    return {"default": {"abs": 1e-12, "rel": 1e-6, "why": why},
            "solver_iterations_mean": {"abs": 0.5, "rel": 0.05,
                                       "why": "iteration counts move with round-off near the "
                                       "stopping tolerance"},
            "solver_residual_max": {"abs": 1e-10, "rel": 10.0,
                                    "why": "residuals at convergence are round-off sized; only "
                                    "an order-of-magnitude change matters"}}


#: Tolerances written into a new baseline, per engine.
DEFAULT_TOLERANCES = {
    "reference": REFERENCE_TOLERANCES,
    "mujoco": _deterministic("MuJoCo steps deterministically (one thread, fixed iteration "
                             "order); 1e-6 relative leaves room for the round-off of another "
                             "build of the same version"),
    "pybullet": _deterministic("Bullet's sequential-impulse solver is deterministic for a "
                               "fixed scene and sweep count; 1e-6 relative for another build"),
    "exudyn": {**_deterministic("Exudyn's implicit integrator is deterministic; its Newton "
                                "stops at a tolerance, so 1e-5 relative"),
               "default": {"abs": 1e-12, "rel": 1e-5,
                           "why": "Exudyn's Newton iterations stop at a relative tolerance; "
                           "1e-5 relative leaves room for round-off of another build"}},
    "siconos": _deterministic("Siconos (Moreau-Jean, NSGS) is deterministic for a fixed "
                              "scene; 1e-6 relative for another build of the same version"),
}


@dataclass(frozen=True)
class Tolerance:
    absolute: float
    relative: float
    why: str = ""

    def allows(self, base: float, new: float) -> bool:
        if math.isnan(base) and math.isnan(new):
            return True
        if not (math.isfinite(base) and math.isfinite(new)):
            return base == new
        return abs(new - base) <= self.absolute + self.relative * abs(base)

    def describe(self) -> str:
        return f"{self.absolute:g} + {self.relative:g} x |base|"


@dataclass
class RegressOutcome:
    """What a check found: regressions (one line each), notes, and the number of runs."""

    regressions: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    runs: int = 0
    compared_figures: int = 0


def load_baseline(path: str | Path) -> dict:
    path = Path(path)
    if not path.exists():
        return {"description": "Quick regression suite of clearbench: every engine on a few "
                "smoke scenes with short horizons, and a short c60-on each.",
                "suite": DEFAULT_SUITE,
                "tolerances": DEFAULT_TOLERANCES, "results": {}}
    data = json.loads(path.read_text())
    for key in ("suite", "tolerances"):
        if key not in data:
            raise RunInputError(f"{path}: {key}", None, "missing from the baseline file")
    return data


def suite_specs(baseline: dict, extra_modules: Mapping[str, str] | None = None,
                skipped: dict | None = None) -> dict[str, RunSpec]:
    """Run id -> spec, validated (RunInputError naming the suite entry). An entry whose engine
    is not available here goes into ``skipped`` (id -> why) when that dict is given."""
    specs = {}
    for index, entry in enumerate(baseline["suite"]):
        ident = entry.get("id") or f"suite[{index}]"
        if skipped is not None:
            reason = _unavailable(entry.get("engine", "reference"), extra_modules)
            if reason:
                skipped[ident] = reason
                continue
        try:
            specs[ident] = make_run_spec(
                entry["scene"], entry.get("engine", "reference"),
                scene_parameters=entry.get("parameters"), time_step=entry.get("time_step"),
                horizon=entry.get("horizon"), record_every=int(entry.get("record_every", 1)),
                options=entry.get("options"), timeout=float(entry.get("timeout", 300)),
                extra_engine_modules=extra_modules, campaign="regress")
        except RunInputError as error:
            raise RunInputError(f"suite entry {ident!r}: {error.field}", error.value,
                                error.reason) from None
    return specs


def _unavailable(label: str, extra_modules: Mapping[str, str] | None) -> str:
    """Why the engine of ``label`` cannot run here ('' when it can, or when the label is not
    a known engine: suite_specs then names the fault)."""
    try:
        name, _ = parse_engine_label(label)
    except RunInputError:
        return ""
    if extra_modules and name in extra_modules:
        return ""
    if name not in ENGINES:
        return ""
    availability = engine_availability(name)
    return "" if availability.available else f"{name} not available here: " \
        f"{availability.detail}"


def _engine_name(label: str | None) -> str:
    return str(label or "reference").split("[", 1)[0]


def tolerance_for(baseline: dict, metric: str, engine: str = "reference") -> Tolerance:
    """The tolerance of ``metric`` for ``engine`` (its table when the baseline has one per
    engine, else the shared table)."""
    table = baseline["tolerances"]
    if engine in table and isinstance(table[engine], dict) and "abs" not in table[engine]:
        table = table[engine]
    elif any(isinstance(v, dict) and "abs" not in v for v in table.values()):
        table = {}   # per-engine tables, none for this engine: exact comparison
    entry = table.get(metric) or table.get("default") or {"abs": 0.0, "rel": 0.0}
    return Tolerance(float(entry.get("abs", 0.0)), float(entry.get("rel", 0.0)),
                     entry.get("why", ""))


def _result_of(row: dict) -> dict:
    passed = row["expectations_passed"]
    return {"status": row["status"], "scene_hash": row["scene_hash"],
            "expectations_passed": None if passed is None else int(passed),
            "metrics": json.loads(row["metrics"] or "{}"),
            "message": row["message"],
            "engine": f"{row['engine']}[{row['preset']}]",
            "engine_version": row.get("engine_version") or ""}


def run_suite(specs: dict[str, RunSpec], store_dir: str | Path | None = None,
              jobs: int | None = None, runs_per_worker: int = 1,
              progress: bool = False) -> dict[str, dict]:
    """Run the suite (in a temporary store unless one is given) and return results by id."""
    with tempfile.TemporaryDirectory(prefix="clearbench-regress-") as scratch:
        store = ResultsStore(store_dir or scratch)
        Runner(store, jobs=jobs, runs_per_worker=runs_per_worker,
               progress=progress).run_all(list(specs.values()), rerun=store_dir is None)
        return {ident: _result_of(store.get(spec.key)) for ident, spec in specs.items()}


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
        engine = _engine_name(new.get("engine"))
        changed = version_note(base, new)
        first = len(outcome.regressions)
        if base.get("scene_hash") and new.get("scene_hash") != base["scene_hash"]:
            outcome.notes.append(f"{ident}: the scene definition changed since the baseline "
                                 f"({base['scene_hash'][:12]} -> {new['scene_hash'][:12]}): "
                                 "differences may come from the scene, not the solver")
        if new["status"] != base["status"]:
            outcome.regressions.append(f"{ident}: status {base['status']} -> {new['status']}"
                                       + (f" ({new['message']})" if new["message"] else ""))
        if new["expectations_passed"] != base.get("expectations_passed"):
            outcome.regressions.append(f"{ident}: expectations passed "
                                       f"{base.get('expectations_passed')} -> "
                                       f"{new['expectations_passed']}")
        for metric, base_value in sorted(base.get("metrics", {}).items()):
            if not new["metrics"] and new["status"] != base["status"]:
                break   # the changed status says it: no figure was measured
            tolerance = tolerance_for(baseline, metric, engine)
            if metric not in new["metrics"]:
                outcome.regressions.append(f"{ident}: {metric} no longer computed")
                continue
            value = float(new["metrics"][metric])
            outcome.compared_figures += 1
            base_number = _decode(base_value)
            if not tolerance.allows(base_number, value):
                outcome.regressions.append(
                    f"{ident}: {metric} {base_number:.6g} -> {value:.6g} (tolerance "
                    f"{tolerance.describe()})")
        outcome.regressions[first:] = [line + changed for line in outcome.regressions[first:]]
        added = sorted(set(new["metrics"]) - set(base.get("metrics", {})))
        if added:
            outcome.notes.append(f"{ident}: new metrics not in the baseline: {', '.join(added)}")
    for ident in sorted(set(base_results) - set(results) - set(skipped or {})):
        outcome.notes.append(f"{ident}: in the baseline results but not in the suite")
    return outcome


def _encode(value):
    """Plain JSON for a figure: non-finite numbers as the strings 'nan', 'inf', '-inf'."""
    if isinstance(value, float) and not math.isfinite(value):
        return str(value)
    return value


def _decode(value) -> float:
    return float("nan") if value is None else float(value)


def updated_baseline(baseline: dict, results: dict[str, dict],
                     skipped: Mapping[str, str] | None = None) -> dict:
    """The baseline with ``results`` and ``recorded`` replaced (the results of ``skipped``
    runs, whose engine is not available here, kept as they were)."""
    new = dict(baseline)
    kept = {ident: old for ident, old in baseline.get("results", {}).items()
            if ident in (skipped or {})}
    new["results"] = {**kept, **{
        ident: {"status": result["status"], "scene_hash": result["scene_hash"],
                "expectations_passed": result["expectations_passed"],
                "engine_version": result.get("engine_version", ""),
                "metrics": {k: _encode(v) for k, v in sorted(result["metrics"].items())}}
        for ident, result in results.items()}}
    revision = revision_info()
    machine = machine_info()
    new["recorded"] = {"revision": revision["revision"], "dirty": revision["dirty"],
                       "machine": f"{machine['hostname']} ({machine['cpu']})",
                       "date": datetime.now(UTC).isoformat(timespec="seconds"),
                       "engines": {r["engine"].split("[", 1)[0]: r.get("engine_version", "")
                                   for r in results.values() if r.get("engine")}}
    return new


def write_baseline(path: str | Path, baseline: dict) -> None:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(baseline, indent=2, sort_keys=False, allow_nan=False) + "\n")
