"""The runner: isolated workers whose crash, hang, exception or NaN is a recorded outcome;
input errors named before any run; deterministic keys; a sweep killed with -9 resumes."""

from __future__ import annotations

import math
import os
import re
import signal
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from clearbench.adapters import all_availability
from clearbench.harness.run.engine_choice import RunInputError, parse_engine_label
from clearbench.harness.run.runner import Runner
from clearbench.harness.run.spec import make_run_spec
from clearbench.harness.run.store import ResultsStore

from .harness_helpers import FAKE, ROOT, subprocess_env


def fake_spec(preset: str = "default", scene: str = "torque-free-flip", **kwargs):
    kwargs.setdefault("horizon", 0.5)
    return make_run_spec(scene, f"fake[{preset}]", extra_engine_modules=FAKE, **kwargs)


def test_every_failure_is_recorded_and_the_rest_of_the_sweep_completes(tmp_path):
    store = ResultsStore(tmp_path / "store")
    specs = {
        "segfault": fake_spec("segfault"),
        "hang": fake_spec("hang", timeout=2.0),
        "nan": fake_spec("nan"),
        "raise": fake_spec("raise"),
        "ok": fake_spec("default"),
        "ok-fine": fake_spec("default", time_step=5e-4),
        "unsupported": fake_spec("default", scene="clearance-pendulum"),
    }
    start = time.monotonic()
    outcome = Runner(store, jobs=2).run_all(specs.values())
    elapsed = time.monotonic() - start
    assert len(outcome.ran) == len(specs) and len(store) == len(specs)
    rows = {name: store.get(spec.key) for name, spec in specs.items()}
    assert rows["segfault"]["status"] == "crashed"
    assert "SIGSEGV" in rows["segfault"]["message"]
    assert rows["hang"]["status"] == "timed_out"
    assert "2 s" in rows["hang"]["message"]
    assert rows["nan"]["status"] == "diverged"  # the engine said OK: the harness's guard
    assert rows["nan"]["engine_status"] == "ok"
    assert "non-finite positions" in rows["nan"]["message"]
    assert rows["raise"]["status"] == "crashed"
    assert "RuntimeError: fake engine failure" in rows["raise"]["message"]
    assert rows["unsupported"]["status"] == "unsupported"
    assert "clearance_joints" in rows["unsupported"]["message"]
    for name in ("ok", "ok-fine"):
        assert rows[name]["status"] == "ok"
        assert rows[name]["steps"] == round(0.5 / specs[name].time_step)
        assert Path(store.directory / rows[name]["trajectory"]).exists()
    # The hang is killed at its 2 s limit while the other runs go on beside it; 30 s is far
    # above 2 s + 7 worker start-ups of ~0.3 s on 2 cores, far below a hang that blocks.
    assert elapsed < 30.0
    # No temporary trajectory file is left behind.
    assert not list((store.directory / "trajectories").glob(".*"))


def test_energy_growth_is_a_diverged_verdict(tmp_path):
    store = ResultsStore(tmp_path / "store")
    spec = fake_spec("energy", scene="bouncing-ball-e0.5")
    Runner(store, jobs=1).run_all([spec])
    row = store.get(spec.key)
    assert row["engine_status"] == "ok" and row["status"] == "diverged"
    assert "energy grew" in row["message"]


@pytest.mark.parametrize("kwargs, field", [
    ({"scene": "no-such-scene"}, "scene"),
    ({"engine": "no-such-engine"}, "engine"),
    ({"engine": "fake[no-such-preset]"}, "engine preset"),
    ({"engine": "fake[default"}, "engine"),
    ({"time_step": 0.0}, "time_step"),
    ({"time_step": -1e-3}, "time_step"),
    ({"time_step": float("nan")}, "time_step"),
    ({"horizon": float("inf")}, "horizon"),
    ({"time_step": 2.0, "horizon": 1.0}, "time_step"),
    ({"record_every": 0}, "record_every"),
    ({"timeout": 0}, "timeout"),
    ({"options": {"no_such_option": 1}}, "fake option no_such_option"),
    ({"options": {"sleep": -1.0}}, "fake option sleep"),
    ({"scene_parameters": {"no_such_parameter": 1}}, "scene parameter 'no_such_parameter'"),
    ({"scene_parameters": {"radial_clearance": -1.0}}, "scene"),
])
def test_bad_input_names_the_field_before_any_run(kwargs, field):
    arguments = {"scene": "clearance-pendulum", "engine": "fake"}
    arguments.update(kwargs)
    scene = arguments.pop("scene")
    engine = arguments.pop("engine")
    with pytest.raises(RunInputError) as caught:
        make_run_spec(scene, engine, extra_engine_modules=FAKE, **arguments)
    assert caught.value.field == field
    assert str(caught.value).startswith(f"{field} = ")


