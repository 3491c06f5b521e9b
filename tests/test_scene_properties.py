"""Property-based: generated scenes (tests/runnable_scenes.py). An invalid one makes
``clearbench validate`` and ``clearbench run`` exit 2 naming the field at fault, before any
engine runs; a valid one runs a few steps in every available engine through the Runner
(isolated workers: a crash is an outcome) and ends in a recorded verdict, never a harness
traceback (a measurement that raised is recorded as ``metrics_error``)."""

from __future__ import annotations

import copy
import json
import tempfile
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from clearbench.adapters import all_availability
from clearbench.adapters.trajectory import RunStatus
from clearbench.harness.cli.main import main
from clearbench.harness.measure.verdicts import VERDICTS, run_verdict
from clearbench.harness.run.runner import Runner
from clearbench.harness.run.spec import make_run_spec
from clearbench.harness.run.store import ResultsStore

from .runnable_scenes import MUTATIONS, valid_scene

QUICK = settings(max_examples=2, deadline=None, derandomize=True,
                 suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
MORE = settings(max_examples=25, deadline=None,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
#: Wall-clock limit of one generated run [s]: five steps of a three-body scene take well under
#: a second in every engine; the limit only bounds a hang (recorded as timed out).
RUN_LIMIT = 120.0


def _write(scene: dict, directory: Path) -> Path:
    path = directory / "generated.json"
    path.write_text(json.dumps(scene))
    return path


# capsys is read out at the start of each example, so sharing it across examples is safe.
@settings(max_examples=30, deadline=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(scene=valid_scene(), mutation=st.sampled_from(MUTATIONS))
def test_an_invalid_scene_exits_2_naming_the_field(scene, mutation, capsys):
    what, field, mutate = mutation
    bad = copy.deepcopy(scene)
    mutate(bad)
    with tempfile.TemporaryDirectory() as directory:
        path = _write(bad, Path(directory))
        capsys.readouterr()
        assert main(["validate", str(path)]) == 2, what
        assert field in capsys.readouterr().err, what
        store = Path(directory) / "store"
        assert main(["run", str(path), "--store", str(store)]) == 2, what
        assert field in capsys.readouterr().err, what
        assert not store.exists()  # refused before any engine ran or anything was stored


def _run_everywhere(scenes: list[dict]) -> None:
    engines = [a.engine for a in all_availability() if a.available]
    with tempfile.TemporaryDirectory() as directory:
        specs = []
        for number, scene in enumerate(scenes):
            folder = Path(directory) / str(number)
            folder.mkdir()
            path = _write(scene, folder)
            assert main(["validate", str(path)]) == 0
            specs += [make_run_spec(path, engine, timeout=RUN_LIMIT) for engine in engines]
        store = ResultsStore(Path(directory) / "store")
        outcome = Runner(store, jobs=2, runs_per_worker=len(specs)).run_all(specs)
        assert len(outcome.ran) == len({spec.key for spec in specs})  # equal scenes: one run
        for spec in specs:
            row = store.get(spec.key)
            assert row is not None, spec.label
            assert row["status"] in {s.value for s in RunStatus}, spec.label
            assert run_verdict(row["status"], row["expectations_passed"]) in VERDICTS
            assert not row["metrics_error"], (spec.label, row["metrics_error"])


@QUICK
@given(scenes=st.lists(valid_scene(), min_size=1, max_size=2))
def test_valid_scenes_run_in_every_engine_to_a_recorded_verdict(scenes):
    _run_everywhere(scenes)


@pytest.mark.slow
@MORE
@given(scenes=st.lists(valid_scene(), min_size=1, max_size=3))
def test_valid_scenes_run_in_every_engine_to_a_recorded_verdict_many(scenes):
    _run_everywhere(scenes)
