"""The quick regression suite: its runs, their specs, and running them into results.

A suite entry is a plain dict: ``id``, ``scene`` (registered name or scene file),
``engine`` (``ENGINE[PRESET]``), and optionally ``parameters`` (the scene factory's keyword
parameters, as ``--set``), ``time_step``, ``horizon``, ``record_every``, ``options``,
``timeout`` [s] and ``ensemble`` (the number of round-off perturbations its tolerances are
measured from, :mod:`.perturbations`; default :data:`.perturbations.ROUNDOFF_SEEDS`).
The suite of a new baseline is what the engines declare (:func:`default_suite`).
"""

from __future__ import annotations

import json
import tempfile
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

from clearbench.adapters import ENGINES, engine_availability
from clearbench.harness.run.engine_choice import (
    RunInputError,
    engine_defaults,
    engine_module_path,
    engine_names,
    parse_engine_label,
)
from clearbench.harness.run.numba_cache import WARM_UP_TIMEOUT, fill_cache
from clearbench.harness.run.runner import Runner
from clearbench.harness.run.spec import RunSpec, make_run_spec, resolve_scene
from clearbench.harness.run.store import ResultsStore


def default_suite(engines: Sequence[str] | None = None,
                  extra_modules: Mapping[str, str] | None = None) -> list[dict]:
    """The suite of a new baseline: the quick runs each engine declares
    (``HARNESS_DEFAULTS.regress_runs``, :mod:`clearbench.adapters.harness_defaults`), for
    ``engines`` (names; default: every engine of the registry and of ``extra_modules``), in
    that order.

    Raises
    ------
    RunInputError
        An unknown engine, or a module that fails to load.
    """
    names = engine_names(extra_modules) if engines is None else engines
    return [entry for name in names
            for entry in engine_defaults(name, extra_modules).regress_entries(name)]


def entry_spec(entry: dict, ident: str, extra_modules: Mapping[str, str] | None = None,
               scene_transform=None) -> RunSpec:
    """The spec of one suite entry (``scene_transform``: a function Scene -> Scene applied to
    the built scene, e.g. a round-off perturbation of its initial state).

    Raises
    ------
    RunInputError
        Naming the suite entry and the field at fault.
    """
    try:
        scene = entry["scene"]
        parameters = entry.get("parameters")
        if scene_transform is not None:
            built, _ = resolve_scene(scene, parameters)
            scene, parameters = scene_transform(built), None
        return make_run_spec(
            scene, entry.get("engine", "reference"), scene_parameters=parameters,
            time_step=entry.get("time_step"), horizon=entry.get("horizon"),
            record_every=int(entry.get("record_every", 1)), options=entry.get("options"),
            timeout=float(entry.get("timeout", 300)), extra_engine_modules=extra_modules,
            campaign="regress")
    except RunInputError as error:
        raise RunInputError(f"suite entry {ident!r}: {error.field}", error.value,
                            error.reason) from None


def suite_entries(baseline: dict, extra_modules: Mapping[str, str] | None = None,
                  skipped: dict | None = None) -> dict[str, dict]:
    """Run id -> suite entry, for the entries whose engine is available here (the others go
    into ``skipped``, id -> why, when that dict is given)."""
    entries = {}
    for index, entry in enumerate(baseline["suite"]):
        ident = entry.get("id") or f"suite[{index}]"
        if skipped is not None:
            reason = _unavailable(entry.get("engine", "reference"), extra_modules)
            if reason:
                skipped[ident] = reason
                continue
        entries[ident] = entry
    return entries


def suite_specs(baseline: dict, extra_modules: Mapping[str, str] | None = None,
                skipped: dict | None = None) -> dict[str, RunSpec]:
    """Run id -> spec, validated (RunInputError naming the suite entry). An entry whose engine
    is not available here goes into ``skipped`` (id -> why) when that dict is given."""
    return {ident: entry_spec(entry, ident, extra_modules)
            for ident, entry in suite_entries(baseline, extra_modules, skipped).items()}


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


def engine_name(label: str | None) -> str:
    """``'mujoco'`` of ``'mujoco[tuned]'`` (``'reference'`` when None)."""
    return str(label or "reference").split("[", 1)[0]


@dataclass(frozen=True)
class EngineSelection:
    """The engines ``clearbench regress -e`` names: ``ENGINE`` takes every entry of the engine,
    ``ENGINE[PRESET]`` the entries of that label only."""

    labels: tuple[str, ...]

    @classmethod
    def parse(cls, labels: Sequence[str], extra_modules: Mapping[str, str] | None = None
              ) -> EngineSelection:
        """RunInputError naming a label that is malformed or names no engine."""
        for label in labels:
            name, _ = parse_engine_label(label, "--engines")
            engine_module_path(name, extra_modules)
        return cls(tuple(labels))

    @property
    def names(self) -> list[str]:
        return list(dict.fromkeys(engine_name(label) for label in self.labels))

    def takes(self, entry: dict) -> bool:
        """Whether the suite entry ``entry`` runs an engine of the selection."""
        name, preset = parse_engine_label(entry.get("engine", "reference"))
        return any(parse_engine_label(label) == (name, preset) if "[" in label
                   else engine_name(label) == name for label in self.labels)


