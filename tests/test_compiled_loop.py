"""The compiled time loop (ref_solver/compiled) against the Python loop (ref_solver/python_loop),
its oracle.

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

import dataclasses
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


def _compare(name: str, options: dict | None = None, horizon: float | None = None):
    """Runs ``name`` in both loops (``horizon`` [T], default ``STEPS`` steps) and asserts their
    agreement (module docstring); returns the (Python, compiled) runs."""
    scene = get_scene(name)
    h = scene.time_step
    runs = {loop: create("default").run(scene, RunSettings(
                horizon=STEPS * h if horizon is None else horizon,
                options={**(options or {}), "step_loop": loop}))
            for loop in ("python", "compiled")}
    python, compiled = runs["python"], runs["compiled"]
    assert python.metadata["step_loop"] == "python"
    assert compiled.metadata["step_loop"] == "compiled"
    assert compiled.status == python.status
    assert compiled.steps == python.steps
    length = scene_size(scene)
    speed = _velocity_scale(scene, length)
    np.testing.assert_array_equal(compiled.times, python.times)
    # A step whose projection or contact problem did not converge ends wherever its iteration
    # stopped: past it the two paths are fixed by round-off only to the unmet tolerance (on
    # stiff-tight-clearance, 1e-14 m apart before, 1e-7 m ten steps after). Both must meet the
    # same first such step, and agree within AGREEMENT on every state before it.
    first = _first_unconverged(python)
    assert _first_unconverged(compiled) == first
    python, compiled = _before(python, first), _before(compiled, first)
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
    return runs["python"], runs["compiled"]


def _first_unconverged(trajectory) -> int:
    """The first step [count] whose projection or contact problem did not converge (a step
    past the run's end when every one did)."""
    steps = [*trajectory.metadata.get("unconverged_projections", []),
             *trajectory.unconverged_steps]
    return min(steps, default=trajectory.steps + 1)


def _before(trajectory, step: int):
    """The trajectory's states recorded before ``step`` (their index is their step count)."""
    keep = slice(0, min(step, len(trajectory.times)))
    return dataclasses.replace(
        trajectory, times=trajectory.times[keep], positions=trajectory.positions[keep],
        orientations=trajectory.orientations[keep], velocities=trajectory.velocities[keep],
        angular_velocities=trajectory.angular_velocities[keep],
        contact_force=trajectory.contact_force[keep],
        active_contacts=trajectory.active_contacts[keep])


@pytest.mark.parametrize("name", scene_names())
def test_compiled_loop_agrees_with_python_step_on_every_supported_scene(name, request):
    if name == "stiff-tight-clearance":
        # Measured with the face-solid kernel (kernels/gaps/face_solids.py): positions agree to
        # 2e-14 m up to the first unconverged projection (step 4 on both paths), but the
        # contact forces split between the nearly redundant flange contacts differently by
        # 1.3e-6 of the largest force before it (ddb0acf's kernel: within 1e-9). Open: run, not
        # strict, so the day it agrees again shows.
        request.applymarker(pytest.mark.xfail(
            reason="contact-force split on near-redundant flange contacts", strict=False))
    # The whole library takes about 10 s (20 steps each, numba's cache warm).
    scene = get_scene(name)
    if not _supported(scene):
        pytest.skip("the compiled loop does not support this scene (see test_fallback)")
    _compare(name)


@pytest.mark.parametrize("rule", ["held", "predicted"])
@pytest.mark.parametrize("name", ["clearance-pendulum", "slider-crank", "box-grid", "c60-on"])
def test_both_loops_apply_the_other_activation_rules_alike(name, rule):
    # The first activation round's rules other than the default (ref_solver/activation.py), on
    # scenes with clearance joints, ideal joints and resting contacts.
    _compare(name, {"activation": rule})


@pytest.mark.parametrize("name, impacts", [
    ("bouncing-ball-e0.5", 3), ("bouncing-ball-e0.9", 3), ("stiff-large-step-ball", 3),
    ("stiff-elastic", 3), ("flores-slider-crank", 1)])
def test_both_loops_localise_impacts_alike(name, impacts):
    # The scenes with restitution, whose default preset localises impacts (the Python step
    # splits a step at the crossing: MoreauJeanStepper._advance), run long enough for
    # ``impacts`` contacts to close from flight (a recorded state with no active contact
    # followed by one with an active contact), each a localised impact.
    scene = get_scene(name)
    horizon = {"flores-slider-crank": 0.01}.get(name, scene.horizon)
    python, compiled = _compare(name, horizon=horizon)
    assert python.metadata["localise_impacts"]
    # The same steps split at an impact (each split step counted once).
    assert compiled.metadata["split_steps"] == python.metadata["split_steps"] >= impacts
    touching = python.active_contacts > 0
    assert int(np.sum(touching[1:] & ~touching[:-1])) >= impacts


def test_a_run_the_compiled_loop_cannot_step_falls_back_with_its_reason():
    # Impact localisation is compiled: bouncing-ball-e0.5 (restitution 0.5, localised by the
    # default preset) runs in the compiled loop.
    scene = get_scene("bouncing-ball-e0.5")
    run = create("default").run(scene, RunSettings(horizon=5 * scene.time_step))
    assert run.metadata["step_loop"] == "compiled"
    assert run.metadata["step_loop_fallback"] == ""
    # A stepper with a feature the loop lacks (the Python projection) steps in Python, with
    # the reason; forcing the compiled loop on it is an option error.
    model = build(scene, create("default").run_settings(scene, RunSettings()))
    model.stepper.compiled_projection = False
    loop = choose_step_loop("auto", model.stepper)
    assert not loop.compiled and "Python projection" in loop.fallback
    with pytest.raises(OptionError, match="step_loop"):
        choose_step_loop("compiled", model.stepper)


def test_auto_is_the_default_and_python_can_be_forced():
    scene = get_scene("pendulum")
    run = create("default").run(scene, RunSettings(horizon=3 * scene.time_step))
    assert run.metadata["step_loop"] == "compiled"
    run = create("default").run(scene, RunSettings(horizon=3 * scene.time_step,
                                                   options={"step_loop": "python"}))
    assert run.metadata["step_loop"] == "python"
    assert run.metadata["step_loop_fallback"] == "step_loop = python"
