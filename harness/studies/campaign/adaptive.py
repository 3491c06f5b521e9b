"""A metamodel campaign: design runs added in batches on Dask until every output's metamodel
meets the file's accuracy and interval targets, or the run budget ends; then the rare-event
estimates and the true runs that confirm them.

Stage k fits every output on the first n_k design samples (n_1 = ``initial``, then ``batch``
more at a time, up to the campaign's ``samples``, the run budget): the metamodel chosen by Q2
(:mod:`.metamodel`), its figures with bootstrap intervals (:mod:`.metamodel_estimates`). The
campaign stops at the first stage where every output has Q2 >= ``q2`` and every half-width
target is met (``targets met``), or when the budget is used (``run budget``); the state says
which and, for the latter, what was still short.

Everything is resumable: the runs are the store's (a design sample already recorded, also by
another campaign with the same design, runs no more), and each stage's fits are kept in
``<store>/campaigns/<name>.metamodel.json`` under a digest of the data and settings they
were computed from, so a resumed campaign refits nothing it has.

Design rows may also come from a table of given runs (``given``: a campaign CSV written by
``clearbench campaign report``, e.g. by another revision of the code), for the samples whose
inputs it holds; the state counts them apart from the store's.
"""

from __future__ import annotations

import hashlib
import json
import math
from collections.abc import Callable
from dataclasses import asdict

import numpy as np

import clearbench
from clearbench.harness.run.runner import MANY_RUNS_PER_WORKER
from clearbench.harness.run.store import ResultsStore
from clearbench.harness.studies.campaign.definition import CampaignDefinition, CampaignError
from clearbench.harness.studies.campaign.execution import (
    plan_points,
    plan_samples,
    run_samples,
)
from clearbench.harness.studies.campaign.metamodel import (
    CHAOS,
    ChaosBasis,
    FittedModel,
    choose_metamodel,
    fit_kriging,
    input_distribution,
)
from clearbench.harness.studies.campaign.metamodel_estimates import (
    FIGURES_METHOD,
    bootstrap_estimates,
)
from clearbench.harness.studies.campaign.rare_events import (
    confirmation_points,
    failure_probability,
    ray_factors,
)
from clearbench.harness.studies.campaign.results import campaign_table, report_table

#: Index of the first confirmation run (design samples stay below it).
CONFIRMATION_START = 10_000_000


def state_path(store: ResultsStore, definition: CampaignDefinition):
    return store.directory / "campaigns" / f"{definition.name}.metamodel.json"


def load_state(store: ResultsStore, definition: CampaignDefinition) -> dict:
    path = state_path(store, definition)
    if not path.exists():
        return {}
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except json.JSONDecodeError:  # torn by a kill: refit
        return {}


def _save_state(store: ResultsStore, definition: CampaignDefinition, state: dict) -> None:
    clearbench.write_json(state_path(store, definition), state, indent=1, default=float)


def design_table(definition: CampaignDefinition, store: ResultsStore, count: int,
                 given=None):
    """The first ``count`` design samples (a DataFrame as :func:`campaign_table`'s, with a
    ``source`` column: ``store``, ``given`` or ``pending``); a sample pending in the store is
    taken from ``given`` (a DataFrame of the same columns) when it holds the sample's index
    with the same inputs."""
    table, _ = report_table(definition, store, () if given is None else (given,),
                            plan_samples(definition, 0, count), strict=True)
    return table


