"""Regression check: baseline update, a clean pass, and injected regressions detected."""

from __future__ import annotations

import json

from clearbench.harness.cli.main import main
from clearbench.harness.studies.regress import Tolerance, compare

from .harness_helpers import FAKE_OPTION, needs_metrics

SUITE = [
    {"id": "flip", "scene": "torque-free-flip", "engine": "fake", "horizon": 0.2},
    {"id": "ball", "scene": "bouncing-ball-e0.5", "engine": "fake", "horizon": 0.2,
     "time_step": 2e-3},
]
TOLERANCES = {"default": {"abs": 1e-12, "rel": 1e-9,
                          "why": "the fake engine is deterministic to round-off"}}


def _baseline(tmp_path):
    path = tmp_path / "baseline.json"
    path.write_text(json.dumps({"description": "test", "suite": SUITE,
                                "tolerances": TOLERANCES, "results": {}}))
    return path


def test_compare_names_each_regression():
    baseline = {"tolerances": {"default": {"abs": 0.0, "rel": 1e-6},
                               "loose": {"abs": 1.0, "rel": 0.0}},
                "results": {"a": {"status": "ok", "expectations_passed": 1,
                                  "metrics": {"x": 1.0, "loose": 5.0, "gone": 2.0}},
                            "b": {"status": "ok", "expectations_passed": 1, "metrics": {}}}}
    results = {"a": {"status": "ok", "expectations_passed": 1, "message": "",
                     "metrics": {"x": 1.0 + 1e-5, "loose": 5.9, "new": 1.0}},
               "b": {"status": "diverged", "expectations_passed": 0, "message": "boom",
                     "metrics": {}}}
    outcome = compare(baseline, results)
    text = "\n".join(outcome.regressions)
    assert "a: x 1 -> 1.00001" in text            # 1e-5 relative > 1e-6 relative
    assert "loose" not in text                    # 0.9 within its absolute tolerance of 1
    assert "a: gone no longer computed" in text
    assert "b: status ok -> diverged (boom)" in text
    assert "b: expectations passed 1 -> 0" in text
    assert len(outcome.regressions) == 4
    assert any("new" in note for note in outcome.notes)


def test_tolerance():
    tolerance = Tolerance(1e-9, 1e-6)
    assert tolerance.allows(1.0, 1.0 + 1e-6)
    assert not tolerance.allows(1.0, 1.0 + 2e-6)
    assert tolerance.allows(0.0, 1e-9) and not tolerance.allows(0.0, 2e-9)
    assert tolerance.allows(float("nan"), float("nan"))
    assert not tolerance.allows(1.0, float("nan"))


def test_regress_update_pass_and_injected_regression(tmp_path, capsys, monkeypatch):
    path = _baseline(tmp_path)
    arguments = ["regress", "--baseline", str(path), *FAKE_OPTION]
    assert main(arguments) == 1  # no baseline results yet
    assert "no baseline result" in capsys.readouterr().out
    assert main(arguments + ["--update"]) == 0
    written = json.loads(path.read_text())
    assert set(written["results"]) == {"flip", "ball"}
    assert written["tolerances"] == TOLERANCES and written["suite"] == SUITE
    assert "revision" in written["recorded"]
    capsys.readouterr()
    assert main(arguments) == 0
    assert "no regression" in capsys.readouterr().out
    monkeypatch.setenv("CLEARBENCH_FAKE_NAN", "1")  # the workers inherit it: engine now NaNs
    assert main(arguments) == 1
    out = capsys.readouterr().out
    assert "flip: status ok -> diverged" in out and "ball: status ok -> diverged" in out


@needs_metrics
def test_regress_detects_a_metric_outside_its_tolerance(tmp_path, capsys, monkeypatch):
    path = _baseline(tmp_path)
    arguments = ["regress", "--baseline", str(path), *FAKE_OPTION]
    assert main(arguments + ["--update"]) == 0
    monkeypatch.setenv("CLEARBENCH_FAKE_BIAS", "1e-2")  # heights drift up 1 cm/s: 2 mm in 0.2 s
    capsys.readouterr()
    assert main(arguments) == 1
    out = capsys.readouterr().out
    # The potential energy m g z moves by m g 2 mm = 0.02 J: far outside 1e-9 relative.
    assert "ball: energy_drift" in out and "status" not in out


def test_regress_rejects_a_bad_suite(tmp_path, capsys):
    path = tmp_path / "bad.json"
    path.write_text(json.dumps({"suite": [{"id": "x", "scene": "nope", "engine": "fake"}],
                                "tolerances": {}}))
    assert main(["regress", "--baseline", str(path), *FAKE_OPTION]) == 2
    assert "suite entry 'x'" in capsys.readouterr().err


