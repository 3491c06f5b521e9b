"""``clearbench mujoco-table`` in-process: prints the shared evaluator's figures; bad input
exits with status 2."""

from __future__ import annotations

from clearbench.harness.cli.main import main


def test_mujoco_table_prints_the_expectation_figures(capsys):
    status = main(["mujoco-table", "--scene", "pendulum", "--scene", "incline-stick",
                   "--preset", "tuned", "--dt", "1e-3", "--horizon", "0.2"])
    assert status == 0
    out = capsys.readouterr().out
    assert "**pendulum**" in out and "mujoco[tuned] dt=0.001" in out
    assert "energy drift / (m g d) [%]" in out
    assert "creep below the friction angle [um]" in out


def test_mujoco_table_compact_is_one_table(capsys):
    assert main(["mujoco-table", "--scene", "pendulum", "--preset", "default", "--dt", "1e-3",
                 "--horizon", "0.1", "--compact"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("| scene | figure | mujoco[default] dt=0.001 |")
    assert "| pendulum | period, relative error [%] |" in out


def test_mujoco_table_rejects_bad_input(capsys):
    assert main(["mujoco-table", "--preset", "fast"]) == 2
    assert "unknown preset" in capsys.readouterr().err
    assert main(["mujoco-table", "--scene", "nope"]) == 2
    assert main(["mujoco-table", "--dt", "-1"]) == 2
    assert main(["mujoco-table", "--no-mujoco"]) == 2
