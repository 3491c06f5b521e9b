"""Readable command output: a progress line per finished run when stdout is not a terminal,
and every figure of ``clearbench run`` printed with its own unit (a ratio saying what it is of)
instead of one "scene units" header over relative figures."""

from __future__ import annotations

import json
import re
from types import SimpleNamespace

from clearbench.harness.cli.common import progress_line
from clearbench.harness.cli.main import main
from clearbench.harness.cli.run import print_summary
from clearbench.harness.measure.units import figure_unit
from clearbench.harness.run.spec import make_run_spec
from clearbench.scenarios.library import get_scene
from clearbench.scenarios.units import MM_G_MS

from .harness_helpers import FAKE_OPTION, ROOT, write_probe


def test_progress_line_names_the_run_its_verdict_and_its_time():
    spec = make_run_spec("pendulum", "reference", time_step=1e-3)
    record = SimpleNamespace(status="ok", expectations_passed=1, worker_seconds=1.23)
    assert progress_line(37, 135, spec, record) == \
        "[37/135] reference[default] pendulum dt=1 ms ✓ pass 1.23 s"
    failed = SimpleNamespace(status="ok", expectations_passed=0, worker_seconds=0.5)
    assert progress_line(1, 2, spec, failed).endswith("dt=1 ms ✗ physics failed 0.5 s")


def test_a_sweep_prints_a_line_per_finished_run_when_stdout_is_not_a_terminal(tmp_path,
                                                                               capsys):
    probe = write_probe(tmp_path, horizon=0.2)
    argv = ["sweep", str(probe), "-e", "fake", "--dt", "1x,0.5x", "--reference-engine",
            "none", "--jobs", "1", *FAKE_OPTION]
    assert main([*argv, "--store", str(tmp_path / "a")]) == 0
    out = capsys.readouterr().out  # captured: not a terminal
    lines = re.findall(r"^\[(\d)/(\d)\] fake\[default\] probe dt=(\S+ ms) (\S+) .* \S+ s$",
                       out, flags=re.MULTILINE)
    # Two runs (the probe's 10 ms step and half of it), numbered in the order they finish.
    assert sorted((done, total) for done, total, _, _ in lines) == [("1", "2"), ("2", "2")], out
    assert sorted(step for _, _, step, _ in lines) == ["10 ms", "5 ms"]
    assert main([*argv, "--store", str(tmp_path / "b"), "--no-progress"]) == 0
    assert not re.search(r"^\[\d/\d\]", capsys.readouterr().out, flags=re.MULTILINE)


def _row(metrics: dict, expectations: list) -> dict:
    return {"scene_name": "clearance-pendulum", "engine": "mujoco", "preset": "tuned",
            "time_step": 0.1, "horizon": 10.0, "status": "ok", "expectations_passed": 1,
            "message": "", "engine_status": "ok", "engine_message": "",
            "engine_version": "mujoco 4", "worker_seconds": 1.0, "build_seconds": 0.1,
            "stepping_seconds": 0.5, "steps": 100, "stepping_seconds_per_step": 5e-3,
            "stepping_seconds_per_simulated_second": 0.05, "metrics": json.dumps(metrics),
            "error_source": "", "expectations": json.dumps(expectations), "metrics_error": "",
            "trajectory": "", "key": "k"}


def test_run_prints_each_figure_with_its_unit(capsys):
    scene = get_scene("clearance-pendulum").rescaled(MM_G_MS)
    metrics = {"penetration_max": 0.01, "clearance_excess_relative": 0.5,
               "energy_growth": 1e-3, "energy_scale": 98.1, "stiction_creep_rate": 1e-4,
               "ideal_limit.clearance_excess": 0.05, "made_up_figure": 1.0}
    print_summary(_row(metrics, [{"name": "ideal_limit", "kind": "approaches_ideal",
                                  "passed": True}]), scene=scene)
    out = capsys.readouterr().out
    assert "scene units" not in out  # no one header claiming a unit for ratios
    for name, unit in (("penetration_max", "mm"), ("clearance_excess_relative",
                                                     "of the radial clearance"),
                       ("energy_growth", "of energy_scale"), ("energy_scale", "N*mm"),
                       ("stiction_creep_rate", "mm/ms"), ("ideal_limit.clearance_excess", "mm"),
                       ("made_up_figure", "(unit not stated)")):
        assert re.search(rf"^\s+{re.escape(name)}\s+\S+ {re.escape(unit)}$", out,
                         flags=re.MULTILINE), (name, out)


def test_every_figure_of_the_quick_suite_has_a_unit():
    """Every figure the committed quick baseline holds, in its scene, has a stated unit."""
    baseline = json.loads((ROOT / "reports" / "baselines" / "quick.json").read_text())
    missing = set()
    for run, result in baseline["results"].items():  # "[ENGINE[PRESET] ]SCENE" -> result
        scene = get_scene(run.split()[-1])
        for name in result.get("metrics", {}):
            if figure_unit(name, scene) is None:
                missing.add((run, name))
    assert not missing
