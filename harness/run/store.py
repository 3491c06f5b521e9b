"""The results store: one SQLite database of runs, plus one .npz trajectory per run beside it.

Layout of a store directory::

    runs.sqlite            table ``runs`` (one row per run, keyed by what determines its
                           trajectory, with the key of what determines its measurement), table
                           ``scenes`` (scene JSON by content hash), table ``meta`` (schema
                           version)
    trajectories/KEY.npz   the trajectory of run KEY (clearbench.adapters.trajectory format)

A run is recorded only when complete, in one transaction (the trajectory file is moved into
place inside it); the key is the primary key, so a run can never be recorded twice, and a sweep
killed at any instant leaves either the whole run or nothing. ``pandas`` reads it with
:meth:`ResultsStore.dataframe` (metrics expanded into ``m_<name>`` columns) or directly with
``pandas.read_sql("select * from runs", sqlite3.connect(path))``.
"""

from __future__ import annotations

import contextlib
import dataclasses
import json
import math
import os
import platform
import socket
import sqlite3
import subprocess
import time
from collections.abc import Iterator
from dataclasses import asdict, dataclass, fields
from datetime import UTC, datetime
from functools import lru_cache
from pathlib import Path

import clearbench
from clearbench.adapters.trajectory import RunStatus, Trajectory
from clearbench.harness.measure.verdicts import run_verdict
from clearbench.harness.run.messages import MeasuredMessage, RanMessage
from clearbench.harness.run.spec import RunSpec
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.serialization import scene_from_dict, scene_to_dict

#: Version 2 added ``measure_key`` and ``verdict``; a version-1 store is migrated when opened
#: (its runs are keyed by other rules: none is reused, each is run again when asked for).
SCHEMA_VERSION = 2
#: Stored outcomes that are run again when asked for, rather than served from the store. A
#: crash is not always a property of the run: a worker killed from outside (out of memory, a
#: signal), an engine's interpreter failing to start, an input no check caught; served, it
#: would stand until the code changes. Rerunning it costs little (most crashes happen while
#: building or in the first steps) and gives the same record when the crash is the engine's.
#: A time-out is served: it costs the whole wall-clock limit each time (``--rerun`` asks).
RERUN_STATUSES = (RunStatus.CRASHED.value,)
DATABASE = "runs.sqlite"
TRAJECTORIES = "trajectories"


