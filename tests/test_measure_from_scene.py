"""Joint and clearance figures taken from the scene, on hand-made trajectories (no engine): a
journal out of its bore reads as an excess of many clearances, growing with the distance; a
body that starts elsewhere than the scene says reads as joint error from t = 0.

The figures are the harness's shared measurement, the same code for every engine's trajectory
(the engines differ only in the trajectory they return), so one hand-made trajectory checks
the measurement of all of them.
"""

from __future__ import annotations

import numpy as np
import pytest

from clearbench.adapters.trajectory import RunStatus, Trajectory, scene_fields
from clearbench.harness.measure import series
from clearbench.harness.measure.figures import measure
from clearbench.kernels.gaps import axis_crosses_inside_ring, enclosing_ring_gap
from clearbench.scenarios.library import get_scene

from .verdict_scenes import branched_tree


def _still(scene, count: int) -> Trajectory:
    """Every body at its scene pose on ``count`` samples (1 ms apart), at rest."""
    positions = np.array([[b.position for b in scene.bodies]] * count, dtype=float)
    orientations = np.array([[b.orientation for b in scene.bodies]] * count, dtype=float)
    nb, nc = len(scene.bodies), len(scene.all_contacts)
    return Trajectory(
        engine="hand", preset="default", **scene_fields(scene), time_step=1e-3,
        times=np.arange(count) * 1e-3, positions=positions, orientations=orientations,
        velocities=np.zeros((count, nb, 3)), angular_velocities=np.zeros((count, nb, 3)),
        contact_normal_force=np.zeros((count, nc)), contact_force=np.zeros((count, nc, 3)),
        solver_iterations=np.zeros(count, dtype=np.int64), solver_residual=np.zeros(count),
        solver_converged=np.ones(count, dtype=bool),
        active_contacts=np.zeros(count, dtype=np.int64), steps=count - 1)


#: Distances of the bearing (the pendulum bob) from the journal, perpendicular to the bore
#: axis [m]: within the 0.1 mm clearance, just beyond it, at the journal radius (10 mm), at
#: twice the bore radius (where the unsigned ring gap turned the eccentricity negative), and
#: 1.43 m away (the Siconos run that printed 9.3e-5 m).
DISTANCES = (5e-5, 2e-4, 1e-2, 2.5e-2, 1.43)


def _bob_moved(distances) -> tuple:
    scene = get_scene("clearance-pendulum")
    trajectory = _still(scene, len(distances))
    bob = scene.body_index("bob")
    trajectory.positions[:, bob, 0] += np.asarray(distances)  # across the bore axis (y)
    return scene, trajectory


def test_the_eccentricity_is_the_journal_distance_from_the_bore_axis_however_far():
    scene, trajectory = _bob_moved(DISTANCES)
    motion = series.clearance_motion(scene, trajectory)
    eccentricity = motion.eccentricity[:, 0]
    # Parallel axes: the eccentricity is the axis distance itself, to round-off of metres
    # (1e-12 m: a few ulp of the 1.43 m sample).
    np.testing.assert_allclose(eccentricity, DISTANCES, rtol=0, atol=1e-12)
    assert np.all(eccentricity >= 0)
    assert np.all(np.diff(motion.excess[:, 0]) > 0)  # monotone in the distance
    clearance = scene.clearance_joints[0].radial_clearance
    # 1.43 m out: an excess of about 14 300 clearances, not capped at the journal radius.
    assert motion.excess[-1, 0] == pytest.approx(1.43 - clearance, rel=1e-12)
    assert motion.excess[-1, 0] > scene.clearance_joints[0].journal_radius


def test_a_journal_out_of_its_bore_fails_no_penetration_and_the_clearance_check():
    scene, trajectory = _bob_moved((0.0, 0.0, 1.43))
    measurement = measure(scene, trajectory)
    results = {r["name"]: r for r in measurement.expectations}
    assert results["no_penetration"]["passed"] is False
    assert results["ideal_limit"]["passed"] is False
    assert measurement.figures["clearance_excess_max"] > 1.0  # metres: far beyond the bore
    assert measurement.verdict is RunStatus.DIVERGED
    assert "left its bore" in measurement.verdict_reason


def test_a_journal_in_its_bore_keeps_its_gap():
    scene, trajectory = _bob_moved((0.0, 3e-5, 6e-5))
    measurement = measure(scene, trajectory)
    results = {r["name"]: r for r in measurement.expectations}
    assert results["no_penetration"]["passed"] is True
    assert results["ideal_limit"]["passed"] is True
    assert measurement.figures["clearance_excess_max"] == 0.0


@pytest.mark.parametrize(("crossing", "inside"), [((0.5, 0.0), True), ((1.5, 0.0), False),
                                                  ((0.0, -1.5), True), ((0.0, 1.5), False)])
def test_an_arc_counts_a_journal_past_its_opening_as_inside(crossing, inside):
    # Unit ring in the xy-plane, an arc over the upper half (0 to pi): a journal axis along z
    # crossing below the arc left through the opening, above it through the material.
    rotation = np.eye(3)
    point = (crossing[0], crossing[1], 0.3)
    assert axis_crosses_inside_ring(np.zeros(3), rotation, 1.0, 0.0, np.pi, point,
                                    (0.0, 0.0, 1.0)) is (inside or crossing[0] == 0.5)


def test_the_enclosing_gap_is_continuous_where_the_axis_crosses_the_ring():
    # Unsigned gap at the crossing: distance 0 minus the journal radius, both ways.
    assert enclosing_ring_gap(-0.01, 0.01, True) == enclosing_ring_gap(-0.01, 0.01, False)


def test_a_body_started_elsewhere_reads_as_joint_error_from_the_first_sample():
    scene = branched_tree()
    trajectory = _still(scene, 3)
    assert np.max(series.joint_violation(scene, trajectory).distance) == 0.0
    # Swap two bodies' rows (what a renumbered multibody returns): the anchors no longer meet
    # on any sample, t = 0 included.
    left, right = scene.body_index("left"), scene.body_index("right")
    trajectory.positions[:, [left, right]] = trajectory.positions[:, [right, left]]
    distance = series.joint_violation(scene, trajectory).distance
    names = [j.name for j in scene.joints]
    arm = 0.2  # m, the tree's arm
    # left's frame is 0.5 arm from hub_left's anchor; put at right's place it is 0.5 arm
    # below and 0.5 arm short of it: its anchor point misses by 0.5 arm x sqrt 2.
    assert distance[0, names.index("hub_left")] == pytest.approx(0.5 * arm * np.sqrt(2))
