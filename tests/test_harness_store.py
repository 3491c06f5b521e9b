"""The results store: atomic keyed records, pandas frame, scenes and trajectories kept."""

from __future__ import annotations

import json
import math
import sqlite3

import numpy as np
import pandas as pd

from clearbench.adapters.trajectory import RunStatus, Trajectory
from clearbench.harness.measure.verdicts import run_verdict
from clearbench.harness.run.messages import MeasuredMessage, RanMessage
from clearbench.harness.run.spec import make_run_spec
from clearbench.harness.run.store import (
    COLUMNS,
    ResultsStore,
    RunRecord,
    machine_info,
    revision_info,
)

from .harness_helpers import FAKE


def _record(spec, status="ok", figures=None):
    ran = RanMessage(status=status, message="", worker_seconds=0.5, build_seconds=0.1,
                     stepping_seconds=0.2, steps=100, samples=101, engine_version="v1",
                     capabilities={"gravity": ["native", ""]}, trajectory_saved=False)
    measured = MeasuredMessage(
        status=status, figures=figures or {"penetration_max": 1e-6, "error": 0.01},
        expectations=[{"name": "e", "kind": "no_penetration", "passed": True}],
        error_source="analytic (e)")
    return RunRecord.from_messages(spec, ran, measured, revision_info(), machine_info())


def test_record_is_keyed_and_never_duplicated(tmp_path):
    store = ResultsStore(tmp_path)
    spec = make_run_spec("bouncing-ball-e0.5", "fake", extra_engine_modules=FAKE)
    assert store.record(_record(spec), scene=spec.scene)
    assert not store.record(_record(spec, "diverged"))  # same key: left as it was
    assert store.get(spec.key)["status"] == "ok"
    assert store.record(_record(spec, "diverged"), replace=True)
    assert store.get(spec.key)["status"] == "diverged"
    assert len(store) == 1
    with sqlite3.connect(store.path) as connection:
        assert connection.execute("SELECT COUNT(*) FROM runs").fetchone()[0] == 1


def test_record_fields_and_derived_times(tmp_path):
    store = ResultsStore(tmp_path)
    spec = make_run_spec("bouncing-ball-e0.5", "fake", extra_engine_modules=FAKE,
                         time_step=2e-3, options={"bias": 0.0})
    store.record(_record(spec), scene=spec.scene)
    row = store.get(spec.key)
    assert set(row) == set(COLUMNS)
    assert row["scene_hash"] == spec.scene.content_hash
    assert row["engine"] == "fake" and row["preset"] == "default"
    assert json.loads(row["options"]) == {"bias": 0.0}
    assert json.loads(row["scene_source"])["registry_name"] == "bouncing-ball-e0.5"
    # 0.2 s of stepping for 100 steps of 2e-3 s: 1e-3 s per step, 1 s per simulated second.
    assert math.isclose(row["stepping_seconds_per_step"], 2e-3, rel_tol=1e-12)
    assert math.isclose(row["stepping_seconds_per_simulated_second"], 1.0, rel_tol=1e-12)
    assert row["expectations_passed"] == 1
    assert row["hostname"] and row["cpu"] and row["git_revision"]
    assert store.scene(spec.scene.content_hash) == spec.scene


def test_the_stored_verdict_is_the_one_every_reader_derives(tmp_path):
    # An ok run whose expectations passed but whose instrument witnessed an unseen
    # penetration (any depth > 0) is stored "unseen penetration", as the report and the CLI
    # derive it from the row's status, expectations and figures (run_verdict).
    store = ResultsStore(tmp_path)
    spec = make_run_spec("bouncing-ball-e0.5", "fake", extra_engine_modules=FAKE)
    store.record(_record(spec, figures={"unseen_penetration": 1e-4, "error": 0.01}))
    row = store.get(spec.key)
    assert row["verdict"] == "unseen penetration"
    assert row["verdict"] == run_verdict(row["status"], row["expectations_passed"],
                                         json.loads(row["metrics"]))