def with_declared_runs(baseline: dict, engines: Sequence[str],
                       extra_modules: Mapping[str, str] | None = None) -> tuple[dict, list[str]]:
    """``baseline`` with the quick runs each of ``engines`` (names) declares appended to its
    suite, for those that have no entry in it yet; and the names that got them. This is how a
    new engine's runs enter a committed baseline (``clearbench regress --update -e NAME``)."""
    added = engines_without_runs(baseline, engines, extra_modules)
    if not added:
        return baseline, []
    return {**baseline, "suite": [*baseline["suite"], *default_suite(added, extra_modules)]}, \
        added


def engines_without_runs(baseline: dict, engines: Sequence[str] | None = None,
                         extra_modules: Mapping[str, str] | None = None) -> list[str]:
    """Those of ``engines`` (names; default: every engine of the registry and of
    ``extra_modules``) that have no entry in the suite."""
    present = {engine_name(entry.get("engine")) for entry in baseline["suite"]}
    return [name for name in (engine_names(extra_modules) if engines is None else engines)
            if name not in present]


def restricted(baseline: dict, selection: EngineSelection | None) -> tuple[dict, list[str]]:
    """The baseline with its suite and results restricted to the entries of ``selection``
    (all when None), and the ids of the entries left out."""
    if selection is None:
        return baseline, []
    taken = [entry for entry in baseline["suite"] if selection.takes(entry)]
    others = [entry.get("id") for entry in baseline["suite"] if not selection.takes(entry)]
    ids = {entry.get("id") for entry in taken}
    return {**baseline, "suite": taken,
            "results": {i: r for i, r in baseline.get("results", {}).items() if i in ids}}, \
        others


def _result_of(row: dict) -> dict:
    passed = row["expectations_passed"]
    return {"status": row["status"], "scene_hash": row["scene_hash"],
            "expectations_passed": None if passed is None else int(passed),
            "metrics": json.loads(row["metrics"] or "{}"),
            "message": row["message"],
            "engine": f"{row['engine']}[{row['preset']}]",
            "engine_version": row.get("engine_version") or "",
            "worker_seconds": float(row.get("worker_seconds") or 0.0)}


def warm_up_specs(entries: Mapping[str, dict],
                  extra_modules: Mapping[str, str] | None = None) -> list[RunSpec]:
    """One run of two steps per distinct scene of the entries of the engines that compile
    numba kernels (``HARNESS_DEFAULTS.numba``; the measuring code's kernels are compiled by
    their runs too), with a long wall-clock limit: run one after the other before a suite,
    they fill numba's cache, so that the suite's runs (each in a fresh worker, with the
    entry's own limit) do not all compile the same kernels at once from an empty cache and
    time out."""
    specs = {}
    for ident, entry in entries.items():
        if not engine_defaults(engine_name(entry.get("engine")), extra_modules).numba:
            continue
        key = json.dumps([entry["scene"], entry.get("parameters")], sort_keys=True)
        if key in specs:
            continue
        spec = entry_spec(entry, ident, extra_modules)
        specs[key] = entry_spec({**entry, "horizon": 2 * spec.time_step,
                                 "timeout": WARM_UP_TIMEOUT}, ident, extra_modules)
    return list(specs.values())


def warm_up(entries: Mapping[str, dict], extra_modules: Mapping[str, str] | None = None,
            environment: Mapping[str, str] | None = None) -> None:
    """Run :func:`warm_up_specs` one after the other in one worker (results discarded)."""
    fill_cache(warm_up_specs(entries, extra_modules), jobs=1, environment=environment)


def run_suite(specs: Mapping[str, RunSpec], store_dir: str | Path | None = None,
              jobs: int | None = None, runs_per_worker: int = 1, progress: bool = False,
              environment: Mapping[str, str] | None = None) -> dict[str, dict]:
    """Run ``specs`` (in a temporary store unless one is given; every run afresh) and return
    results by id: status, scene hash, expectations verdict, metrics, message, engine label and
    version, worker wall time [s]. ``environment``: variables set for the worker processes."""
    with tempfile.TemporaryDirectory(prefix="clearbench-regress-") as scratch:
        store = ResultsStore(store_dir or scratch)
        Runner(store, jobs=jobs, runs_per_worker=runs_per_worker, progress=progress,
               environment=environment).run_all(list(specs.values()),
                                                rerun=store_dir is None)
        return {ident: _result_of(store.get(spec.key)) for ident, spec in specs.items()}

