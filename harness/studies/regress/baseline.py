"""The baseline file: load, update from a measurement, write.

A baseline file (JSON, under ``reports/baselines/``) holds

- ``suite``: the runs (:mod:`.suite`);
- ``perturbations``: the perturbations its tolerances were measured under
  (:mod:`.perturbations`);
- ``tolerance_model``: the constants of :mod:`.tolerance`, for the reader;
- ``results``: per run id the status, expectations verdict, metrics and engine version of the
  run as given, the statuses and verdicts seen under the perturbations, and per figure its
  check (:class:`~.tolerance.Check`: class, base, spread, range, floor, limit, reason);
- ``recorded``: revision, machine, engine versions, date and the cost of the measurement.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from datetime import UTC, datetime
from pathlib import Path

from clearbench.harness.run.engine_choice import RunInputError, engine_defaults, engine_names
from clearbench.harness.run.store import machine_info, revision_info
from clearbench.harness.studies.regress import tolerance
from clearbench.harness.studies.regress.perturbations import (
    check_perturbations,
    default_perturbations,
)
from clearbench.harness.studies.regress.suite import default_suite

DEFAULT_BASELINE = Path("reports/baselines/quick.json")


def tolerance_model(extra_modules: Mapping[str, str] | None = None) -> dict:
    """The constants of the tolerance model (:mod:`.tolerance`), as written in a baseline, and
    the engines (of the registry and ``extra_modules``) that declare rigid contacts."""
    rigid = [name for name in engine_names(extra_modules)
             if engine_defaults(name, extra_modules).rigid_contacts]
    return {"exact_widen": tolerance.EXACT_WIDEN,
            "statistical_spread": tolerance.STATISTICAL_SPREAD,
            "floor_relative": tolerance.FLOOR_RELATIVE,
            "bound_headroom": tolerance.BOUND_HEADROOM,
            "ensemble_widen": tolerance.ENSEMBLE_WIDEN,
            "count_floor": [tolerance.COUNT_FLOOR_RELATIVE, tolerance.COUNT_FLOOR_ABSOLUTE],
            "rigid_engines": rigid,
            "why": "see docs/harness.md#regression and harness/studies/regress/tolerance.py"}


def new_baseline(engines: Sequence[str] | None = None,
                 extra_modules: Mapping[str, str] | None = None) -> dict:
    """A baseline without results: the quick runs and perturbations the engines declare
    (:func:`.suite.default_suite`, :func:`.perturbations.default_perturbations`) for
    ``engines`` (names; default every engine of the registry and of ``extra_modules``)."""
    return {"description": "Quick regression suite of clearbench: every engine on a few "
            "smoke scenes with short horizons, and a short c60-on each.",
            "suite": default_suite(engines, extra_modules),
            "perturbations": default_perturbations(engines, extra_modules), "results": {}}


def load_baseline(path: str | Path, engines: Sequence[str] | None = None,
                  extra_modules: Mapping[str, str] | None = None) -> dict:
    """The baseline at ``path`` (:func:`new_baseline` of ``engines`` when the file does not
    exist).

    Raises
    ------
    RunInputError
        Naming the missing or invalid key.
    """
    path = Path(path)
    if not path.exists():
        return new_baseline(engines, extra_modules)
    data = json.loads(path.read_text())
    if "suite" not in data:
        raise RunInputError(f"{path}: suite", None, "missing from the baseline file")
    data.setdefault("perturbations", default_perturbations(extra_modules=extra_modules))
    try:
        check_perturbations(data["perturbations"])
    except ValueError as error:
        raise RunInputError(f"{path}: {error}", None, "invalid perturbation") from None
    return data


def _stored(result: dict) -> dict:
    stored = {"status": result["status"], "scene_hash": result["scene_hash"],
              "expectations_passed": result["expectations_passed"],
              "engine_version": result.get("engine_version", ""),
              "metrics": {k: _plain(v) for k, v in sorted(result["metrics"].items())}}
    for key in ("statuses_seen", "expectations_seen", "perturbations",
                "perturbation_failures", "checks"):
        if key in result:
            stored[key] = result[key]
    return stored


def _plain(value):
    if isinstance(value, float) and not math.isfinite(value):
        return str(value)
    return value


def updated_baseline(baseline: dict, results: dict[str, dict],
                     skipped: Mapping[str, str] | None = None,
                     cost: Mapping[str, float] | None = None,
                     extra_modules: Mapping[str, str] | None = None) -> dict:
    """The baseline with ``results`` (each with its ``checks``), ``tolerance_model`` and
    ``recorded`` replaced (the results of ``skipped`` runs, whose engine is not available
    here or was not chosen, kept as they were, with their engines' versions); ``cost``: runs,
    worker seconds and seconds of the measurement."""
    new = {key: value for key, value in baseline.items() if key != "tolerances"}
    new.setdefault("perturbations", default_perturbations(extra_modules=extra_modules))
    new["tolerance_model"] = tolerance_model(extra_modules)
    kept = {ident: old for ident, old in baseline.get("results", {}).items()
            if ident in (skipped or {})}
    new["results"] = {**kept, **{ident: _stored(r) for ident, r in results.items()}}
    revision = revision_info()
    machine = machine_info()
    new["recorded"] = {"revision": revision["revision"], "dirty": revision["dirty"],
                       "machine": f"{machine['hostname']} ({machine['cpu']})",
                       "date": datetime.now(UTC).isoformat(timespec="seconds"),
                       "engines": _engine_versions(baseline, kept, results)}
    if cost:
        new["recorded"]["cost"] = {k: round(float(v), 1) for k, v in cost.items()}
    return new


def _engine_versions(baseline: dict, kept: Mapping[str, dict],
                     results: Mapping[str, dict]) -> dict[str, str]:
    """Engine name -> version of the engines measured (``results``) and of those whose results
    were ``kept`` (their versions as the baseline recorded them)."""
    recorded = baseline.get("recorded", {}).get("engines", {})
    labels = {entry.get("id"): entry.get("engine") or "reference"
              for entry in baseline.get("suite", [])}
    versions = {}
    for ident in kept:
        name = str(labels.get(ident, "")).split("[", 1)[0]
        if name in recorded:
            versions[name] = recorded[name]
    versions.update({r["engine"].split("[", 1)[0]: r.get("engine_version", "")
                     for r in results.values() if r.get("engine")})
    return versions


def write_baseline(path: str | Path, baseline: dict) -> None:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(baseline, indent=1, sort_keys=False, allow_nan=False) + "\n")
