"""The C-60 studies (``clearbench c60 validate``, ``clearbench c60 identify``) make their runs
through the one run pipeline: isolated workers with a wall-clock limit, the results store, the
run key of every run. A repeated study makes no run; a changed scene or code is a new key; a run
past its limit is reported with its status, not raised."""

from __future__ import annotations

import json

import pytest

import clearbench
from clearbench.harness.c60 import identification
from clearbench.harness.c60.runs import RunRequest, StudyRuns
from clearbench.harness.cli.main import main
from clearbench.harness.run.runner import Runner
from clearbench.harness.run.store import ResultsStore

#: A c60-on horizon that keeps a run to 50 steps (seconds in a worker); the study's is 4 ms.
SHORT_HORIZON = 0.05


def on_only(name: str) -> identification.Candidate:
    from dataclasses import replace

    return replace(identification.candidates(name)[0], trip_test=False, contact_test=False)


def short_study(store_dir) -> tuple[StudyRuns, identification.Identification]:
    store = ResultsStore(store_dir)
    runs = StudyRuns(store, Runner(store, jobs=2))
    study = identification.identify(runs, [on_only("latch-0.1")], on_horizon=SHORT_HORIZON,
                                    calibrate=False)
    return runs, study


def test_a_repeated_study_serves_its_runs_from_the_store(tmp_path):
    first, study = short_study(tmp_path)
    assert len(first.made) == 2 and first.reused == [] and len(first.store) == 2
    assert [run.status for run in study.runs.values()] == ["ok", "ok"]
    rows = first.store.dataframe(expand_metrics=False)
    assert set(rows["campaign"]) == {"c60"} and set(rows["engine"]) == {"reference"}
    again, repeated = short_study(tmp_path)
    assert again.made == [] and sorted(again.reused) == sorted(first.made)
    # The same stored runs, so the same figures, to the bit.
    assert repeated.figures[0].fc_mean == study.figures[0].fc_mean
    assert repeated.figures[0].fc1_prototype == study.figures[0].fc1_prototype


def test_a_changed_scene_preset_or_code_is_another_run(tmp_path, monkeypatch):
    runs = StudyRuns(ResultsStore(tmp_path), run_missing=False)
    request = RunRequest("on", "c60-on", {"horizon": SHORT_HORIZON})
    key = runs.spec(request).key
    assert runs.spec(RunRequest("on", "c60-on", {"horizon": 2 * SHORT_HORIZON})).key != key
    assert runs.spec(RunRequest("on", "c60-on", {"horizon": SHORT_HORIZON,
                                                 "variant": "latch-0.1"})).key != key
    other_preset = StudyRuns(ResultsStore(tmp_path), run_missing=False,
                             engine="reference[nsgs]")
    assert other_preset.spec(request).key != key
    # An engine option (a scheme variant to validate) is another run, named in the reports.
    held = StudyRuns(ResultsStore(tmp_path), run_missing=False, options={"activation": "held"})
    assert held.spec(request).key != key
    assert held.spec(request).options_dict == {"activation": "held"}
    assert held.settings_label == "default; options activation=held"
    assert runs.settings_label == "default"
    monkeypatch.setitem(clearbench._SOURCE_DIGESTS, clearbench.PHYSICS_SUBPACKAGES, "0" * 16)
    assert StudyRuns(ResultsStore(tmp_path), run_missing=False).spec(request).key != key


def test_validate_reports_runs_past_their_limit_and_reuses_them(tmp_path, capsys):
    out = tmp_path / "validation.md"
    command = ["c60", "validate", "--no-sensitivity", "--no-speed-check", "--timeout", "0.001",
               "--store", str(tmp_path / "store"), "--out", str(out), "--figures",
               str(tmp_path / "figures"), "--no-progress"]
    assert main(command) == 0
    printed = capsys.readouterr().out
    assert "C-60 runs: 5 made, 0 reused" in printed
    report = json.loads(out.with_suffix(".json").read_text())
    assert [run["status"] for run in report["runs"]] == ["timed_out"] * 5
    assert "Run on_nominal (c60-on) ended timed_out: wall-clock limit of 0.001 s reached" \
        in report["findings"]
    fc1 = next(row for row in report["rows"] if row["quantity"].startswith("FC-1, C7"))
    assert fc1["ours"] is None and "| timed_out |" in out.read_text()
    # A time-out is a recorded outcome: the same command serves it from the store.
    assert main(command) == 0
    assert "C-60 runs: 0 made, 5 reused" in capsys.readouterr().out


def test_identify_notes_a_run_past_its_limit_on_its_variant(tmp_path, capsys):
    out = tmp_path / "identification.md"
    assert main(["c60", "identify", "--variants", "latch-0.1", "--no-calibration",
                 "--timeout", "0.001", "--store", str(tmp_path / "store"), "--out", str(out),
                 "--no-progress"]) == 0
    assert "C-60 runs: 3 made, 0 reused" in capsys.readouterr().out
    text = out.read_text()
    assert ("c60-on (mean clearances) ended timed_out (wall-clock limit of 0.001 s reached)"
            in text)
    assert "trip test ended timed_out" in text
    row = json.loads(out.with_suffix(".json").read_text())["variants"][0]
    assert row["fc1_prototype_N"] is None and row["trip_peak_N"] is None


def test_a_bad_preset_is_refused_before_any_run(tmp_path, capsys):
    assert main(["c60", "validate", "--preset", "nonsense", "--store", str(tmp_path)]) == 2
    assert "nonsense" in capsys.readouterr().err
    assert not (tmp_path / "runs.sqlite").exists()


@pytest.mark.parametrize("option", ["activation=nonsense", "no_such_option=1"])
def test_a_bad_engine_option_is_refused_before_any_run(tmp_path, capsys, option):
    assert main(["c60", "validate", "--option", option, "--store", str(tmp_path)]) == 2
    assert option.split("=")[0] in capsys.readouterr().err
    assert not (tmp_path / "runs.sqlite").exists()


@pytest.mark.slow
def test_identify_twice_makes_its_runs_once(tmp_path, capsys):
    # Two c60-on runs of the study's 4 ms (seconds each with a warm numba cache).
    out = tmp_path / "identification.md"
    command = ["c60", "identify", "--variants", "latch-0.1", "--runs", "on",
               "--no-calibration", "--store", str(tmp_path / "store"), "--out", str(out),
               "--no-progress"]
    assert main(command) == 0
    assert "C-60 runs: 2 made, 0 reused" in capsys.readouterr().out
    first = out.with_suffix(".json").read_text()
    assert main(command) == 0
    assert "C-60 runs: 0 made, 2 reused" in capsys.readouterr().out
    assert out.with_suffix(".json").read_text() == first
