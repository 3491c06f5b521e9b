"""Regression check end to end with the fake engine: update, a clean pass, injected
regressions detected, bad suites refused, every available engine covered."""

from __future__ import annotations

import copy
import json

from clearbench.harness.cli.main import main
from clearbench.harness.run.engine_choice import engine_defaults
from clearbench.harness.studies.regress import (
    compare,
    measure_baseline,
    suite_entries,
    suite_specs,
    updated_baseline,
)

from .harness_helpers import FAKE_OPTION

SUITE = [
    {"id": "flip", "scene": "torque-free-flip", "engine": "fake", "horizon": 0.2},
    {"id": "ball", "scene": "bouncing-ball-e0.5", "engine": "fake", "horizon": 0.2,
     "time_step": 2e-3},
]
#: One round-off seed: the fake engine has no numba or OpenBLAS code path to perturb.
ROUNDOFF_ONLY = [{"name": "roundoff", "kind": "roundoff", "ulps": 4, "seeds": 1,
                  "why": "test"}]


def _baseline(tmp_path):
    path = tmp_path / "baseline.json"
    path.write_text(json.dumps({"description": "test", "suite": SUITE,
                                "perturbations": ROUNDOFF_ONLY, "results": {}}))
    return path


def test_regress_update_pass_and_injected_regression(tmp_path, capsys, monkeypatch):
    path = _baseline(tmp_path)
    arguments = ["regress", "--baseline", str(path), *FAKE_OPTION]
    assert main(arguments) == 1  # no baseline results yet
    assert "no baseline result" in capsys.readouterr().out
    assert main(arguments + ["--update"]) == 0
    written = json.loads(path.read_text())
    assert set(written["results"]) == {"flip", "ball"}
    assert written["suite"] == SUITE and written["perturbations"] == ROUNDOFF_ONLY
    assert "revision" in written["recorded"] and written["recorded"]["cost"]["runs"] == 4
    for result in written["results"].values():   # every figure has its measured check
        assert set(result["checks"]) == set(result["metrics"])
        assert result["perturbations"] == ["roundoff-1"]
    capsys.readouterr()
    assert main(arguments) == 0
    assert "no regression" in capsys.readouterr().out
    monkeypatch.setenv("CLEARBENCH_FAKE_NAN", "1")  # the workers inherit it: engine now NaNs
    assert main(arguments) == 1
    out = capsys.readouterr().out
    assert "flip: status ok -> diverged" in out and "ball: status ok -> diverged" in out


def test_regress_detects_a_metric_outside_its_tolerance(tmp_path, capsys, monkeypatch):
    path = _baseline(tmp_path)
    arguments = ["regress", "--baseline", str(path), *FAKE_OPTION]
    assert main(arguments + ["--update"]) == 0
    monkeypatch.setenv("CLEARBENCH_FAKE_BIAS", "1e-2")  # heights drift up 1 cm/s: 2 mm in 0.2 s
    capsys.readouterr()
    assert main(arguments) == 1
    out = capsys.readouterr().out
    # The potential energy m g z moves by m g 2 mm = 0.02 J of a 1 J scale: 2e-2 against a
    # floor of 1e-8 and a round-off spread.
    assert "ball: energy_drift" in out and "status" not in out


def test_regress_rejects_a_bad_suite(tmp_path, capsys):
    path = tmp_path / "bad.json"
    path.write_text(json.dumps({"suite": [{"id": "x", "scene": "nope", "engine": "fake"}]}))
    assert main(["regress", "--baseline", str(path), *FAKE_OPTION]) == 2
    assert "suite entry 'x'" in capsys.readouterr().err


def test_regress_rejects_a_bad_perturbation(tmp_path, capsys):
    path = tmp_path / "bad.json"
    path.write_text(json.dumps({"suite": SUITE, "perturbations": [
        {"name": "r", "kind": "roundoff", "ulps": 0, "seeds": 2}]}))
    assert main(["regress", "--baseline", str(path), *FAKE_OPTION]) == 2
    assert "perturbations[0].ulps: 0" in capsys.readouterr().err


def test_regress_covers_one_quick_scene_per_available_engine():
    """Every available engine on a quick scene: the baseline measured from a run and one
    round-off perturbation passes its own runs, and a moved figure is a regression naming the
    engine, the scene, the figure and the version."""
    from clearbench.adapters import ENGINES, all_availability

    labels = [f"{name}[{engine_defaults(name).regress_preset}]" for name in ENGINES]
    suite = [{"id": f"{label} incline-stick", "scene": "incline-stick", "engine": label,
              "horizon": 0.05} for label in labels]
    baseline = {"suite": suite, "perturbations": ROUNDOFF_ONLY, "results": {}}
    skipped: dict = {}
    specs = suite_specs(baseline, skipped=skipped)
    entries = {i: e for i, e in suite_entries(baseline).items() if i in specs}
    results = measure_baseline(entries, specs, ROUNDOFF_ONLY)["results"]
    available = {a.engine for a in all_availability() if a.available}
    assert {r["engine"].split("[")[0] for r in results.values()} == available
    assert len(skipped) == len(suite) - len(available)
    written = updated_baseline(baseline, results, skipped)
    assert compare(written, results, skipped).regressions == []
    for ident, result in results.items():
        assert written["results"][ident]["engine_version"] == result["engine_version"] != ""
    ident = next(iter(results))
    moved = copy.deepcopy(results)
    moved[ident]["metrics"]["stiction_displacement"] = 1.0   # 1 m on a 0.2 m box: far outside
    written["results"][ident]["engine_version"] = "older"
    lines = compare(written, moved, skipped).regressions
    assert len(lines) == 1 and lines[0].startswith(f"{ident}: stiction_displacement ")
    assert " -> 1 (" in lines[0]
    assert lines[0].endswith(f"[engine version changed: older -> "
                             f"{results[ident]['engine_version']}]")


def test_an_update_of_one_engine_keeps_the_versions_of_the_engines_it_did_not_measure():
    """`regress --update -e NAME` keeps the other engines' results: their versions stay in
    ``recorded.engines`` beside the measured engine's (they were dropped once)."""
    suite = [{"id": "a", "scene": "pendulum", "engine": "mujoco[tuned]"},
             {"id": "b", "scene": "pendulum", "engine": "reference"}]
    baseline = {"suite": suite, "perturbations": ROUNDOFF_ONLY,
                "results": {"a": {"status": "ok"}, "b": {"status": "ok"}},
                "recorded": {"engines": {"mujoco": "mujoco 1.0", "reference": "built in"}}}
    fresh = {"b": {"status": "ok", "engine": "reference[default]", "engine_version": "new",
                   "scene_hash": "h", "expectations_passed": True, "metrics": {},
                   "checks": {}}}
    written = updated_baseline(baseline, fresh, {"a": "not chosen"})
    assert written["recorded"]["engines"] == {"mujoco": "mujoco 1.0", "reference": "new"}
    assert written["results"]["a"] == {"status": "ok"}
