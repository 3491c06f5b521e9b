"""The compiled time loop (ref_solver/compiled) against the Python step, its oracle.

Both paths call the same kernels; they differ in the order of a few sums (numpy's BLAS
products against numba's loops, Newton's dense kernel above the sparse driver's 100 rows) and
so by round-off, which the one-step contact solve (stopping at a relative residual of 1e-12)
can carry into its iterate. Over the first ``STEPS`` steps the two trajectories must agree
within ``AGREEMENT`` of the scene's length scale L (positions) and velocity scale V
(velocities; angular velocities times L): 1e-9 allows the solver's 1e-12 stopping tolerance
(the relative size of the difference between two iterates that both meet it) to grow by a
factor 1000 over the steps, and is still a million times below any figure the harness
reports (they resolve 1e-3 of a length).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from clearbench.adapters.base import RunSettings
from clearbench.adapters.options import OptionError
from clearbench.adapters.reference.build import build
from clearbench.adapters.reference.engine import create
from clearbench.adapters.reference.run import choose_step_loop
from clearbench.scenarios.library import get_scene, scene_names
from clearbench.scenarios.scales import scene_size

STEPS = 20
AGREEMENT = 1e-9


def _velocity_scale(scene, length: float) -> float:
    """V [L/T]: the largest of sqrt(|g| L), the initial speeds and the initial angular speeds
    times L."""
    g = float(np.linalg.norm(scene.gravity))
    speeds = [math.sqrt(g * length)]
    for body in scene.bodies:
        speeds.append(float(np.linalg.norm(body.velocity)))
        speeds.append(float(np.linalg.norm(body.angular_velocity)) * length)
    return max(speeds) if max(speeds) > 0.0 else 1.0


def _supported(scene) -> bool:
    engine = create("default")
    settings = RunSettings()
    model = build(scene, engine.run_settings(scene, settings))
    return choose_step_loop("auto", model.stepper).compiled


def _compare(name: str) -> None:
    scene = get_scene(name)
    h = scene.time_step
    runs = {loop: create("default").run(scene, RunSettings(horizon=STEPS * h,
                                                           options={"step_loop": loop}))
            for loop in ("python", "compiled")}
    python, compiled = runs["python"], runs["compiled"]
    assert python.metadata["step_loop"] == "python"
    assert compiled.metadata["step_loop"] == "compiled"
    assert compiled.status == python.status
    assert compiled.steps == python.steps
    length = scene_size(scene)
    speed = _velocity_scale(scene, length)
    np.testing.assert_array_equal(compiled.times, python.times)
    assert np.max(np.abs(compiled.positions - python.positions)) <= AGREEMENT * length
    assert np.max(np.abs(compiled.orientations - python.orientations)) <= AGREEMENT
    assert np.max(np.abs(compiled.velocities - python.velocities)) <= AGREEMENT * speed
    assert np.max(np.abs(compiled.angular_velocities - python.angular_velocities)) \
        <= AGREEMENT * speed / length
    # Contact forces: relative to the largest force of the run (the same solver tolerance).
    force = max(float(np.max(np.abs(python.contact_force), initial=0.0)), 1e-300)
    assert np.max(np.abs(compiled.contact_force - python.contact_force), initial=0.0) \
        <= AGREEMENT * force
    np.testing.assert_array_equal(compiled.active_contacts, python.active_contacts)
    assert compiled.unconverged_steps == python.unconverged_steps


@pytest.mark.parametrize("name", scene_names())
def test_compiled_loop_agrees_with_python_step_on_every_supported_scene(name):
    # The whole library takes about 10 s (20 steps each, numba's cache warm).
    scene = get_scene(name)
    if not _supported(scene):
        pytest.skip("the compiled loop does not support this scene (see test_fallback)")
    _compare(name)


def test_unsupported_scene_falls_back_with_its_reason():
    # bouncing-ball-e0.5: restitution 0.5 with the default preset's impact localisation.
    scene = get_scene("bouncing-ball-e0.5")
    run = create("default").run(scene, RunSettings(horizon=5 * scene.time_step))
    assert run.metadata["step_loop"] == "python"
    assert "impact localisation" in run.metadata["step_loop_fallback"]
    with pytest.raises(OptionError, match="step_loop"):
        create("default").run(scene, RunSettings(horizon=5 * scene.time_step,
                                                 options={"step_loop": "compiled"}))
    # Without localisation the same scene is compiled.
    run = create("default").run(scene, RunSettings(horizon=5 * scene.time_step,
                                                   options={"localise_impacts": False}))
    assert run.metadata["step_loop"] == "compiled"
    assert run.metadata["step_loop_fallback"] == ""


def test_auto_is_the_default_and_python_can_be_forced():
    scene = get_scene("pendulum")
    run = create("default").run(scene, RunSettings(horizon=3 * scene.time_step))
    assert run.metadata["step_loop"] == "compiled"
    run = create("default").run(scene, RunSettings(horizon=3 * scene.time_step,
                                                   options={"step_loop": "python"}))
    assert run.metadata["step_loop"] == "python"
    assert run.metadata["step_loop_fallback"] == "step_loop = python"