@dataclass(frozen=True)
class RunRecord:
    """One row of the ``runs`` table (units: seconds for wall times, the scene's own units for
    ``time_step``, ``horizon`` and the metrics).

    ``status`` is the run's status (ok / diverged / crashed / timed_out / unsupported) after
    the harness's own checks of the trajectory (non-finite values, tunnelling, escape);
    ``engine_status`` is what the engine or worker reported before them; ``verdict`` the
    run's verdict from its status and expectations (a key of
    :data:`clearbench.harness.measure.verdicts.VERDICTS`). ``key`` is the run key (what
    determines the trajectory), ``measure_key`` what determines the measurement
    (:attr:`~clearbench.harness.run.spec.RunSpec.measure_key`).
    """

    key: str
    recorded_utc: str
    campaign: str
    scene_name: str
    scene_hash: str
    scene_source: str            # JSON: registry name and parameters, or file
    engine: str
    preset: str
    engine_version: str
    time_step: float
    horizon: float
    record_every: int
    options: str                 # JSON
    timeout: float
    status: str
    message: str
    engine_status: str
    engine_message: str
    worker_seconds: float        # whole run phase in the worker (import, build, stepping) [s]
    build_seconds: float         # building the engine model [s]
    stepping_seconds: float      # stepping alone [s]
    steps: int
    samples: int
    stepping_seconds_per_simulated_second: float
    stepping_seconds_per_step: float
    error: float                 # headline error (relative, see measure.figures), NaN when none
    error_source: str
    expectations_passed: int | None   # 1 all passed, 0 one failed, None none judged
    metrics: str                 # JSON: flat name -> float
    expectations: str            # JSON: list of per-expectation results
    capabilities: str            # JSON: feature -> [support, detail]
    verdict_reason: str
    metrics_error: str
    verdict: str
    measure_key: str
    git_revision: str
    git_dirty: int
    hostname: str
    cpu: str
    cores: int
    python: str
    clearbench_version: str
    trajectory: str              # path relative to the store, "" when none

    @classmethod
    def from_messages(cls, spec: RunSpec, ran: RanMessage, measured: MeasuredMessage,
                      revision: dict, machine: dict) -> RunRecord:
        """Assemble a row from the spec and the worker's two messages (:mod:`.messages`)."""
        stepping = float(ran.stepping_seconds)
        steps = int(ran.steps or 0)
        simulated = steps * spec.time_step
        record = cls(
            key=spec.key,
            recorded_utc=datetime.now(UTC).isoformat(timespec="seconds"),
            campaign=spec.campaign,
            scene_name=spec.scene.name,
            scene_hash=spec.scene.content_hash,
            scene_source=json.dumps(spec.source.to_dict(), sort_keys=True),
            engine=spec.engine.name,
            preset=spec.engine.preset,
            engine_version=str(ran.engine_version),
            time_step=float(spec.time_step),
            horizon=float(spec.horizon),
            record_every=int(spec.record_every),
            options=json.dumps(spec.options_dict, sort_keys=True),
            timeout=float(spec.timeout),
            status=ran.status,
            message=ran.message,
            engine_status=ran.status,
            engine_message=ran.message,
            worker_seconds=float(ran.worker_seconds),
            build_seconds=float(ran.build_seconds),
            stepping_seconds=stepping,
            steps=steps,
            samples=int(ran.samples or 0),
            stepping_seconds_per_simulated_second=(
                stepping / simulated if simulated > 0 else math.nan),
            stepping_seconds_per_step=stepping / steps if steps > 0 else math.nan,
            error=math.nan,
            error_source="",
            expectations_passed=None,
            metrics="{}",
            expectations="[]",
            capabilities=json.dumps(ran.capabilities, sort_keys=True),
            verdict_reason="",
            metrics_error="",
            verdict="",
            measure_key="",
            git_revision=revision["revision"],
            git_dirty=int(revision["dirty"]),
            hostname=machine["hostname"],
            cpu=machine["cpu"],
            cores=int(machine["cores"]),
            python=machine["python"],
            clearbench_version=clearbench.__version__,
            trajectory="",
        )
        return record.measured(measured, spec.measure_key)

    def measured(self, measured: MeasuredMessage, measure_key: str) -> RunRecord:
        """This row with the measurement ``measured`` (keyed ``measure_key``): the run's
        status (the engine's when nothing was measured), its message (the reason of the
        harness's checks where they changed the status), figures, expectations and verdict."""
        status = measured.status or self.engine_status
        message = self.engine_message
        if measured.status and measured.status != self.engine_status:
            message = measured.reason or message
        figures = measured.figures or {}
        results = measured.expectations or []
        judged = [r.get("passed") for r in results if r.get("passed") is not None]
        passed = None if not judged else int(all(judged))
        return dataclasses.replace(
            self, status=status, message=message,
            error=float(figures.get("error", math.nan)), error_source=measured.error_source,
            expectations_passed=passed, metrics=json.dumps(figures, sort_keys=True),
            expectations=json.dumps(results, sort_keys=True),
            verdict_reason=measured.reason, metrics_error=measured.metrics_error,
            verdict=run_verdict(status, passed, figures), measure_key=measure_key)

    @classmethod
    def from_row(cls, row: dict) -> RunRecord:
        """The record of a stored row (:meth:`ResultsStore.get`)."""
        return cls(**{name: row[name] for name in COLUMNS})


_SQL_TYPES = {"str": "TEXT", "float": "REAL", "int": "INTEGER", "int | None": "INTEGER"}
COLUMNS: tuple[str, ...] = tuple(f.name for f in fields(RunRecord))


def _create_table_sql() -> str:
    columns = []
    for f in fields(RunRecord):
        sql_type = _SQL_TYPES[str(f.type)]
        suffix = " PRIMARY KEY" if f.name == "key" else ""
        columns.append(f"{f.name} {sql_type}{suffix}")
    return f"CREATE TABLE IF NOT EXISTS runs ({', '.join(columns)})"


@lru_cache(maxsize=1)
def revision_info() -> dict:
    """Git revision of the clearbench source tree and whether it has uncommitted changes."""
    root = Path(__file__).resolve().parents[2]
    try:
        revision = subprocess.run(["git", "rev-parse", "HEAD"], cwd=root, capture_output=True,
                                  text=True, timeout=10, check=True).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"],
                               cwd=root, capture_output=True, text=True, timeout=10,
                               check=True).stdout.strip() != ""
    except (OSError, subprocess.SubprocessError):
        return {"revision": f"unknown (clearbench {clearbench.__version__})", "dirty": False}
    return {"revision": revision, "dirty": dirty}


