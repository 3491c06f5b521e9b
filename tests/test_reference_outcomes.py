"""A failure inside the reference engine's step is a recorded outcome, not a crash of the caller."""

from __future__ import annotations

import numpy as np

from clearbench.adapters.base import RunSettings
from clearbench.adapters.reference.engine import create
from clearbench.adapters.trajectory import RunStatus
from clearbench.ref_solver import stepper
from clearbench.scenarios.library import get_scene


def test_an_exception_in_a_step_is_a_crashed_run_with_the_state_it_started_from(monkeypatch):
    # The Python step, whose step method is replaced below (bouncing-ball-e0.5 is compiled by
    # default since impact localisation is).
    scene = get_scene("bouncing-ball-e0.5")
    python = {"step_loop": "python"}
    clean = create().run(scene, RunSettings(horizon=5 * scene.time_step, options=python))
    original = stepper.MoreauJeanStepper.step
    calls = {"n": 0}

    def failing_step(self, state):
        calls["n"] += 1
        if calls["n"] == 5:  # the warm-up step, then steps 1, 2, 3: step 4 fails
            raise ZeroDivisionError("division by zero")
        return original(self, state)

    monkeypatch.setattr(stepper.MoreauJeanStepper, "step", failing_step)
    trajectory = create().run(scene, RunSettings(horizon=10 * scene.time_step, options=python))
    assert trajectory.status is RunStatus.CRASHED
    assert "ZeroDivisionError in step 4" in trajectory.message
    # Samples 0..3 and the start of step 4 (= the end of step 3, repeated): the failing step
    # can be replayed from the last sample. The steps before it are those of a clean run.
    assert trajectory.steps == 3
    np.testing.assert_array_equal(trajectory.positions[:4], clean.positions[:4])
    np.testing.assert_array_equal(trajectory.positions[-1], clean.positions[3])


def test_a_stiction_window_without_samples_gives_no_verdict_instead_of_an_error():
    # c60-on judges "stays latched" from 3 ms on; a 1 ms run has no sample there: the figures
    # are NaN (no verdict), where they used to raise IndexError.
    import math

    from clearbench.harness.measure import series as metrics

    scene = get_scene("bouncing-ball-e0.5")
    trajectory = create().run(scene, RunSettings(horizon=5 * scene.time_step))
    stick = metrics.stiction(scene, trajectory, "ball", start=1.0, end=2.0)
    assert math.isnan(stick.displacement) and math.isnan(stick.creep_rate)
