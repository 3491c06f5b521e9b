"""Tests of the Exudyn adapter's options and guards, each guard shown firing: no solution
files, Exudyn's printing kept out of stdout (the worker protocol), solver failures recorded
with Exudyn's own reason, non-finite state and energy gain stopping the run, unsupported pairs
with their reason. Cost: a few seconds.
"""

from __future__ import annotations

import dataclasses
import os
import sys
import warnings

import numpy as np
import pytest

from clearbench.adapters.base import RunSettings
from clearbench.adapters.exudyn import create
from clearbench.adapters.exudyn import run as run_module
from clearbench.adapters.exudyn.settings import exudyn_restitution, resolve_settings
from clearbench.adapters.trajectory import RunStatus
from clearbench.scenarios.bodies import Body
from clearbench.scenarios.contacts import ContactPair
from clearbench.scenarios.library import get_scene
from clearbench.scenarios.library.basic import ground
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.shapes import Box

# Exudyn 1.13 warns about its own renamed settings on every import path it uses.
warnings.filterwarnings("ignore", category=DeprecationWarning)


def _short(scene: Scene, steps: int) -> RunSettings:
    return RunSettings(horizon=steps * scene.time_step)


# ---------------------------------------------------------------------------- options
def test_options_are_checked_before_any_run():
    engine = create("default")
    scene = get_scene("bouncing-ball-e0.5")
    with pytest.raises(ValueError, match="unknown exudyn option"):
        engine.run(scene, RunSettings(options={"no_such_option": 1}))
    with pytest.raises(ValueError, match=r"friction_regularisation_velocity=-1"):
        engine.run(scene, RunSettings(options={"friction_regularisation_velocity": -1}))
    with pytest.raises(ValueError, match=r"impact_model=3"):
        engine.run(scene, RunSettings(options={"impact_model": 3}))
    with pytest.raises(ValueError, match=r"spectral_radius=1.5"):
        resolve_settings("tuned", {"spectral_radius": 1.5})
    with pytest.raises(ValueError, match="unknown exudyn preset"):
        create("fast")


def test_plastic_pairs_get_a_positive_restitution():
    settings = resolve_settings("default")
    assert exudyn_restitution(0.0, settings) == settings.plastic_restitution > 0
    assert exudyn_restitution(0.5, settings) == 0.5


