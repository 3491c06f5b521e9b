"""A campaign's results as a table: one row per sample, read from the results store.

Outputs are computed from each recorded trajectory by the campaign's output definitions (the
shared output code of :mod:`clearbench.harness.measure.series`), so changing how an output is
collected needs no rerun. Computed values are cached beside the store
(``campaigns/<name>.outputs.json``), keyed by run key and a digest of the output definitions.
"""

from __future__ import annotations

import hashlib
import json
import math
from dataclasses import asdict

import numpy as np

import clearbench
from clearbench.harness.measure.series import output_values
from clearbench.harness.run.store import ResultsStore
from clearbench.harness.studies.campaign.definition import (
    CampaignDefinition,
    CampaignError,
    OutputSpec,
)
from clearbench.harness.studies.campaign.execution import CampaignLog, plan_samples

#: Relative tolerance on the inputs of a given row against the design's.
GIVEN_TOLERANCE = 1e-9
#: The columns a given row brings, beside the outputs, where the CSV has them (its run key:
#: the run that computed it, maybe by another revision of the code).
GIVEN_COLUMNS = ("key", "status", "message", "worker_seconds", "stepping_seconds")


def collect(spec: OutputSpec, times: np.ndarray, values: np.ndarray) -> float:
    """The value of one output over a run: ``spec.statistic`` over the last ``spec.window``
    (scene time units) of the samples ``values`` (T,) at ``times`` (T,)."""
    if len(times) == 0:
        return math.nan
    if spec.statistic == "final":
        return float(values[-1])
    inside = times >= times[-1] - spec.window - 1e-9 * max(abs(times[-1]), 1.0)
    window = values[inside]
    reduce = {"mean": np.mean, "min": np.min, "max": np.max}[spec.statistic]
    return float(reduce(window))


def outputs_digest(definition: CampaignDefinition) -> str:
    """Digest of how the outputs are collected (names, sources, statistics, windows)."""
    text = json.dumps([[o.name, o.output, o.statistic, o.window] for o in definition.outputs])
    return hashlib.sha256(text.encode()).hexdigest()[:12]


def _output_cache(store: ResultsStore, definition: CampaignDefinition):
    path = store.directory / "campaigns" / f"{definition.name}.outputs.json"
    digest = outputs_digest(definition)
    cache = {}
    if path.exists():
        try:
            cache = json.loads(path.read_text(encoding="utf-8"))
        except json.JSONDecodeError:  # a cache torn by a kill: recompute
            cache = {}
    return path, digest, cache.get(digest, {}), cache


def run_outputs(store: ResultsStore, definition: CampaignDefinition, key: str,
                scene) -> dict[str, float]:
    """Every campaign output of the recorded run ``key`` (NaN where it has no trajectory)."""
    trajectory = store.load_trajectory(key)
    if trajectory is None or len(trajectory.times) == 0:
        return {o.name: math.nan for o in definition.outputs}
    series = output_values(scene, trajectory)
    return {o.name: collect(o, trajectory.times, series[o.output]) for o in definition.outputs}


def campaign_table(definition: CampaignDefinition, store: ResultsStore, samples=None):
    """One row per planned sample (or per sample of ``samples``, a list of
    :class:`CampaignSample`): sample, key, status, message, worker_seconds,
    stepping_seconds, the inputs and the outputs by name (a pandas DataFrame). Samples not
    recorded yet have status "pending"; outputs of runs that did not end ok are kept as
    computed (the statistics use the ok runs and count the others)."""
    import pandas as pd  # lazily, as the results store does

    samples = plan_samples(definition) if samples is None else samples
    path, digest, cached, whole = _output_cache(store, definition)
    rows = []
    changed = False
    for sample in samples:
        key = sample.spec.key
        record = store.get(key)
        row = {"sample": sample.index, "key": key}
        row.update({law.name: float(v) for law, v in zip(definition.inputs, sample.inputs,
                                                         strict=True)})
        if record is None:
            row.update(status="pending", message="", worker_seconds=math.nan,
                       stepping_seconds=math.nan)
            row.update({o.name: math.nan for o in definition.outputs})
        else:
            row.update(status=record["status"], message=record["message"],
                       worker_seconds=record["worker_seconds"],
                       stepping_seconds=record["stepping_seconds"])
            if key not in cached:
                cached[key] = run_outputs(store, definition, key, sample.spec.scene)
                changed = True
            row.update(cached[key])
        rows.append(row)
    if changed:
        whole[digest] = cached
        clearbench.write_json(path, whole)
    return pd.DataFrame(rows)


