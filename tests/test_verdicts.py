"""The run verdict, the swept tunnelling test and the contact energy on hand-made trajectories
(no engine): what each rule says, where its bounds sit."""

from __future__ import annotations

import numpy as np
import pytest

from clearbench.adapters import mujoco, reference
from clearbench.adapters.base import RunSettings
from clearbench.adapters.trajectory import RunStatus, Trajectory, scene_fields
from clearbench.harness.measure import series
from clearbench.harness.measure.figures import measure
from clearbench.harness.measure.verdicts import VERDICTS, run_verdict
from clearbench.scenarios.library import get_scene


@pytest.mark.parametrize(("status", "passed", "verdict"), [
    ("ok", 1, "pass"), ("ok", 0, "physics failed"), ("ok", None, "no check"),
    ("ok", float("nan"), "no check"), ("diverged", 1, "diverged"), ("crashed", None, "crashed"),
    ("timed_out", None, "timed out"), ("unsupported", None, "unsupported"),
])
def test_run_verdict_combines_status_and_expectations(status, passed, verdict):
    assert run_verdict(status, passed) == verdict


def test_every_verdict_has_its_own_symbol_and_colour():
    assert {run_verdict(s.value, 1) for s in RunStatus} <= set(VERDICTS)
    assert len({v.symbol for v in VERDICTS.values()}) == len(VERDICTS)
    assert len({v.colour for v in VERDICTS.values()}) == len(VERDICTS)
    with pytest.raises(ValueError, match="unknown run status"):
        run_verdict("exploded", 1)


def _ball_and_plate(heights, normal_forces=None) -> Trajectory:
    """A trajectory of ``stiff-tunnelling`` (5 mm ball, plate 2 mm thick, top face at z = 0)
    with the ball's centre at the given heights [m], one sample per millisecond."""
    scene = get_scene("stiff-tunnelling")
    count = len(heights)
    positions = np.zeros((count, 2, 3))
    positions[:, 0] = scene.body("plate").position
    positions[:, 1, 2] = heights
    orientations = np.zeros((count, 2, 4))
    orientations[..., 0] = 1.0
    forces = np.zeros((count, 1)) if normal_forces is None else \
        np.asarray(normal_forces, dtype=float).reshape(count, 1)
    return Trajectory(
        engine="hand", preset="default", **scene_fields(scene), time_step=1e-3,
        times=np.arange(count) * 1e-3, positions=positions, orientations=orientations,
        velocities=np.zeros((count, 2, 3)), angular_velocities=np.zeros((count, 2, 3)),
        contact_normal_force=forces, contact_force=np.zeros((count, 1, 3)),
        solver_iterations=np.zeros(count, dtype=np.int64), solver_residual=np.zeros(count),
        solver_converged=np.ones(count, dtype=bool),
        active_contacts=np.zeros(count, dtype=np.int64), steps=count - 1)


def test_a_ball_through_the_plate_between_two_samples_is_tunnelled():
    scene = get_scene("stiff-tunnelling")
    # 20 mm above the plate, then 30 mm below it: no sample inside the plate.
    trajectory = _ball_and_plate([0.02, -0.03, -0.08])
    assert np.max(series.penetration(scene, trajectory)) == 0.0
    swept = series.swept_penetration(scene, trajectory)
    # On the path the ball's centre crosses the plate: the penetration reaches the ball's
    # radius plus the plate's half thickness (6 mm), within one sub-step (0.5 mm).
    assert swept[0] == pytest.approx(0.006, abs=5e-4)
    result = measure(scene, trajectory)
    assert result.verdict is RunStatus.DIVERGED
    assert "crossed between two samples" in result.verdict_reason


def test_a_ball_that_stops_on_the_plate_is_not_tunnelled():
    scene = get_scene("stiff-tunnelling")
    trajectory = _ball_and_plate([0.05, 0.02, 0.005, 0.005, 0.005])
    assert series.swept_penetration(scene, trajectory)[0] == 0.0
    assert "tunnelled" not in measure(scene, trajectory).verdict_reason


def test_contact_energy_is_half_the_normal_force_times_the_penetration():
    scene = get_scene("stiff-tunnelling")
    # Centre 4.9 mm above the top face: 0.1 mm deep, pressed by 10 N.
    trajectory = _ball_and_plate([0.0049, 0.006], normal_forces=[10.0, 0.0])
    energy = series.contact_energy(scene, trajectory)
    # 0.5 * 10 N * 1e-4 m = 5e-4 J, to round-off of the gap (1e-12 of the lengths).
    assert energy == pytest.approx([5e-4, 0.0], rel=1e-9, abs=1e-15)


def test_a_rigid_engine_stores_no_contact_energy():
    scene = get_scene("stiff-tunnelling")
    # The same 0.1 mm and 10 N from an engine with rigid contacts (the force is an impulse
    # over the step, the depth that of a step that captured an impact): no stored energy.
    trajectory = _ball_and_plate([0.0049, 0.006], normal_forces=[10.0, 0.0])
    trajectory.rigid_contacts = True
    assert series.contact_energy(scene, trajectory).tolist() == [0.0, 0.0]


def test_a_run_records_whether_its_engine_has_rigid_contacts():
    scene, settings = get_scene("bouncing-ball-e0.5"), RunSettings(horizon=0.01)
    assert reference.create().run(scene, settings).rigid_contacts is True
    assert mujoco.create().run(scene, settings).rigid_contacts is False
