"""``clearbench bench`` in-process: the list of benchmarks; ``bench physics-table`` and
``mujoco-table`` print the shared evaluator's figures; bad input exits with status 2."""

from __future__ import annotations

import pytest

from clearbench.harness.cli.bench import BENCHMARKS
from clearbench.harness.cli.main import main


def test_mujoco_table_prints_the_expectation_figures(capsys):
    status = main(["bench", "mujoco-table", "--scene", "pendulum", "--scene", "incline-stick",
                   "--preset", "tuned", "--dt", "1e-3", "--horizon", "0.2"])
    assert status == 0
    out = capsys.readouterr().out
    assert "**pendulum**" in out and "mujoco[tuned] dt=0.001" in out
    assert "energy drift / (m g d) [%]" in out
    assert "creep below the friction angle [um]" in out


def test_mujoco_table_compact_is_one_table(capsys):
    assert main(["bench", "mujoco-table", "--scene", "pendulum", "--preset", "default",
                 "--dt", "1e-3", "--horizon", "0.1", "--compact"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("| scene | figure | mujoco[default] dt=0.001 |")
    assert "| pendulum | period, relative error [%] |" in out


def test_mujoco_table_rejects_bad_input(capsys):
    assert main(["bench", "mujoco-table", "--preset", "fast"]) == 2
    assert "unknown mujoco preset 'fast'" in capsys.readouterr().err
    assert main(["bench", "mujoco-table", "--scene", "nope"]) == 2
    assert main(["bench", "mujoco-table", "--dt", "-1"]) == 2
    assert main(["bench", "mujoco-table", "--no-mujoco"]) == 2


def test_bench_lists_every_benchmark_without_a_name_or_with_list(capsys):
    assert main(["bench"]) == 0
    listed = capsys.readouterr().out
    assert main(["bench", "--list", "reference"]) == 0  # --list wins over a name
    assert capsys.readouterr().out == listed
    names = [line.split()[0] for line in listed.splitlines()]
    assert names == list(BENCHMARKS)
    assert {"physics-table", "mujoco-table", "impact-localisation", "scale-invariance",
            "fc3d-sweep", "newton-first", "geometry"} <= set(names)


def test_bench_rejects_an_unknown_benchmark():
    with pytest.raises(SystemExit) as exit_info:
        main(["bench", "nope"])
    assert exit_info.value.code == 2


def test_physics_table_runs_any_engine_and_preset(capsys):
    status = main(["bench", "physics-table", "-e", "pybullet[tuned]", "--scene", "pendulum",
                   "--dt", "1e-3", "--horizon", "0.1", "--compact"])
    assert status == 0
    out = capsys.readouterr().out
    assert out.startswith("| scene | figure | pybullet[tuned] dt=0.001 |")
    assert "| pendulum | energy drift / (m g d) [%] |" in out
    assert "build time" not in out  # PyBullet's import banner stays out of the table


def test_physics_table_rejects_bad_engines_before_running(capsys):
    assert main(["bench", "physics-table"]) == 2
    assert "give --engine" in capsys.readouterr().err
    assert main(["bench", "physics-table", "-e", "nope"]) == 2
    assert "unknown engine" in capsys.readouterr().err
    assert main(["bench", "physics-table", "-e", "pybullet[fast]"]) == 2
    assert "'fast'" in capsys.readouterr().err
    assert main(["bench", "physics-table", "-e", "mujoco", "--horizon", "0"]) == 2


def test_table_options_are_checked_before_any_run(capsys):
    assert main(["bench", "physics-table", "-e", "pybullet[tuned]", "--option", "nope=1"]) == 2
    assert "pybullet option nope = 1: unknown pybullet option" in capsys.readouterr().err
    assert main(["bench", "contact-cost", "-e", "pybullet[tuned]", "--option",
                 "num_solver_iterations=0"]) == 2
    assert "pybullet option num_solver_iterations = 0: must be an integer >= 1" in \
        capsys.readouterr().err


def test_contact_cost_prints_a_row_per_box_count(capsys):
    assert main(["bench", "contact-cost", "-e", "pybullet[tuned]", "--boxes", "1",
                 "--boxes", "4", "--dt", "1e-3", "--horizon", "0.005"]) == 0
    out = capsys.readouterr().out
    assert "| pybullet[tuned] | 1 (4) |" in out and "| pybullet[tuned] | 4 (16) |" in out