def _digest(*parts) -> str:
    text = json.dumps(parts, sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def _interval_dict(value) -> dict | None:
    return None if value is None else asdict(value)


def fit_stage(definition: CampaignDefinition, table, basis: ChaosBasis | None) -> dict:
    """Every output's metamodel on the ok rows of ``table``: kind, Q2, its validation
    predictions, and its figures with bootstrap intervals; whether the targets are met."""
    settings = definition.metamodel
    ok = table[table["status"] == "ok"]
    x = ok[[law.name for law in definition.inputs]].to_numpy(float)
    outputs, short = [], []
    for index, spec in enumerate(definition.outputs):
        y = ok[spec.name].to_numpy(float)
        keep = np.isfinite(y)
        try:
            fitted = choose_metamodel(x[keep], y[keep], basis, settings.candidates,
                                      settings.max_degree, settings.validation,
                                      settings.folds, seed=definition.seed + index)
        except ValueError as error:
            raise CampaignError("metamodel.initial", settings.initial,
                                f"{spec.name}: {error}; start with more runs") from None
        figures = bootstrap_estimates(fitted, basis, x[keep], y[keep], definition,
                                      spec.lower_limit, spec.upper_limit, settings.bootstrap,
                                      seed=definition.seed + 1000 * index)
        entry = {"name": spec.name, "kind": fitted.kind, "degree": fitted.degree,
                 "q2": fitted.q2, "residual_rms": fitted.residual_rms,
                 "candidates": fitted.candidates, "runs": int(keep.sum()),
                 "samples": ok["sample"].to_numpy()[keep].tolist(),
                 "validation_predictions": fitted.predictions.tolist(),
                 "observed": y[keep].tolist(),
                 "mean": asdict(figures.mean), "sigma": asdict(figures.sigma),
                 "cp": _interval_dict(figures.cp), "cpk": _interval_dict(figures.cpk),
                 "s1": [asdict(v) for v in figures.s1], "st": [asdict(v) for v in figures.st],
                 "interaction": asdict(figures.interaction),
                 "unexplained": figures.unexplained, "bootstrap": figures.replicates}
        entry["short"] = _short_of(entry, figures, settings)
        short += [f"{spec.name}: {text}" for text in entry["short"]]
        outputs.append(entry)
    return {"runs": int(len(ok)), "outputs": outputs, "met": not short, "short": short}


def _short_of(entry: dict, figures, settings) -> list[str]:
    """What of the targets one output misses (empty: all met)."""
    short = []
    if not entry["q2"] >= settings.q2:
        short.append(f"Q2 {entry['q2']:.3f} < {settings.q2:g}")
    sigma = figures.sigma.value
    for figure, target in settings.targets.items():
        width = figures.half_width(figure)
        if figure in ("mean", "sigma"):
            width = width / sigma if sigma > 0 else math.nan
        if not math.isnan(width) and not width <= target:
            unit = " sigma" if figure in ("mean", "sigma") else ""
            short.append(f"{figure} half-width {width:.3g}{unit} > {target:g}{unit}")
    return short


def _stage_sizes(definition: CampaignDefinition) -> list[int]:
    settings = definition.metamodel
    sizes = [settings.initial]
    while sizes[-1] < definition.samples:
        sizes.append(min(sizes[-1] + settings.batch, definition.samples))
    return sizes


def run_metamodel_campaign(definition: CampaignDefinition, store: ResultsStore, *,
                           scheduler: str | None = None, workers: int = 2,
                           progress: bool = False, given=None,
                           on_stage: Callable[[dict], None] | None = None,
                           runs_per_worker: int = MANY_RUNS_PER_WORKER) -> dict:
    """Run ``definition`` (``method = "metamodel"``) to its stop; returns the state (also
    written beside the store): the stages, the stop and its reason, the rare-event estimates
    and the confirmation runs. ``runs_per_worker`` as for
    :func:`~.execution.run_campaign`."""
    if definition.metamodel is None:
        raise CampaignError("method", definition.method, "is not \"metamodel\"")
    settings = definition.metamodel
    distribution = input_distribution(definition)
    basis = ChaosBasis(distribution) if "chaos" in settings.candidates else None
    state = load_state(store, definition)
    cache = state.get("stage_cache", {})
    stages = []
    reason = "run budget"
    for size in _stage_sizes(definition):
        table = design_table(definition, store, size, given)
        pending = table[table["source"] == "pending"]
        if len(pending):
            samples = [s for s in plan_samples(definition, 0, size)
                       if s.index in set(pending["sample"])]
            run_samples(definition, samples, store, scheduler=scheduler, workers=workers,
                        progress=progress, runs_per_worker=runs_per_worker)
            table = design_table(definition, store, size, given)
        key = _digest(definition.raw, FIGURES_METHOD, table[["sample", "status"] + [
            o.name for o in definition.outputs]].to_dict("list"))
        if key not in cache:
            cache[key] = fit_stage(definition, table, basis)
            cache[key]["sources"] = table["source"].value_counts().to_dict()
            state["stage_cache"] = cache
            _save_state(store, definition, state)
        stage = {"size": size, **cache[key]}
        stages.append(stage)
        if on_stage is not None:
            on_stage(stage)
        if stage["met"]:
            reason = "targets met"
            break
    final = stages[-1]
    state.update(stages=[{k: v for k, v in s.items()} for s in stages], stop=reason,
                 runs=final["runs"], budget=definition.samples)
    state.pop("rare_events", None)
    _save_state(store, definition, state)   # the stages, before the confirmation runs
    state["rare_events"] = _rare_events(definition, store, table, final, distribution, basis,
                                        scheduler, workers, progress, runs_per_worker)
    _save_state(store, definition, state)
    return state


def _rare_events(definition, store, table, final, distribution, basis, scheduler, workers,
                 progress, runs_per_worker) -> list[dict]:
    """Failure probabilities of the outputs with limits, and their confirmation runs."""
    settings = definition.metamodel
    ok = table[table["status"] == "ok"]
    x_all = ok[[law.name for law in definition.inputs]].to_numpy(float)
    events, points, owners = [], [], []
    for index, (spec, entry) in enumerate(zip(definition.outputs, final["outputs"],
                                              strict=True)):
        if not spec.has_limits:
            continue
        y = ok[spec.name].to_numpy(float)
        keep = np.isfinite(y)
        fitted = refitted(entry, basis, x_all[keep], y[keep])
        probability = failure_probability(fitted, distribution, spec.lower_limit,
                                          spec.upper_limit, seed=definition.seed + index)
        sides = []
        for side in probability["sides"]:
            record = asdict(side)
            record["confirmation"] = []
            # a true check only where the estimate is a tail: the median design inside
            # the limits and the design point found
            if (not side.origin_fails and 0 < side.form < 0.5
                    and settings.confirmation_runs > 0):
                ray = confirmation_points(distribution, side, settings.confirmation_runs)
                predicted = fitted.predict(ray)
                for t, row, value in zip(ray_factors(len(ray)), ray, predicted, strict=True):
                    record["confirmation"].append({"t": float(t), "inputs": row.tolist(),
                                                   "predicted": float(value)})
                    points.append(row)
                    owners.append((len(events), len(sides), len(record["confirmation"]) - 1))
            sides.append(record)
        events.append({"name": spec.name, "residual_rms": fitted.residual_rms,
                       "ppm_form": probability["ppm_form"],
                       "ppm_importance": probability["ppm_importance"],
                       "importance_cv": probability["importance_cv"],
                       "ppm_importance_interval": probability["ppm_importance_interval"],
                       "sides": sides})
    if points:
        samples = plan_points(definition, np.array(points), CONFIRMATION_START)
        run_samples(definition, samples, store, scheduler=scheduler, workers=workers,
                    progress=progress, runs_per_worker=runs_per_worker,
                    label=lambda s: f"confirmation-{s.index - CONFIRMATION_START}")
        results = campaign_table(definition, store, samples)
        for (event, side, run), (_, row) in zip(owners, results.iterrows(), strict=True):
            target = events[event]["sides"][side]["confirmation"][run]
            name = events[event]["name"]
            target.update(status=row["status"], key=row["key"], observed=float(row[name]))
    for event in events:
        for side in event["sides"]:
            _judge_confirmation(side, event["residual_rms"])
    return events


def refitted(entry: dict, basis: ChaosBasis | None, x: np.ndarray,
             y: np.ndarray) -> FittedModel:
    """A stage's metamodel of one output (its kind and degree, with the validation it had)
    fitted again on its design ``x`` (n, d), ``y`` (n,)."""
    model = basis.fit(x, y, entry["degree"]) if entry["kind"] == CHAOS else fit_kriging(x, y)
    return FittedModel(entry["kind"], entry["degree"], entry["q2"], entry["residual_rms"],
                       np.asarray(entry["validation_predictions"]), model, entry["candidates"])


def _judge_confirmation(side: dict, residual_rms: float) -> None:
    """Whether the true runs near the design point agree with the metamodel: each within 3
    validation residual RMS of its prediction, and on the predicted side of the limit when
    the prediction is further from it than that."""
    runs = [r for r in side["confirmation"] if r.get("status") == "ok"]
    if not runs:
        side["confirmed"] = None
        return
    tolerance = 3 * residual_rms
    agree = []
    for run in runs:
        error = run["observed"] - run["predicted"]
        run["error_in_residual_rms"] = error / residual_rms if residual_rms > 0 else math.inf
        fails = (run["observed"] < side["limit"]) if side["side"] == "lower" \
            else (run["observed"] > side["limit"])
        run["outside_limit"] = bool(fails)
        agree.append(abs(error) <= tolerance)
    side["confirmed"] = bool(all(agree))