def test_compare_uses_each_engines_tolerances_and_says_whether_its_version_changed():
    baseline = {"tolerances": {"reference": {"default": {"abs": 0.0, "rel": 1e-6}},
                               "mujoco": {"default": {"abs": 0.0, "rel": 1e-2}}},
                "results": {
                    "reference pendulum": {"status": "ok", "expectations_passed": 1,
                                           "engine_version": "clearbench 0.1.0",
                                           "metrics": {"x": 1.0}},
                    "mujoco[tuned] pendulum": {"status": "ok", "expectations_passed": 1,
                                               "engine_version": "mujoco 4.0.0",
                                               "metrics": {"x": 1.0, "y": 1.0}},
                    "pybullet[tuned] pendulum": {"status": "ok", "metrics": {}}}}
    results = {"reference pendulum": {"status": "ok", "expectations_passed": 1, "message": "",
                                      "engine": "reference[default]",
                                      "engine_version": "clearbench 0.1.0",
                                      "metrics": {"x": 1.0 + 1e-5}},
               "mujoco[tuned] pendulum": {"status": "ok", "expectations_passed": 1,
                                          "message": "", "engine": "mujoco[tuned]",
                                          "engine_version": "mujoco 4.1.0",
                                          "metrics": {"x": 1.0 + 1e-3, "y": 1.5}}}
    outcome = compare(baseline, results, {"pybullet[tuned] pendulum": "pybullet not available"})
    # 1e-5 relative: outside the reference's 1e-6, inside MuJoCo's 1e-2 (x); y moved 50 %.
    assert outcome.regressions == [
        "reference pendulum: x 1 -> 1.00001 (tolerance 0 + 1e-06 x |base|) "
        "[engine clearbench 0.1.0 unchanged]",
        "mujoco[tuned] pendulum: y 1 -> 1.5 (tolerance 0 + 0.01 x |base|) "
        "[engine version changed: mujoco 4.0.0 -> mujoco 4.1.0]"]
    assert "pybullet[tuned] pendulum: not run (pybullet not available)" in outcome.notes


def test_regress_covers_one_quick_scene_per_available_engine(tmp_path):
    """Every available engine on a quick scene: the baseline written from a run passes, and a
    moved figure is a regression naming the engine, the scene, the figure and the version."""
    import copy

    from clearbench.adapters import all_availability
    from clearbench.harness.studies.regress import (
        DEFAULT_TOLERANCES,
        ENGINE_PRESETS,
        run_suite,
        suite_specs,
        updated_baseline,
    )

    suite = [{"id": f"{name}[{ENGINE_PRESETS.get(name, 'default')}] incline-stick",
              "scene": "incline-stick", "engine": f"{name}[{ENGINE_PRESETS.get(name, 'default')}]",
              "horizon": 0.05} for name in ENGINE_PRESETS | {"reference": "default"}]
    baseline = {"suite": suite, "tolerances": DEFAULT_TOLERANCES, "results": {}}
    skipped: dict = {}
    results = run_suite(suite_specs(baseline, skipped=skipped))
    available = {a.engine for a in all_availability() if a.available}
    assert {r["engine"].split("[")[0] for r in results.values()} == available
    assert len(skipped) == len(suite) - len(available)
    written = updated_baseline(baseline, results, skipped)
    assert compare(written, results, skipped).regressions == []
    for ident, result in results.items():
        assert written["results"][ident]["engine_version"] == result["engine_version"] != ""
    ident = next(iter(results))
    moved = copy.deepcopy(written)
    moved["results"][ident]["metrics"]["penetration_max"] = 1.0   # 1 m: far outside
    moved["results"][ident]["engine_version"] = "older"
    lines = compare(moved, results, skipped).regressions
    assert len(lines) == 1 and lines[0].startswith(f"{ident}: penetration_max 1 -> ")
    assert lines[0].endswith(f"[engine version changed: older -> "
                             f"{results[ident]['engine_version']}]")


def test_a_run_that_timed_out_is_one_status_line_without_a_version():
    baseline = {"tolerances": {"default": {"abs": 0.0, "rel": 1e-6}},
                "results": {"siconos[default] pendulum": {
                    "status": "ok", "expectations_passed": 1, "engine_version": "siconos 4.4",
                    "metrics": {"x": 1.0, "y": 2.0}}}}
    results = {"siconos[default] pendulum": {
        "status": "timed_out", "expectations_passed": None, "engine": "siconos[default]",
        "engine_version": "", "message": "wall-clock limit of 300 s reached", "metrics": {}}}
    lines = compare(baseline, results).regressions
    assert lines == [
        "siconos[default] pendulum: status ok -> timed_out (wall-clock limit of 300 s reached) "
        "[engine siconos 4.4 in the baseline; this run reported no version]",
        "siconos[default] pendulum: expectations passed 1 -> None "
        "[engine siconos 4.4 in the baseline; this run reported no version]"]