@lru_cache(maxsize=1)
def machine_info() -> dict:
    """Host name, CPU model, usable cores and Python version of this machine."""
    cpu = platform.processor() or platform.machine()
    with contextlib.suppress(OSError):
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    try:
        cores = len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover
        cores = os.cpu_count() or 1
    return {"hostname": socket.gethostname(), "cpu": cpu, "cores": cores,
            "python": platform.python_version()}


def _migrate_from_1(connection: sqlite3.Connection) -> str:
    """Add the columns of version 2 (``verdict``, ``measure_key``) to a version-1 store;
    returns the new version. Its runs keep their keys (computed by other rules: none matches
    a run asked for now)."""
    present = {row[1] for row in connection.execute("PRAGMA table_info(runs)")}
    for name in ("verdict", "measure_key"):
        if name not in present:
            connection.execute(f"ALTER TABLE runs ADD COLUMN {name} TEXT DEFAULT ''")
    connection.execute("UPDATE meta SET value = ? WHERE name = 'schema_version'",
                       (str(SCHEMA_VERSION),))
    return str(SCHEMA_VERSION)


class ResultsStore:
    """A results store in ``directory`` (created when missing)."""

    def __init__(self, directory: str | os.PathLike):
        self.directory = Path(directory)
        self.trajectory_dir.mkdir(parents=True, exist_ok=True)
        with self._connect() as connection:
            connection.execute(_create_table_sql())
            connection.execute("CREATE TABLE IF NOT EXISTS scenes (scene_hash TEXT PRIMARY KEY, "
                               "scene_name TEXT, scene_json TEXT)")
            connection.execute("CREATE TABLE IF NOT EXISTS meta (name TEXT PRIMARY KEY, "
                               "value TEXT)")
            connection.execute("INSERT OR IGNORE INTO meta VALUES ('schema_version', ?)",
                               (str(SCHEMA_VERSION),))
            version = connection.execute(
                "SELECT value FROM meta WHERE name = 'schema_version'").fetchone()[0]
            if int(version) == 1:
                version = _migrate_from_1(connection)
        if int(version) != SCHEMA_VERSION:
            raise ValueError(f"{self.path}: store schema version {version}, this clearbench "
                             f"reads version {SCHEMA_VERSION}")

    @property
    def path(self) -> Path:
        """The SQLite database."""
        return self.directory / DATABASE

    @property
    def trajectory_dir(self) -> Path:
        return self.directory / TRAJECTORIES

    def trajectory_path(self, key: str) -> Path:
        return self.trajectory_dir / f"{key}.npz"

    @contextlib.contextmanager
    def _connect(self) -> Iterator[sqlite3.Connection]:
        connection = sqlite3.connect(self.path, timeout=60.0, isolation_level=None)
        try:
            connection.execute("PRAGMA journal_mode=WAL")
            connection.execute("PRAGMA synchronous=FULL")
            yield connection
        finally:
            connection.close()

    # ------------------------------------------------------------------ writing
    def record(self, record: RunRecord, trajectory_file: Path | None = None,
               replace: bool = False, scene: Scene | None = None) -> bool:
        """Record a complete run atomically; its trajectory file is moved into the store.

        Returns False (and leaves the store as it was) when the key is already recorded and
        ``replace`` is False.
        """
        with self._connect() as connection:
            connection.execute("BEGIN IMMEDIATE")
            try:
                exists = connection.execute("SELECT 1 FROM runs WHERE key = ?",
                                            (record.key,)).fetchone() is not None
                if exists and not replace:
                    connection.execute("ROLLBACK")
                    return False
                row = asdict(record)
                if trajectory_file is not None:
                    final = self.trajectory_path(record.key)
                    os.replace(trajectory_file, final)
                    row["trajectory"] = str(final.relative_to(self.directory))
                elif exists:
                    self.trajectory_path(record.key).unlink(missing_ok=True)
                placeholders = ", ".join("?" for _ in COLUMNS)
                connection.execute(
                    f"INSERT OR REPLACE INTO runs ({', '.join(COLUMNS)}) VALUES ({placeholders})",
                    [row[c] for c in COLUMNS])
                if scene is not None:
                    connection.execute(
                        "INSERT OR IGNORE INTO scenes VALUES (?, ?, ?)",
                        (scene.content_hash, scene.name,
                         json.dumps(scene_to_dict(scene), sort_keys=True)))
                connection.execute("COMMIT")
            except BaseException:
                connection.execute("ROLLBACK")
                raise
        return True

    # ------------------------------------------------------------------ reading
    def keys(self) -> set[str]:
        with self._connect() as connection:
            return {row[0] for row in connection.execute("SELECT key FROM runs")}

    def reusable_keys(self) -> set[str]:
        """Keys of the runs a sweep may serve from the store instead of running them: every
        run but a crashed one (:data:`RERUN_STATUSES`)."""
        return set(self.reusable())

    def reusable(self) -> dict[str, str]:
        """Run key -> measurement key of the runs a sweep may serve from the store instead of
        running them: every run but a crashed one (:data:`RERUN_STATUSES`). A run whose
        measurement key is not the one asked for is measured again from its trajectory."""
        marks = ", ".join("?" for _ in RERUN_STATUSES)
        with self._connect() as connection:
            return {row[0]: row[1] for row in connection.execute(
                f"SELECT key, measure_key FROM runs WHERE status NOT IN ({marks})",
                RERUN_STATUSES)}

    def remeasure(self, record: RunRecord) -> None:
        """Replace the measurement of the stored run ``record.key`` by ``record``'s (status,
        message, figures, expectations, verdict, measurement key), its run and trajectory
        kept."""
        names = ("status", "message", "error", "error_source", "expectations_passed",
                 "metrics", "expectations", "verdict_reason", "metrics_error", "verdict",
                 "measure_key")
        row = asdict(record)
        with self._connect() as connection:
            connection.execute(
                f"UPDATE runs SET {', '.join(f'{name} = ?' for name in names)} WHERE key = ?",
                [row[name] for name in names] + [record.key])

    def __len__(self) -> int:
        with self._connect() as connection:
            return int(connection.execute("SELECT COUNT(*) FROM runs").fetchone()[0])

    def get(self, key: str) -> dict | None:
        """The row of run ``key`` as a dict (JSON columns left as text), or None."""
        with self._connect() as connection:
            connection.row_factory = sqlite3.Row
            row = connection.execute("SELECT * FROM runs WHERE key = ?", (key,)).fetchone()
        return dict(row) if row is not None else None

    def scene(self, scene_hash: str) -> Scene | None:
        """The scene a run was given, by content hash (None when not stored)."""
        with self._connect() as connection:
            row = connection.execute("SELECT scene_json FROM scenes WHERE scene_hash = ?",
                                     (scene_hash,)).fetchone()
        return scene_from_dict(json.loads(row[0])) if row else None

    def load_trajectory(self, key: str) -> Trajectory | None:
        path = self.trajectory_path(key)
        return Trajectory.load(path) if path.exists() else None

    def dataframe(self, expand_metrics: bool = True):
        """Every run as a pandas DataFrame; ``m_<name>`` columns hold the metrics."""
        import pandas as pd  # lazy: pandas only for the commands that tabulate the store

        with self._connect() as connection:
            frame = pd.read_sql_query("SELECT * FROM runs ORDER BY recorded_utc, key",
                                      connection)
        frame["label"] = frame["engine"] + "[" + frame["preset"] + "]"
        if expand_metrics and len(frame):
            metrics = pd.DataFrame([json.loads(text or "{}") for text in frame["metrics"]],
                                   index=frame.index)
            metrics.columns = [f"m_{c}" for c in metrics.columns]
            frame = pd.concat([frame, metrics], axis=1)
        return frame

    def clean_partial_files(self, older_than: float = 3600.0) -> int:
        """Remove temporary trajectory files (``.KEY.PID.tmp.npz`` and their ``.partial.npz``)
        of runs interrupted more than ``older_than`` seconds ago; returns how many were
        removed. A :class:`~clearbench.harness.run.runner.Runner` calls it when it opens the
        store: a run's temporary file lives from its end to its recording (seconds; its
        measurement is bounded by ``MEASURE_TIMEOUT``), so an hour-old one was left by a sweep
        that was killed."""
        removed = 0
        cutoff = time.time() - older_than
        for path in self.trajectory_dir.glob(".*.npz"):
            with contextlib.suppress(OSError):
                if path.stat().st_mtime < cutoff:
                    path.unlink()
                    removed += 1
        return removed