# ---------------------------------------------------------------------------- guards
def test_no_solution_file_is_written(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    scene = get_scene("bouncing-ball-e0.5")
    trajectory = create("default").run(scene, _short(scene, 20))
    assert trajectory.status is RunStatus.OK
    assert os.listdir(tmp_path) == []


def _failing_run():
    """A ball hitting a very stiff contact with 1 Newton iteration and no step reduction:
    Exudyn's solver fails (it prints its 'DYNAMIC SOLVER FAILED' banner by default)."""
    scene = dataclasses.replace(get_scene("bouncing-ball-e0.5"), name="stiff-ball")
    ball = dataclasses.replace(scene.bodies[1], position=(0.0, 0.0, 0.1005),
                               velocity=(0.0, 0.0, -5.0))
    scene = dataclasses.replace(scene, bodies=(scene.bodies[0], ball))
    return create("default").run(scene, RunSettings(horizon=0.01, options=dict(
        contact_stiffness=1e12, newton_max_iterations=1, adaptive_step=False)))


def test_solver_failure_is_recorded_and_stdout_kept_out(capfd):
    before = sys.stdout
    trajectory = _failing_run()
    out, err = capfd.readouterr()
    assert sys.stdout is before
    assert trajectory.status is RunStatus.DIVERGED
    assert "Exudyn" in trajectory.message and "t = " in trajectory.message
    assert out == ""
    # The reason read from the solver's flags, in the message and the metadata: here the
    # contact switching iteration fails (Newton converged), at the nominal step (no step
    # reduction). Exudyn's own GetErrorString says "Newton did not converged" for it (its
    # flags printed inverted): it is kept apart, never as the reason.
    reason = trajectory.metadata["solver_error"]
    assert trajectory.metadata["failed_loop"] == "discontinuous"
    assert reason.startswith("discontinuous (contact/friction switching) iteration did not "
                             "converge at step size 0.001")
    assert "no step reduction" in reason
    assert "Newton did not converged" in trajectory.metadata["exudyn_error_string"]
    assert reason in trajectory.message
    assert len(trajectory.times) >= 1


@pytest.mark.parametrize("adaptive", [False, True])
def test_newton_failure_is_reported_as_one(adaptive):
    """Newton's tolerances below round-off (1e-300) on the pendulum: Newton cannot converge
    (its residual stalls near 1e-15 in the model's force units). The run says Newton failed,
    with the step size and the residual, and whether step reduction was exhausted (Exudyn's
    own string blames the discontinuous iteration)."""
    scene = get_scene("pendulum")
    trajectory = create("default").run(scene, RunSettings(horizon=0.01, options=dict(
        newton_absolute_tolerance=1e-300, newton_relative_tolerance=1e-300,
        newton_max_iterations=3, adaptive_step=adaptive)))
    assert trajectory.status is RunStatus.DIVERGED
    assert trajectory.metadata["failed_loop"] == "newton"
    reason = trajectory.metadata["solver_error"]
    assert reason in trajectory.message
    assert reason.startswith("Newton did not converge at step size")
    assert "residual" in reason and "absolute tolerance 1e-300" in reason
    assert ("step reduction reached the minimum step size" in reason) == adaptive
    assert "discontinuous iteration was not successful" in \
        trajectory.metadata["exudyn_error_string"]


def test_internal_error_is_a_crashed_run_with_exudyn_s_reason(capfd):
    """Redundant constraints of a planar loop in 3D, with the full-pivot LU switched off:
    Exudyn's dense solver raises InternalError ("matrix is not factorized")."""
    scene = get_scene("slider-crank")
    trajectory = create("default").run(scene, RunSettings(
        horizon=5 * scene.time_step, options={"closed_loop_full_pivot": False}))
    out, _ = capfd.readouterr()
    assert out == ""
    assert trajectory.status is RunStatus.CRASHED
    assert "InternalError" in trajectory.message
    assert "matrix is not factorized" in trajectory.message


def test_pulling_normal_force_is_recorded():
    """Exudyn does not clip the normal force at zero: the metadata keeps the most negative
    recorded pair sum (0 when none pulled), in the model's units."""
    scene = get_scene("bouncing-ball-e0.5")
    trajectory = create("default").run(scene, _short(scene, 50))
    assert trajectory.status is RunStatus.OK, trajectory.message
    lowest = trajectory.metadata["min_normal_force"]
    assert lowest <= 0.0
    assert lowest == min(0.0, float(trajectory.contact_normal_force.min()))


def test_non_finite_state_stops_the_run(monkeypatch):
    original = run_module.Runner._post_step

    def corrupt(self, mbs, t):
        if t > 3.5 * self.dt:
            q = np.asarray(mbs.systemData.GetODE2Coordinates())
            q[0] = np.nan
            mbs.systemData.SetODE2Coordinates(q)
        return original(self, mbs, t)

    monkeypatch.setattr(run_module.Runner, "_post_step", corrupt)
    scene = get_scene("pendulum")
    trajectory = create("default").run(scene, _short(scene, 10))
    assert trajectory.status is RunStatus.DIVERGED
    assert "non-finite state" in trajectory.message
    assert len(trajectory.times) == 5  # t = 0..3 dt, then the offending sample


def test_energy_gain_stops_the_run(monkeypatch):
    original = run_module.Runner.energy

    def growing(self, state=None):
        total, kinetic = original(self, state)
        return total + (100.0 if self.count > 3 else 0.0), kinetic

    monkeypatch.setattr(run_module.Runner, "energy", growing)
    scene = get_scene("pendulum")
    trajectory = create("default").run(scene, _short(scene, 50))
    assert trajectory.status is RunStatus.DIVERGED
    assert "energy gain" in trajectory.message


def test_energy_guard_off_where_loads_do_work():
    scene = get_scene("slider-crank")
    trajectory = create("default").run(scene, _short(scene, 3))
    assert any("energy guard off" in note for note in trajectory.metadata["guards"])


def test_box_box_is_unsupported_with_its_reason():
    scene = Scene(name="stack", horizon=0.1, time_step=1e-3, bodies=(
        ground(),
        Body("a", position=(0, 0, 0.05), shapes=(Box("b", half_extents=(0.05,) * 3),)),
        Body("b", position=(0, 0, 0.15), shapes=(Box("b", half_extents=(0.05,) * 3),))),
        contacts=(ContactPair("floor", body_a="ground", shape_a="floor", body_b="a",
                              shape_b="b"),
                  ContactPair("stack", body_a="a", shape_a="b", body_b="b", shape_b="b")))
    trajectory = create("default").run(scene)
    assert trajectory.status is RunStatus.UNSUPPORTED
    assert "box-box" in trajectory.message
