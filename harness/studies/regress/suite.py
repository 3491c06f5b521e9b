"""The quick regression suite: its runs, their specs, and running them into results.

A suite entry is a plain dict: ``id``, ``scene`` (registered name or scene file),
``engine`` (``ENGINE[PRESET]``), and optionally ``parameters`` (the scene factory's keyword
parameters, as ``--set``), ``time_step``, ``horizon``, ``record_every``, ``options``,
``timeout`` [s] and ``ensemble`` (the number of round-off perturbations its tolerances are
measured from, :mod:`.perturbations`; default :data:`.perturbations.ROUNDOFF_SEEDS`).
"""

from __future__ import annotations

import json
import tempfile
from collections.abc import Mapping
from pathlib import Path

from clearbench.adapters import ENGINES, engine_availability
from clearbench.harness.run.engine_choice import RunInputError, parse_engine_label
from clearbench.harness.run.runner import Runner
from clearbench.harness.run.spec import RunSpec, make_run_spec, resolve_scene
from clearbench.harness.run.store import ResultsStore

#: Suite of the reference engine (smoke scenes, short horizons). Each entry also carries the
#: deliberate physics changes it must catch (tests/test_regress_catches.py): the bounce apexes
#: and rest time move with the restitution, the sliding box's stop with the friction (0.8 s
#: covers its stop at v0 / (mu g) = 0.68 s), the clearance pendulum's eccentricity with the
#: clearance.
REFERENCE_SUITE = [
    {"id": "bouncing-ball-e0.5", "scene": "bouncing-ball-e0.5", "engine": "reference",
     "horizon": 1.0},
    {"id": "incline-stick", "scene": "incline-stick", "engine": "reference", "horizon": 0.3},
    {"id": "sliding-box", "scene": "sliding-box", "engine": "reference", "horizon": 0.8},
    {"id": "pendulum", "scene": "pendulum", "engine": "reference", "horizon": 1.0},
    # 0.1 s: covers the first impacts in the clearance, before the rattling motion amplifies
    # round-off into a spread of a whole clearance (DESIGN.md: 1e-4 m on long runs).
    {"id": "clearance-pendulum", "scene": "clearance-pendulum", "engine": "reference",
     "horizon": 0.1},
]

#: Quick scenes every other engine runs (scene, horizon [s]): a bounce (restitution, contact),
#: stick on an incline (friction) and a pendulum (an ideal joint).
ENGINE_SCENES = (("bouncing-ball-e0.5", 1.0), ("incline-stick", 0.3), ("pendulum", 1.0))
#: The preset each other engine is checked in (the one the docs measure the C-60 with).
ENGINE_PRESETS = {"mujoco": "tuned", "pybullet": "tuned", "exudyn": "tuned",
                  "siconos": "default"}
#: The preset each engine runs the short c60-on in, where it is not its ENGINE_PRESETS one: the
#: preset the C-60 plans use (Exudyn's 'mechanism', docs/engines/exudyn.md).
C60_PRESETS = {"exudyn": "mechanism"}
#: The short c60-on of each engine: (horizon [ms], step [ms]). 0.2 ms covers the first settling
#: impacts of the joints; Exudyn costs about 35 ms per step on the C-60, so 0.03 ms (before
#: the first clearance closes, about 10 s); Siconos steps 10 us (36 ms of wall time per 1 us
#: step).
C60_SHORT = {"reference": (0.2, 1e-3), "mujoco": (0.2, 1e-3), "pybullet": (0.2, 1e-3),
             "exudyn": (0.03, 1e-3), "siconos": (0.2, 1e-2)}
#: Round-off perturbations of the C-60 runs of the compliant engines, whose impacts amplify
#: round-off into figures that are draws from a distribution (penetration, FC figures): an
#: ensemble of 8 gives the range a new value is judged against (tolerance.py).
C60_ENSEMBLE = {"mujoco": 8, "pybullet": 8, "exudyn": 8}


def _engine_suite() -> list[dict]:
    suite = []
    for name, preset in ENGINE_PRESETS.items():
        label = f"{name}[{preset}]"
        suite += [{"id": f"{label} {scene}", "scene": scene, "engine": label,
                   "horizon": horizon} for scene, horizon in ENGINE_SCENES]
    for name, (horizon, step) in C60_SHORT.items():
        label = f"{name}[{C60_PRESETS.get(name) or ENGINE_PRESETS.get(name, 'default')}]"
        entry = {"id": f"{label} c60-on", "scene": "c60-on", "engine": label,
                 "parameters": {"horizon": horizon}, "time_step": step, "record_every": 10}
        if name in C60_ENSEMBLE:
            entry["ensemble"] = C60_ENSEMBLE[name]
        suite.append(entry)
    return suite


#: Suite written into a new baseline.
DEFAULT_SUITE = REFERENCE_SUITE + _engine_suite()


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


def _result_of(row: dict) -> dict:
    passed = row["expectations_passed"]
    return {"status": row["status"], "scene_hash": row["scene_hash"],
            "expectations_passed": None if passed is None else int(passed),
            "metrics": json.loads(row["metrics"] or "{}"),
            "message": row["message"],
            "engine": f"{row['engine']}[{row['preset']}]",
            "engine_version": row.get("engine_version") or "",
            "worker_seconds": float(row.get("worker_seconds") or 0.0)}


#: Wall-clock limit of a warm-up run [s]: it may compile every numba kernel of the reference
#: solver and of the measuring code from an empty cache (minutes on a loaded 2-core machine).
WARM_UP_TIMEOUT = 3600.0
#: Engines whose runs compile numba kernels (the measuring code's are compiled by them too).
NUMBA_ENGINES = ("reference",)


def warm_up_specs(entries: Mapping[str, dict],
                  extra_modules: Mapping[str, str] | None = None) -> list[RunSpec]:
    """One run of two steps per distinct scene of the entries of :data:`NUMBA_ENGINES`, with a
    long wall-clock limit: run one after the other before a suite, they fill numba's cache,
    so that the suite's runs (each in a fresh worker, with the entry's own limit) do not all
    compile the same kernels at once from an empty cache and time out."""
    specs = {}
    for ident, entry in entries.items():
        if engine_name(entry.get("engine")) not in NUMBA_ENGINES:
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
    specs = warm_up_specs(entries, extra_modules)
    if not specs:
        return
    with tempfile.TemporaryDirectory(prefix="clearbench-warm-") as scratch:
        Runner(ResultsStore(scratch), jobs=1, runs_per_worker=len(specs),
               environment=environment).run_all(specs, rerun=True)


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