def test_engine_labels():
    assert parse_engine_label("mujoco[elliptic]") == ("mujoco", "elliptic")
    assert parse_engine_label("reference") == ("reference", "default")
    with pytest.raises(RunInputError):
        parse_engine_label("a b")


def test_run_key_changes_with_the_physics_code_only(monkeypatch):
    # A trajectory of other physics code is never served as this code's (an adapter fix must
    # not need --rerun); the digest is of the sources' contents, the same on every clone. The
    # measuring code keys the measurement alone: its edit re-measures, reruns nothing.
    import clearbench

    key, measure_key = fake_spec().key, fake_spec().measure_key
    assert clearbench.source_digest() == clearbench.source_digest()
    monkeypatch.setitem(clearbench._SOURCE_DIGESTS, clearbench.MEASURING_SOURCES, "0" * 16)
    assert fake_spec().key == key and fake_spec().measure_key != measure_key
    monkeypatch.setitem(clearbench._SOURCE_DIGESTS, clearbench.PHYSICS_SUBPACKAGES, "0" * 16)
    assert fake_spec().key != key


def test_the_harness_is_not_a_physics_source():
    import clearbench

    assert not any(name.startswith("clearbench.harness")
                   for name in clearbench.PHYSICS_SUBPACKAGES)
    key_fields = fake_spec().key_fields
    assert key_fields["engine_version"] == "fake engine for tests 1.0"
    assert key_fields["plug_in"]  # an engine outside the package: its own source digest


def test_a_changed_measuring_code_measures_the_stored_trajectory_again(tmp_path, monkeypatch):
    import clearbench

    store = ResultsStore(tmp_path / "store")
    spec = fake_spec("nan")
    Runner(store, jobs=1).run_all([spec])
    first = store.get(spec.key)
    assert first["measure_key"] == spec.measure_key
    first_measure_key = spec.measure_key
    assert first["status"] == "diverged" and first["engine_status"] == "ok"
    assert first["verdict"] == "diverged"
    monkeypatch.setitem(clearbench._SOURCE_DIGESTS, clearbench.MEASURING_SOURCES, "0" * 16)
    again = Runner(store, jobs=1).run_all([spec])
    assert again.ran == [] and again.skipped == [spec.key] and again.remeasured == [spec.key]
    second = store.get(spec.key)
    assert second["measure_key"] == spec.measure_key != first_measure_key
    for column in ("status", "message", "engine_status", "metrics", "verdict", "trajectory",
                   "stepping_seconds", "recorded_utc"):
        assert second[column] == first[column], column
    assert Runner(store, jobs=1).run_all([spec]).remeasured == []


def test_run_key_identifies_the_physics_and_settings_only():
    base = fake_spec()
    assert fake_spec().key == base.key
    # The scene's own step given explicitly is the same run.
    assert fake_spec(time_step=1e-3).key == base.key
    assert fake_spec(time_step_factor=1.0).key == base.key
    # The wall-clock limit is not part of what a run is.
    assert fake_spec(timeout=5.0).key == base.key
    assert fake_spec(time_step=5e-4).key != base.key
    assert fake_spec(horizon=0.25).key != base.key
    assert fake_spec("nan").key != base.key
    assert fake_spec(options={"bias": 0.0}).key != base.key
    assert fake_spec(scene_parameters={"spin": 2.0}).key != base.key


def test_a_stored_run_is_not_run_again(tmp_path):
    store = ResultsStore(tmp_path / "store")
    spec = fake_spec()
    first = Runner(store, jobs=1).run_all([spec, spec])
    assert first.ran == [spec.key]  # the same run twice in one sweep is run once
    second = Runner(store, jobs=1).run_all([spec])
    assert second.ran == [] and second.skipped == [spec.key]
    third = Runner(store, jobs=1).run_all([spec], rerun=True)
    assert third.ran == [spec.key]
    assert len(store) == 1


def test_reused_workers_serve_several_runs_and_a_crash_replaces_one(tmp_path):
    store = ResultsStore(tmp_path / "store")
    specs = [fake_spec(time_step=dt) for dt in (1e-3, 5e-4, 2.5e-4)]
    specs.insert(1, fake_spec("segfault"))
    Runner(store, jobs=1, runs_per_worker=10).run_all(specs)
    statuses = [store.get(s.key)["status"] for s in specs]
    assert statuses == ["ok", "crashed", "ok", "ok"]