def throughput(store: ResultsStore, definition: CampaignDefinition) -> dict:
    """Samples per hour and wall seconds per sample, from the campaign's own log: per session,
    the samples it recorded over the time from its start to its last record. ``samples``
    counts every logged sample; the rate leaves out the ``recovered`` ones (stored by a
    session killed before it logged them: their time is unknown)."""
    entries = CampaignLog(store, definition.name).entries()
    sessions: dict[str, dict] = {}
    recovered = 0
    for entry in entries:
        if entry.get("event") == "sample" and entry.get("recovered"):
            recovered += 1   # not the session that logged it: it ran in a killed one
            continue
        session = sessions.setdefault(entry["session"], {"samples": 0, "elapsed": 0.0,
                                                         "workers": None, "worker_seconds": []})
        if entry.get("event") == "start":
            session["workers"] = entry.get("workers")
        elif entry.get("event") == "sample":
            session["samples"] += 1
            session["elapsed"] = max(session["elapsed"], entry["elapsed_s"])
            session["worker_seconds"].append(entry.get("worker_seconds", math.nan))
    timed = sum(s["samples"] for s in sessions.values())
    elapsed = sum(s["elapsed"] for s in sessions.values())
    seconds = [x for s in sessions.values() for x in s["worker_seconds"] if x == x]
    workers = sorted({s["workers"] for s in sessions.values() if s["workers"]})
    return {
        "sessions": len(sessions), "samples": timed + recovered, "recovered": recovered,
        "wall_seconds": elapsed,
        "samples_per_hour": 3600.0 * timed / elapsed if elapsed > 0 else math.nan,
        "worker_seconds_per_sample": float(np.median(seconds)) if seconds else math.nan,
        "workers": workers,
    }


def definition_summary(definition: CampaignDefinition) -> dict:
    """The definition as plain data (for the report's JSON)."""
    return {"name": definition.name, "scene": definition.scene, "engine": definition.engine,
            "design": definition.design, "samples": definition.samples,
            "seed": definition.seed, "scene_parameters": dict(definition.scene_parameters),
            "inputs": [asdict(law) for law in definition.inputs],
            "outputs": [asdict(o) for o in definition.outputs]}


def take_given(definition: CampaignDefinition, table, given, strict: bool = True) -> int:
    """Fill the pending rows of ``table`` (:func:`campaign_table`'s, with a ``source``
    column, changed in place) from ``given`` (a campaign CSV's DataFrame, maybe written by
    another revision of the code or on another machine): run key, status, message, timings,
    inputs and outputs of every pending sample whose index ``given`` holds with the same
    inputs (to :data:`GIVEN_TOLERANCE`); those rows' source becomes ``given``. Returns how
    many rows were filled.

    Raises :class:`CampaignError` naming the sample when ``given`` holds a pending sample with
    other inputs, or the column it lacks, unless ``strict`` is False and it lacks a column or
    none of its shared samples match (then it is another campaign's CSV: nothing is taken).
    """
    names = [law.name for law in definition.inputs]
    columns = [c for c in GIVEN_COLUMNS if c in given.columns] + [
        o.name for o in definition.outputs]
    missing = sorted(set(names + columns) - set(given.columns))
    if missing and not strict:
        return 0   # without this campaign's inputs or outputs: another campaign's CSV
    if missing:
        raise CampaignError("given runs", missing[0], "no such column in the CSV")
    indexed = given.set_index("sample")
    pending = [row for row in table.index[table["status"] == "pending"]
               if int(table.at[row, "sample"]) in indexed.index]
    differing = [row for row in pending if not np.allclose(
        indexed.loc[int(table.at[row, "sample"]), names].to_numpy(float),
        table.loc[row, names].to_numpy(float), rtol=GIVEN_TOLERANCE, atol=0.0)]
    if differing and (strict or len(differing) < len(pending)):
        row = differing[0]
        sample = int(table.at[row, "sample"])
        raise CampaignError(f"given runs, sample {sample}",
                            indexed.loc[sample, names].to_numpy(float).tolist(),
                            f"inputs differ from this design's "
                            f"{table.loc[row, names].to_numpy(float).tolist()}")
    if differing:
        return 0
    for row in pending:
        sample = int(table.at[row, "sample"])
        for column in columns + names:   # the inputs as the run had them (within tolerance)
            table.at[row, column] = indexed.at[sample, column]
        table.at[row, "source"] = "given"
    return len(pending)


def report_table(definition: CampaignDefinition, store: ResultsStore, given=(),
                 samples=None, strict: bool = False):
    """:func:`campaign_table` (of ``samples``, default every planned one) with a ``source``
    column (``store``, ``given`` or ``pending``), its pending samples taken from each of the
    campaign CSVs ``given`` (DataFrames) that holds them with this design's inputs
    (:func:`take_given`, with ``strict``: False passes another campaign's CSV over). Returns
    the table and how many rows each CSV filled."""
    table = campaign_table(definition, store, samples)
    table["source"] = np.where(table["status"] == "pending", "pending", "store")
    filled = [take_given(definition, table, frame, strict=strict) for frame in given]
    return table, filled
