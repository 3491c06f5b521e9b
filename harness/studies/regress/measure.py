"""Measuring a baseline: every suite entry as it is and under each perturbation, and the check
of every figure from the spread (``clearbench regress --update``).

Cost: one run per entry, plus per entry its round-off seeds (2, or its ``ensemble``: 8 for
the compliant engines' C-60 runs), plus one run per environment perturbation for the entries
(every engine: see :func:`planned_variants`) and one per option perturbation of its
engine; an entry that turns out to have a statistical figure gets more
round-off seeds, up to :data:`ENSEMBLE_SIZE`. About 190 runs for the default suite against 22
for a check (130 were measured with one environment perturbation on the reference only).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Mapping

from clearbench.harness.run.engine_choice import engine_defaults
from clearbench.harness.run.spec import RunSpec
from clearbench.harness.studies.regress.perturbations import (
    Variant,
    perturb_initial_state,
    variants_for,
)
from clearbench.harness.studies.regress.suite import engine_name, entry_spec, run_suite, warm_up
from clearbench.harness.studies.regress.tolerance import classify, figure_scale

#: Round-off seeds of an entry with a statistical figure (its ensemble; tolerance.py).
ENSEMBLE_SIZE = 8
#: Statuses of a perturbed run that are not accepted as statuses of the entry: an engine that
#: crashes under a perturbation of a few roundings (Siconos 4.4 aborts when a joint's initial
#: violation exceeds DBL_EPSILON in absolute terms: 8.9e-16 m for a pendulum bob 1 m out) is
#: recorded (``perturbation_failures``), but a crash of the run as given stays a regression.
ENGINE_FAILURES = ("crashed", "timed_out")


def planned_variants(entries: Mapping[str, dict], perturbations: list[dict]
                     ) -> dict[str, list[Variant]]:
    """Run id -> its perturbed reruns. The environment perturbations (numba, OpenBLAS) apply
    to every engine: besides the reference solver's numba kernels and the harness's measuring
    code, the adapters prepare every engine's input with numpy (OpenBLAS), and a chaotic run
    amplifies that round-off: PyBullet's C-60 penetration came out at 0.68 um under
    OPENBLAS_CORETYPE=Prescott, outside the range 0.98..1.18 um of 8 round-off seeds."""
    return {ident: variants_for(entry, engine_name(entry.get("engine")), perturbations)
            for ident, entry in entries.items()}


def variant_spec(entry: dict, ident: str, variant: Variant,
                 extra_modules: Mapping[str, str] | None = None) -> RunSpec:
    """The spec of ``entry`` under ``variant`` (its environment is applied by the runner)."""
    entry = dict(entry)
    if variant.options:
        entry["options"] = {**(entry.get("options") or {}), **variant.options}
    transform = None
    if variant.seed:
        def transform(scene, seed=variant.seed, ulps=variant.ulps):
            return perturb_initial_state(scene, seed, ulps)
    return entry_spec(entry, ident, extra_modules, transform)


def run_perturbed(entries: Mapping[str, dict], plan: Mapping[str, list[Variant]],
                  extra_modules: Mapping[str, str] | None = None, jobs: int | None = None,
                  runs_per_worker: int = 1,
                  on_group: Callable[[str, int], None] | None = None
                  ) -> dict[str, dict[str, dict]]:
    """Run every planned variant: run id -> variant name -> result. Variants sharing an
    environment run together (one pool of workers per environment); ``on_group(label,
    runs)`` is called before each group."""
    groups: dict[tuple, dict[tuple[str, str], RunSpec]] = {}
    for ident, variants in plan.items():
        for variant in variants:
            groups.setdefault(variant.environment_key, {})[(ident, variant.name)] = \
                variant_spec(entries[ident], ident, variant, extra_modules)
    results: dict[str, dict[str, dict]] = {ident: {} for ident in plan}
    for environment, specs in groups.items():
        if on_group is not None:
            label = " ".join(f"{k}={v}" for k, v in environment) or "round-off and options"
            on_group(label, len(specs))
        if environment:
            warm_up({ident: entries[ident] for ident, _ in specs}, extra_modules,
                    dict(environment))
        keyed = {f"{ident}\x00{name}": spec for (ident, name), spec in specs.items()}
        ran = run_suite(keyed, jobs=jobs, runs_per_worker=runs_per_worker,
                        environment=dict(environment))
        for key, result in ran.items():
            ident, name = key.split("\x00", 1)
            results[ident][name] = result
    return results


def _ensemble_extension(plan: Mapping[str, list[Variant]], checks: Mapping[str, dict],
                        perturbations: list[dict]) -> dict[str, list[Variant]]:
    """Further round-off seeds, up to :data:`ENSEMBLE_SIZE`, for the entries with a
    statistical figure (none without a round-off perturbation in the set)."""
    roundoff = next((p for p in perturbations if p["kind"] == "roundoff"), None)
    if roundoff is None:
        return {}
    extra = {}
    for ident, variants in plan.items():
        if not any(c["kind"] == "statistical" for c in checks[ident].values()):
            continue
        seeds = max((v.seed for v in variants), default=0)
        if seeds < ENSEMBLE_SIZE:
            extra[ident] = [Variant(f"{roundoff['name']}-{seed}", seed=seed,
                                    ulps=int(roundoff["ulps"]))
                            for seed in range(seeds + 1, ENSEMBLE_SIZE + 1)]
    return extra


def _value(metrics: dict, name: str) -> float | None:
    if name not in metrics:
        return None
    value = metrics[name]
    return math.nan if value is None else float(value)


def checks_of(entry_spec_: RunSpec, base: dict, perturbed: Mapping[str, dict],
              extra_modules: Mapping[str, str] | None = None) -> dict:
    """Figure name -> :class:`~.tolerance.Check` (as dicts) of one run from its unperturbed
    result ``base`` and its perturbed results (variant name -> result); rigid or compliant as
    its engine declares (``HARNESS_DEFAULTS.rigid_contacts``)."""
    rigid = engine_defaults(engine_name(base.get("engine")), extra_modules).rigid_contacts
    checks = {}
    for name in sorted(base["metrics"]):
        base_value = _value(base["metrics"], name)
        values = [v for v in (_value(r["metrics"], name) for r in perturbed.values())
                  if v is not None]
        scale = figure_scale(name, entry_spec_.scene, entry_spec_.horizon, base["metrics"])
        checks[name] = classify(name, rigid, base_value, values, scale).to_dict()
    return checks


def measure_baseline(entries: Mapping[str, dict], specs: Mapping[str, RunSpec],
                     perturbations: list[dict], extra_modules: Mapping[str, str] | None = None,
                     jobs: int | None = None, runs_per_worker: int = 1,
                     on_group: Callable[[str, int], None] | None = None) -> dict:
    """Results of the suite (run id -> result with ``checks``, ``statuses_seen``,
    ``expectations_seen``, ``perturbations``) and ``cost`` (runs and worker seconds).

    Returns
    -------
    dict
        ``results``: run id -> result; ``runs``: runs made; ``worker_seconds``: their summed
        wall time in the workers [s]; ``seconds``: wall time of the whole measurement [s].
    """
    start = time.monotonic()
    if on_group is not None:
        on_group("as given", len(specs))
    warm_up(entries, extra_modules)
    results = run_suite(specs, jobs=jobs, runs_per_worker=runs_per_worker)
    plan = planned_variants(entries, perturbations)
    perturbed = run_perturbed(entries, plan, extra_modules, jobs, runs_per_worker, on_group)
    checks = {ident: checks_of(specs[ident], result, perturbed[ident], extra_modules)
              for ident, result in results.items()}
    extra = _ensemble_extension(plan, checks, perturbations)
    if extra:
        more = run_perturbed(entries, extra, extra_modules, jobs, runs_per_worker, on_group)
        for ident, ran in more.items():
            perturbed[ident].update(ran)
            checks[ident] = checks_of(specs[ident], results[ident], perturbed[ident],
                                      extra_modules)
    runs = len(results) + sum(len(v) for v in perturbed.values())
    worker_seconds = sum(r.get("worker_seconds", 0.0) for r in results.values()) + sum(
        r.get("worker_seconds", 0.0) for v in perturbed.values() for r in v.values())
    for ident, result in results.items():
        others = perturbed[ident]
        finished = [r for r in others.values() if r["status"] not in ENGINE_FAILURES]
        result["checks"] = checks[ident]
        result["statuses_seen"] = sorted({result["status"]} | {r["status"] for r in finished})
        result["expectations_seen"] = sorted(
            {result["expectations_passed"]} | {r["expectations_passed"] for r in finished},
            key=lambda v: (v is None, v))
        result["perturbations"] = sorted(others)
        failures = {name: f"{r['status']}: {r['message']}" for name, r in sorted(others.items())
                    if r["status"] in ENGINE_FAILURES}
        if failures:
            result["perturbation_failures"] = failures
    return {"results": results, "runs": runs, "worker_seconds": worker_seconds,
            "seconds": time.monotonic() - start}
