"""The C-60 with the reference engine: short runs in the default suite, full runs marked slow.

Penetration is measured by the shared geometry (harness.measure), never taken from the engine.
"""

from __future__ import annotations

import numpy as np
import pytest

from clearbench.adapters.base import RunSettings
from clearbench.adapters.reference.engine import create
from clearbench.harness.c60 import analysis
from clearbench.harness.measure import series as metrics
from clearbench.scenarios.c60 import model
from clearbench.scenarios.library import get_scene

ENGINE = create()
#: Largest penetration the brief allows [mm]; the projection's tolerance is 1e-10 of the
#: smallest feature (an offset of 1e-3 mm): 1e-13 mm.
PENETRATION_LIMIT = 1e-6


def unconverged(trajectory) -> list:
    return list(trajectory.unconverged_steps)


def test_short_on_run_takes_up_the_clearances_without_penetration():
    scene = get_scene("c60-on", horizon=0.3)
    trajectory = ENGINE.run(scene, RunSettings())
    assert trajectory.status.value == "ok" and trajectory.steps == 300
    depth = metrics.penetration(scene, trajectory)
    assert depth.max() <= PENETRATION_LIMIT
    # Every step's contact problem converged to the engine's tolerance, else they are listed.
    assert not unconverged(trajectory), unconverged(trajectory)
    assert not trajectory.metadata["unconverged_projections"]
    # The joints take up their clearances within 0.3 ms: about ten contacts carry load.
    assert trajectory.active_contacts[-1] >= 8
    # The plunger is driven at zero x velocity: it stays (to round-off of the driver row).
    plunger = scene.body_index("plunger")
    assert np.abs(trajectory.positions[:, plunger, 0] - trajectory.positions[0, plunger, 0]
                  ).max() < 1e-12


def test_short_trip_run_drives_the_plunger_from_its_start_time():
    # The plunger starts at 0.1 ms here (0.7 ms in the full run) so that 300 steps see it move.
    scene = get_scene("c60-trip", horizon=0.3, plunger_start=0.1)
    trajectory = ENGINE.run(scene, RunSettings())
    assert metrics.penetration(scene, trajectory).max() <= PENETRATION_LIMIT
    assert not unconverged(trajectory), unconverged(trajectory)
    plunger = scene.body_index("plunger")
    x = metrics.centre_of_mass_positions(scene, trajectory)[:, plunger, 0]
    # 0.2 mm/ms for 0.2 ms: 0.04 mm, held by the driver's position row to the projection's
    # tolerance (1e-13 mm); 1e-9 mm leaves room for the round-off of 300 steps.
    assert abs((x[-1] - x[0]) - 0.04) < 1e-9
    assert abs(x[100] - x[0]) < 1e-9


@pytest.fixture(scope="module")
def on_run():
    scene = get_scene("c60-on")
    return scene, ENGINE.run(scene, RunSettings(record_every=10))


@pytest.mark.slow
def test_on_mechanism_settles_latched_without_penetration(on_run):
    scene, trajectory = on_run
    assert metrics.penetration(scene, trajectory).max() <= PENETRATION_LIMIT
    # Settled: over the last millisecond the measurement distances change by less than 1e-4 mm
    # (the joints hold their positions; measured 0). FC-1 jitters by 4e-3 N (0.06 %): with
    # redundant frictional contacts in stick the force distribution is not unique, and each
    # step's solver picks one; 0.01 N bounds it.
    drift = analysis.output_drift(scene, trajectory)
    assert drift["FC1_contact_force"] < 1e-2
    assert max(v for k, v in drift.items() if k != "FC1_contact_force") < 1e-4
    # Latched: the hook holds still after 3 ms (1e-4 mm: far below the joints' clearances).
    from clearbench.harness.measure.expectation_figures import evaluate

    latched = next(r for r in evaluate(scene, trajectory) if r.name == "stays_latched")
    assert latched.figures["displacement"] < 1e-4
    names = trajectory.contact_names
    latch = sum(trajectory.contact_normal_force[-1, i] for i, n in enumerate(names)
                if n.startswith(("Hook_Tbar_C4", "Tbar_Hook_C5")))
    assert latch > 1.0