def test_a_reused_worker_gives_every_engine_the_trajectory_of_a_fresh_one(tmp_path):
    # compare, demo and regress reuse their workers (MANY_RUNS_PER_WORKER): a run must not depend on
    # what ran before it in the process. Each available engine on two scenes, once in a fresh
    # process per run and once all in one process in reverse order (every engine after the
    # others): the same arrays bit for bit, and the same figures
    engines = [a.engine for a in all_availability() if a.available]
    specs = [make_run_spec(scene, engine, horizon=horizon)
             for scene, horizon in (("bouncing-ball-e0", 0.2), ("clearance-pendulum", 0.05))
             for engine in engines]
    fresh = ResultsStore(tmp_path / "fresh")
    reused = ResultsStore(tmp_path / "reused")
    Runner(fresh, jobs=1, runs_per_worker=1).run_all(specs)
    Runner(reused, jobs=1, runs_per_worker=len(specs)).run_all(specs[::-1])
    for spec in specs:
        one, other = fresh.get(spec.key), reused.get(spec.key)
        assert (one["status"], one["metrics"]) == (other["status"], other["metrics"]), spec.label
        first, second = fresh.load_trajectory(spec.key), reused.load_trajectory(spec.key)
        if first is None:
            assert second is None, spec.label
            continue
        for name in ("times", "positions", "orientations", "velocities",
                     "contact_normal_force"):
            assert np.array_equal(getattr(first, name), getattr(second, name),
                                  equal_nan=True), (spec.label, name)


def _children(pid: int) -> set[int]:
    children = set()
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[1]) == pid:
            children.add(int(stat.parent.name))
    return children


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


def _stored_count(database: Path) -> int:
    if not database.exists():
        return 0
    try:
        with sqlite3.connect(database, timeout=10) as connection:
            return connection.execute("SELECT COUNT(*) FROM runs").fetchone()[0]
    except sqlite3.OperationalError:  # table not created yet
        return 0


@pytest.mark.skipif(not Path("/proc").exists(), reason="needs Linux /proc")
def test_kill_9_of_a_sweep_then_rerun_gives_every_run_exactly_once(tmp_path):
    store = tmp_path / "store"
    ladder = "1e-3,9e-4,8e-4,7e-4,6e-4,5e-4,4e-4,3e-4"
    command = [sys.executable, "-m", "clearbench.harness.cli.main", "sweep", "torque-free-flip",
               "--engines", "fake", "--engine-module", "fake=tests.fake_engine", "--dt", ladder,
               "--horizon", "8", "--reference-engine", "none", "--store", str(store),
               "--jobs", "2", "--no-progress"]
    sweep = subprocess.Popen(command, cwd=ROOT, env=subprocess_env(), stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True)
    database = store / "runs.sqlite"
    deadline = time.monotonic() + 60
    workers: set[int] = set()
    while time.monotonic() < deadline and _stored_count(database) < 2:
        workers |= _children(sweep.pid)
        time.sleep(0.05)
        assert sweep.poll() is None, sweep.communicate()
    workers |= _children(sweep.pid)
    recorded_before = _stored_count(database)
    assert 2 <= recorded_before < 8, "the sweep must be killed part-way"
    sweep.send_signal(signal.SIGKILL)
    sweep.wait()
    assert workers, "the sweep ran its runs in worker processes"
    # Workers die with their parent (PR_SET_PDEATHSIG): none is left running. A worker killed
    # while still importing (spawn) sets PR_SET_PDEATHSIG only once its import ends, then sees
    # its parent gone (getppid) and exits: its import took up to 25 s at load average 5-9 on
    # 2 cores, so 90 s bounds a loaded machine while an orphan that never exits still fails.
    deadline = time.monotonic() + 90
    while time.monotonic() < deadline and any(_alive(p) for p in workers):
        time.sleep(0.05)
    assert not any(_alive(p) for p in workers)
    again = subprocess.run(command, cwd=ROOT, env=subprocess_env(), capture_output=True,
                           text=True, timeout=120)
    assert again.returncode == 0, again.stderr
    counts = re.search(r"(\d+) runs done, (\d+) reused", again.stdout)
    done, reused = int(counts.group(1)), int(counts.group(2))
    assert reused >= recorded_before and done + reused == 8
    with sqlite3.connect(database) as connection:
        rows = connection.execute("SELECT key, time_step, status FROM runs").fetchall()
    assert len(rows) == 8 and len({r[0] for r in rows}) == 8
    assert sorted(r[1] for r in rows) == sorted(float(x) for x in ladder.split(","))
    assert all(r[2] == "ok" for r in rows)


