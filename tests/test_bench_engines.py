"""``clearbench bench engines``: the contenders side by side with the ratio to the reference,
bad input refused with status 2 before any run (nothing is asserted about time)."""

from __future__ import annotations

import math

from clearbench.harness.cli.main import main


def test_bench_engines_prints_each_contender_and_its_ratio(capsys):
    status = main(["bench", "engines", "--engine", "mujoco[default]", "--scene", "pendulum",
                   "--steps", "3", "--python-loop"])
    assert status == 0
    out = capsys.readouterr().out
    rows = [line.split() for line in out.splitlines() if line.startswith("pendulum")]
    labels = [" ".join(row[1:-5]) for row in rows]
    assert labels == ["reference[default]", "reference[default] step_loop=python",
                      "mujoco[default]"]
    assert all(row[-5] == "3" and row[-1] == "ok" for row in rows)
    assert rows[0][-3] == "1"  # the reference's ratio to itself
    assert "it/step" in out
    assert "median" in out


def test_bench_engines_rejects_bad_input(capsys):
    assert main(["bench", "engines", "--scene", "nope"]) == 2
    assert "nope" in capsys.readouterr().err
    assert main(["bench", "engines", "--engine", "mujoco[fast]", "--scene", "pendulum"]) == 2
    assert main(["bench", "engines", "--steps", "0", "--scene", "pendulum"]) == 2


def test_bench_engines_takes_an_engine_without_preset(capsys):
    # "reference" is reference[default]: one contender, not two.
    assert main(["bench", "engines", "--engine", "reference", "--scene", "pendulum",
                 "--steps", "2"]) == 0
    rows = [line for line in capsys.readouterr().out.splitlines()
            if line.startswith("pendulum")]
    assert len(rows) == 1 and "reference[default]" in rows[0]


def test_a_hanging_or_crashing_contender_is_a_row_and_the_benchmark_goes_on():
    # Each run goes through the harness's isolated worker with a wall-clock limit: the fake
    # engine's "hang" preset never returns and "segfault" kills its process. Both are rows with
    # their status; the contender after them still runs in a fresh worker. The limit counts
    # the worker's start-up (spawn, imports) with the fake run (milliseconds): 3 s was passed
    # by the first contender's start-up on 2 cores at load 5 (a campaign beside the tests);
    # 10 s is far above that and far below a real hang (the "hang" preset never returns).
    from clearbench.harness.studies.benchmarks.engine_costs import Contender, measure

    contenders = [Contender("fake", preset) for preset in ("default", "hang", "segfault",
                                                           "default")]
    costs = measure(["torque-free-flip"], contenders, steps=4, timeout=10.0,
                    extra_engine_modules={"fake": "tests.fake_engine"})
    assert [c.status for c in costs] == ["ok", "timed_out", "crashed", "ok"]
    # no measured run after a warm-up that hung: no cost
    assert costs[1].message.startswith("warm-up:") and math.isnan(costs[1].seconds_per_step)
    assert costs[3].steps == 4 and costs[3].seconds_per_step > 0


def test_iterations_per_step_are_the_runs_total_over_its_steps():
    # The bench's iterations per step are the run's own: the same deterministic reference run
    # made directly gives the same total (its samples' sum) over the same steps. A mean over
    # the 10 recorded samples alone would be about 10 times too large (each sample adds up the
    # steps since the one before). Exact equality: the same code on the same input.
    import importlib

    import numpy as np

    from clearbench.adapters import ENGINES
    from clearbench.adapters.base import RunSettings
    from clearbench.harness.studies.benchmarks.engine_costs import Contender, measure
    from clearbench.scenarios.library import get_scene

    steps = 40
    [cost] = measure(["sliding-box"], [Contender("reference", "default")], steps=steps)
    scene = get_scene("sliding-box")
    trajectory = importlib.import_module(ENGINES["reference"]).create().run(
        scene, RunSettings(horizon=steps * scene.time_step, record_every=steps // 10))
    assert cost.steps == steps
    assert cost.iterations_per_step == np.sum(trajectory.solver_iterations) / steps > 0


def test_bench_engines_against_refuses_the_contenders_options(capsys):
    assert main(["bench", "engines", "--against", "HEAD", "--python-loop",
                 "--scene", "pendulum"]) == 2
    assert "--python-loop" in capsys.readouterr().err


def test_the_iterations_figure_is_per_step_whatever_the_recording():
    # The run figure solver_iterations_per_step is the run's total over its steps: the same
    # deterministic reference run recorded every step and every 10 steps gives the same figure
    # (the samples' sums are the same total), where a mean over recorded samples would differ
    # tenfold. Equality to round-off of a division (the same integers summed).
    import importlib

    import pytest

    from clearbench.adapters import ENGINES
    from clearbench.adapters.base import RunSettings
    from clearbench.harness.measure.figures import measure
    from clearbench.scenarios.library import get_scene

    scene = get_scene("sliding-box")
    engine = importlib.import_module(ENGINES["reference"]).create()
    figures = []
    for record_every in (1, 10):
        trajectory = engine.run(scene, RunSettings(horizon=40 * scene.time_step,
                                                   record_every=record_every))
        figures.append(measure(scene, trajectory).figures["solver_iterations_per_step"])
        assert figures[-1] == pytest.approx(trajectory.iterations_per_step, rel=1e-15)
    assert figures[0] > 0
    assert figures[1] == pytest.approx(figures[0], rel=1e-15)