def test_dataframe_expands_metrics(tmp_path):
    store = ResultsStore(tmp_path)
    for dt in (1e-3, 5e-4):
        spec = make_run_spec("bouncing-ball-e0.5", "fake", extra_engine_modules=FAKE,
                             time_step=dt)
        store.record(_record(spec, figures={"error": dt}))
    frame = store.dataframe()
    assert isinstance(frame, pd.DataFrame) and len(frame) == 2
    assert sorted(frame["m_error"]) == [5e-4, 1e-3]
    assert set(frame["label"]) == {"fake[default]"}
    # pandas reads the database directly as well.
    with sqlite3.connect(store.path) as connection:
        assert len(pd.read_sql("SELECT * FROM runs", connection)) == 2


def test_trajectory_file_moves_into_the_store_with_the_record(tmp_path):
    store = ResultsStore(tmp_path / "store")
    spec = make_run_spec("bouncing-ball-e0.5", "fake", extra_engine_modules=FAKE)
    trajectory = Trajectory.empty("fake", "default", spec.scene, RunStatus.OK, "")
    temporary = tmp_path / "tmp.npz"
    trajectory.save(temporary)
    assert store.record(_record(spec), trajectory_file=temporary)
    assert not temporary.exists()
    row = store.get(spec.key)
    loaded = store.load_trajectory(spec.key)
    assert row["trajectory"] == f"trajectories/{spec.key}.npz"
    assert loaded.scene_hash == spec.scene.content_hash
    assert np.array_equal(loaded.times, trajectory.times)


def test_a_failed_transaction_records_nothing(tmp_path):
    store = ResultsStore(tmp_path)
    spec = make_run_spec("bouncing-ball-e0.5", "fake", extra_engine_modules=FAKE)
    missing = tmp_path / "no-such-file.npz"
    try:
        store.record(_record(spec), trajectory_file=missing)
    except FileNotFoundError:
        pass
    assert len(store) == 0


def test_a_runner_removes_the_temporary_files_a_killed_sweep_left(tmp_path):
    """A sweep killed between saving a run's trajectory and recording it leaves
    ``.KEY.PID.tmp.npz`` (or its ``.partial.npz``) behind; the next runner on the store removes
    the ones older than an hour and keeps a fresh one (a run being recorded right now)."""
    import os
    import time

    from clearbench.harness.run.runner import Runner

    store = ResultsStore(tmp_path / "store")
    folder = store.trajectory_dir
    stale = [folder / ".abc.123.tmp.npz", folder / ".abc.123.tmp.npz.partial.npz"]
    fresh = folder / ".def.456.tmp.npz"
    kept = folder / "abc.npz"  # a recorded trajectory is never touched, whatever its age
    two_hours_ago = time.time() - 7200.0  # beyond the one-hour bound of clean_partial_files
    for path in (*stale, fresh, kept):
        path.write_bytes(b"")
    for path in (*stale, kept):
        os.utime(path, (two_hours_ago, two_hours_ago))
    Runner(store, jobs=1)
    assert sorted(p.name for p in folder.iterdir()) == sorted([fresh.name, kept.name])


def test_a_version_1_store_is_migrated_and_its_runs_kept(tmp_path):
    # A store of the first schema (no verdict nor measure_key columns): opened, it gains them;
    # its rows stay readable (their keys were computed by other rules and match no new run).
    spec = make_run_spec("bouncing-ball-e0.5", "fake", extra_engine_modules=FAKE)
    store = ResultsStore(tmp_path / "store")
    store.record(_record(spec), scene=spec.scene)
    with sqlite3.connect(store.path) as connection:
        for column in ("verdict", "measure_key"):
            connection.execute(f"ALTER TABLE runs DROP COLUMN {column}")
        connection.execute("UPDATE meta SET value = '1' WHERE name = 'schema_version'")
    migrated = ResultsStore(tmp_path / "store")
    row = migrated.get(spec.key)
    assert row["status"] == "ok" and row["verdict"] == "" and row["measure_key"] == ""
    assert migrated.reusable() == {spec.key: ""}
    with sqlite3.connect(store.path) as connection:
        assert connection.execute("SELECT value FROM meta").fetchone()[0] == "2"