def test_measure_phase_errors_do_not_hide_the_run(tmp_path):
    """A failing metric is recorded beside an ok run, never as the run's outcome."""
    store = ResultsStore(tmp_path / "store")
    spec = fake_spec()
    Runner(store, jobs=1).run_all([spec])
    row = store.get(spec.key)
    assert row["status"] == "ok"
    assert math.isfinite(row["stepping_seconds_per_step"]) and row["stepping_seconds_per_step"] > 0
    assert os.path.exists(store.directory / row["trajectory"])


def test_a_run_measured_against_a_reference_of_its_batch_starts_after_it(tmp_path):
    # One batch holds a slow fine reference and two runs measured against it, on two
    # workers: neither run may start before the reference is stored (its error would be
    # measured against nothing), and both get their error.
    from clearbench.harness.run.runner import RunJob

    store = ResultsStore(tmp_path / "store")
    fine = fake_spec(time_step=5e-4, options={"sleep": 2.0})
    runs = [RunJob(fake_spec(time_step=dt), reference_key=fine.key) for dt in (1e-3, 2e-3)]
    Runner(store, jobs=2).run_all([RunJob(fine), *runs])
    reference = store.get(fine.key)
    for job in runs:
        row = store.get(job.spec.key)
        assert row["recorded_utc"] >= reference["recorded_utc"]
        assert math.isfinite(row["error"]) and row["error"] > 0.0


def test_a_warm_up_job_runs_first_for_its_engine_alone_and_is_not_stored(tmp_path):
    # A warm-up (numba's cache filled by one worker) holds back every job of its engine until
    # it ends, while the other worker runs another engine's job; it is neither stored nor
    # counted. The warm-up sleeps 6 s: far longer than a fake run on the other worker (tenths
    # of a second after its start-up), so the order below does not hang on the machine's speed.
    from clearbench.harness.run.runner import RunJob

    engines = {"fake": "tests.fake_engine", "other": "tests.fake_engine"}
    warm_up = make_run_spec("torque-free-flip", "fake", horizon=0.002,
                            options={"sleep": 6.0}, extra_engine_modules=engines,
                            campaign="numba-warm-up")
    gated = [make_run_spec("torque-free-flip", "fake", horizon=h, extra_engine_modules=engines)
             for h in (0.1, 0.2)]
    free = make_run_spec("torque-free-flip", "other", horizon=0.1, extra_engine_modules=engines)
    finished = []
    start = time.monotonic()
    store = ResultsStore(tmp_path / "store")
    outcome = Runner(store, jobs=2, on_finished=lambda done, total, spec, record: finished.append(
        (spec.key, time.monotonic() - start, total))).run_all(
        [RunJob(warm_up, warm_up=True), *gated, free])
    assert sorted(outcome.ran) == sorted(s.key for s in (*gated, free))
    assert len(store) == 3 and store.get(warm_up.key) is None
    assert [total for _, _, total in finished] == [3, 3, 3]  # the warm-up is not counted
    assert finished[0][0] == free.key  # it ran beside the warm-up
    assert sorted(key for key, _, _ in finished[1:]) == sorted(s.key for s in gated)
    for _, seconds, _ in finished[1:]:
        assert seconds >= 6.0  # the fake engine's runs waited for the warm-up's 6 s sleep


def test_warm_up_jobs_one_per_scene_preset_and_options_of_the_compiling_engines():
    from clearbench.harness.run.numba_cache import WARM_UP_TIMEOUT, warm_up_jobs

    engines = {"fake": "tests.fake_engine"}
    specs = [make_run_spec("torque-free-flip", "fake", time_step=dt, extra_engine_modules=engines)
             for dt in (1e-3, 2e-3)]
    specs.append(make_run_spec("torque-free-flip", "fake", options={"bias": 1.0},
                               extra_engine_modules=engines))
    assert warm_up_jobs(specs, engines=("reference",)) == []
    jobs = warm_up_jobs(specs, engines=("fake",))
    assert len(jobs) == 2 and all(job.warm_up for job in jobs)  # two options, one scene
    first = jobs[0].spec
    assert first.horizon == 2 * first.time_step == 2e-3  # the first spec's step, two steps
    assert first.timeout == WARM_UP_TIMEOUT and first.campaign == "numba-warm-up"
