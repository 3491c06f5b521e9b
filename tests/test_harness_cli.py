"""The harness sub-commands: help, input errors before any run, run and sweep end to end."""

from __future__ import annotations

import pytest

from clearbench.harness.cli.main import build_parser, main
from clearbench.harness.run.engine_choice import RunInputError
from clearbench.harness.run.store import ResultsStore
from clearbench.harness.studies.sweep import LadderStep, parse_ladder

from .harness_helpers import FAKE_OPTION, write_probe

COMMANDS = ("run", "sweep", "stability", "compare", "report", "regress")


@pytest.mark.parametrize("command", COMMANDS)
def test_every_command_has_help(command, capsys):
    with pytest.raises(SystemExit) as exit_:
        build_parser().parse_args([command, "--help"])
    assert exit_.value.code == 0
    assert "usage: clearbench " + command in capsys.readouterr().out


def test_ladder():
    assert parse_ladder("1x, 0.5x,1e-4") == (LadderStep(1.0, True), LadderStep(0.5, True),
                                             LadderStep(1e-4, False))
    for bad in ("", "0", "-1e-3", "fast", "nanx"):
        with pytest.raises(RunInputError):
            parse_ladder(bad)


@pytest.mark.parametrize("arguments, message", [
    (["run", "nope", "-e", "fake"], "scene = 'nope'"),
    (["run", "pendulum", "-e", "fake", "--dt", "0"], "time_step = 0.0"),
    (["run", "pendulum", "-e", "fake[x]"], "engine preset = 'x'"),
    (["run", "pendulum", "-e", "warp"], "engine = 'warp'"),
    (["run", "pendulum", "-e", "fake", "--set", "length"], "--set = 'length'"),
    (["sweep", "pendulum", "-e", "fake", "--dt", "1x,-2"], "--dt = '-2'"),
    (["sweep", "-e", "fake"], "no scene given"),
    (["stability", "-e", "fake[nope]"], "preset = 'nope'"),
])
def test_bad_input_exits_2_naming_the_field_and_runs_nothing(arguments, message, tmp_path,
                                                             capsys):
    store = tmp_path / "store"
    assert main(arguments + FAKE_OPTION + ["--store", str(store)]) == 2
    assert message in capsys.readouterr().err
    assert not (store / "runs.sqlite").exists() or len(ResultsStore(store)) == 0


def test_run_stores_and_prints_then_reuses(tmp_path, capsys):
    store = str(tmp_path / "store")
    out = tmp_path / "traj.npz"
    arguments = ["run", "torque-free-flip", "-e", "fake", "--horizon", "0.2", "--store", store,
                 "--out", str(out), *FAKE_OPTION]
    assert main(arguments) == 0
    text = capsys.readouterr().out
    # The verdict of a finished run is one of the three that status ok allows.
    assert any(f"verdict: {v}" in text for v in ("✓ pass", "✗ physics failed", "○ no check"))
    assert "run key:" in text and out.exists()
    assert main(arguments) == 0
    assert "from the store" in capsys.readouterr().out
    assert main(["run", "torque-free-flip", "-e", "fake[raise]", "--horizon", "0.2",
                 "--store", store, *FAKE_OPTION]) == 1
    assert "crashed — RuntimeError: fake engine failure" in capsys.readouterr().out


def test_sweep_prints_points_per_engine(tmp_path, capsys):
    scene = write_probe(tmp_path)
    store = str(tmp_path / "store")
    assert main(["sweep", str(scene), "-e", "fake", "fake[nan]", "--dt", "1x,0.5x",
                 "--reference-engine", "fake", "--store", store, *FAKE_OPTION]) == 0
    out = capsys.readouterr().out
    assert "5 runs done" in out  # 2 engines x 2 steps + 1 fine reference
    assert "fake[default] (fine ref)" in out and "diverged" in out


def test_error_against_the_fine_reference_falls_with_the_step(tmp_path):
    scene = write_probe(tmp_path)
    store_dir = tmp_path / "store"
    assert main(["sweep", str(scene), "-e", "fake", "--dt", "1x,0.5x,0.25x",
                 "--reference-engine", "fake", "--store", str(store_dir), *FAKE_OPTION]) == 0
    frame = ResultsStore(store_dir).dataframe()
    runs = frame[frame["campaign"] == "sweep"].sort_values("time_step")
    errors = runs["error"].to_numpy()
    # Symplectic Euler is first order: halving dt roughly halves the error (1.3 to 3 allows
    # for the fine reference's own O(dt/16) error).
    assert all(1.3 < errors[i + 1] / errors[i] < 3.0 for i in range(len(errors) - 1))


def test_compare_runs_and_writes_the_report(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["compare", "-e", "fake", "--scenes", "torque-free-flip", "pendulum",
                 "--dt", "1x", "--store", str(tmp_path / "store"), "--out", str(out),
                 *FAKE_OPTION]) == 0
    text = capsys.readouterr().out
    assert "2 runs done" in text and "report:" in text
    assert (out / "report.html").exists() and (out / "summary.md").exists()


def test_stability_runs_every_stiff_case(tmp_path, capsys):
    from clearbench.scenarios.library import scene_names

    assert main(["stability", "-e", "fake", "--store", str(tmp_path / "store"),
                 *FAKE_OPTION]) == 0
    text = capsys.readouterr().out
    for name in scene_names("stiff"):
        assert name in text
    assert "unsupported" in text  # the fake engine has no clearance joints


def test_stability_includes_pybullet_and_exudyn_by_default():
    """Issues 14 and 15: without -e, the stiff suite runs every available engine, the two
    compliant engines of the dependencies included (both are installed here)."""
    from clearbench.harness.studies.stability import available_engines, plan_stability

    labels = {choice.label for choice in available_engines()}
    assert {"pybullet[default]", "exudyn[default]"} <= labels
    planned = {spec.engine.label
               for spec in plan_stability(available_engines(), ["stiff-spring"])}
    assert {"pybullet[default]", "exudyn[default]"} <= planned


@pytest.mark.slow
def test_demo_is_the_default_comparison(tmp_path, capsys):
    """The README's main job end to end on the engines available here (minutes)."""
    out = tmp_path / "out"
    assert main(["demo", "--store", str(tmp_path / "store"), "--out", str(out)]) == 0
    assert (out / "report.html").exists()
