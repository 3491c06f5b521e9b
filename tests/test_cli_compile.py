"""``clearbench compile``: the numba kernels of both step loops compiled by two-step runs in
parallel workers; bad input refused with status 2 before any run."""

from __future__ import annotations

from clearbench.harness.cli.main import main
from clearbench.harness.run.numba_cache import STEP_LOOPS, WARM_UP_TIMEOUT, reference_specs


def test_compile_runs_each_step_loop_of_each_scene(capsys):
    assert main(["compile", "--scenes", "pendulum", "--jobs", "1"]) == 0
    out = capsys.readouterr().out
    assert f"{len(STEP_LOOPS)} of {len(STEP_LOOPS)} runs ok" in out


def test_the_specs_are_two_step_reference_runs_of_each_loop_interleaved_by_scene():
    specs = reference_specs(["pendulum", "bouncing-ball-e0"])
    assert [(s.scene.name, dict(s.options)["step_loop"]) for s in specs] == [
        ("pendulum", "auto"), ("pendulum", "python"),
        ("bouncing-ball-e0", "auto"), ("bouncing-ball-e0", "python")]
    for spec in specs:
        assert spec.engine.name == "reference"
        assert spec.horizon == 2 * spec.time_step   # two steps compile every kernel of a step
        assert spec.timeout == WARM_UP_TIMEOUT


def test_compile_refuses_bad_input(capsys):
    assert main(["compile", "--jobs", "0"]) == 2
    assert "--jobs 0" in capsys.readouterr().err
    assert main(["compile", "--scenes", "nope"]) == 2
    assert "nope" in capsys.readouterr().err