@pytest.mark.slow
def test_fc1_is_the_moment_balance_of_the_moving_contact(on_run):
    # Independent static check of the equilibrium: the contact-pressure law's force on the
    # moving contact (M / 6.06 at its centre of mass) has a moment about the needle axis that
    # C7's normal force balances at its lever about that axis.
    from clearbench.kernels.quaternion import quat_to_matrix
    from clearbench.ref_solver.forces import twist_angle
    from clearbench.scenarios.geometry import contacts_between

    scene, trajectory = on_run
    law = next(load for load in scene.loads if load.name == "contact_pressure_spring")
    pose = {b.name: (trajectory.positions[-1, i], trajectory.orientations[-1, i])
            for i, b in enumerate(scene.bodies)}
    z = np.array([0.0, 0.0, 1.0])
    theta = {n: twist_angle(quat_to_matrix(pose[n][1]), z) for n in ("moving_contact", "plate")}
    moment = law.stiffness * (law.offset + theta["moving_contact"] - theta["plate"])
    rotation = quat_to_matrix(pose["moving_contact"][1])
    centre = pose["moving_contact"][0] + rotation @ np.asarray(
        scene.body("moving_contact").center_of_mass)
    direction = rotation @ np.asarray(law.applications[2].unit_direction())
    force = moment / 6.06 * direction
    axis_point = pose["needle"][0]
    law_moment = np.cross(centre - axis_point, force)[2]
    c7 = next(c for c in scene.contacts if c.name == model.C7)
    result = contacts_between(scene.body(c7.body_a).shape(c7.shape_a), pose[c7.body_a],
                              scene.body(c7.body_b).shape(c7.shape_b), pose[c7.body_b])
    closed = result.gap - c7.offset < 1e-6
    point = result.point_b[closed].mean(axis=0)
    normal = -result.normal[closed][0]  # the force of the fixed contact on the moving one
    lever = np.cross(point - axis_point, normal)[2]
    predicted = -law_moment / lever
    fc1 = analysis.settled_outputs(scene, trajectory)["FC1_contact_force"]
    # Joint friction (mu 0.1 on the J7 and S3 rings, about 20 N at radii of 1-1.5 mm: up to
    # 3 N mm of the law's 150 N mm) and C7's own friction shift the balance by a few percent.
    assert abs(fc1 - predicted) < 0.05 * predicted
    assert 6.5 < fc1 < 8.0  # measured 7.35 N (nominal clearances), see the validation report


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason="FC-1 is 7.35 N, half the paper's 14.96 N simulated / "
                   "15.28 N measured: the source's contact-pressure law (M = 244.46 (D + 0.49)"
                   " N mm) balances at C7 with 7.4 N; see reports/c60_validation.md")
def test_fc1_matches_the_paper_within_ten_percent(on_run):
    scene, trajectory = on_run
    fc1 = analysis.settled_outputs(scene, trajectory)["FC1_contact_force"]
    # The paper's simulation and measurement differ by 2 %; 10 % is the brief's threshold.
    assert abs(fc1 - 14.96) < 0.1 * 14.96


@pytest.fixture(scope="module")
def trip_run():
    scene = get_scene("c60-trip")
    return scene, ENGINE.run(scene, RunSettings(record_every=10))


@pytest.mark.slow
def test_trip_opens_the_contacts(trip_run):
    scene, trajectory = trip_run
    events = analysis.trip_events(scene, trajectory)
    # The plunger (0.51 mm from the bar once settled, 0.2 mm/ms from 0.7 ms) strikes at about
    # 3.2 ms; the latch lets go, C7 chatters within the joints' clearances, then opens.
    assert 2.5 < events.strike < 4.0
    assert events.strike < events.release < events.opening < 10.0
    assert events.gap_after > 0.1  # it did not close again in the next millisecond
    # Up to 2 ms after the opening: no penetration, and contacts on convex patches modelled as
    # full cylinders stay on their CAD patch.
    window = trajectory.times <= events.opening + 2.0
    assert metrics.penetration(scene, trajectory)[window].max() <= PENETRATION_LIMIT
    excursions = analysis.patch_excursions(scene, trajectory, end=events.opening + 2.0)
    assert max(excursions.values()) == 0.0, excursions
    # Every step's contact problem converged, or the few that did not are listed.
    steps = unconverged(trajectory)
    assert len(steps) < 0.01 * trajectory.steps, steps


@pytest.mark.slow
def test_trip_has_no_penetration_over_the_whole_run(trip_run):
    # The whole 20 ms, including the handle turning freely after the trip (the source has no
    # OFF stop; its ON-stop face comes round behind the case's stop pins, which the faces'
    # depth keeps from counting as a contact, see scenarios.c60.model.FACE_DEPTH).
    scene, trajectory = trip_run
    assert metrics.penetration(scene, trajectory).max() <= PENETRATION_LIMIT
    # The few steps whose projection did not reach its tolerance are listed (4 of 20000
    # measured); the penetration above is measured on the recorded states all the same.
    steps = trajectory.metadata["unconverged_projections"]
    assert len(steps) < 1e-3 * trajectory.steps, steps
