"""MuJoCo adapter, runs: the library runs, forces and twists read out in scene conventions,
guards fire, results are unit independent (deterministic: test_engine_contract), loads and
drivers act as the scene says."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from clearbench.adapters.base import RunSettings
from clearbench.adapters.mujoco.engine import create
from clearbench.adapters.trajectory import RunStatus
from clearbench.harness.measure import series as metrics
from clearbench.harness.measure.expectation_figures import evaluate
from clearbench.scenarios.bodies import Body, Motion
from clearbench.scenarios.contacts import ContactPair
from clearbench.scenarios.drivers import Driver
from clearbench.scenarios.expectations import Expectation
from clearbench.scenarios.inertia import solid_box, solid_sphere
from clearbench.scenarios.joints import RevoluteJoint
from clearbench.scenarios.library import get_scene, scene_names
from clearbench.scenarios.loads import LinearSpringDamper, Moment, PointForce, TorsionalSpringDamper
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.shapes import Box, Plane, Sphere
from clearbench.scenarios.units import MM_G_MS

NAMES = scene_names()
G = 9.81
GUARD_MESSAGE = re.compile(r"energy gain|non-finite|MuJoCo warning")


def _figures(scene, trajectory, name):
    return next(r for r in evaluate(scene, trajectory) if r.name == name).figures


@pytest.mark.parametrize("preset", ["default", "tuned"])
@pytest.mark.parametrize("name", NAMES)
def test_library_scene_runs_a_short_horizon(name, preset):
    scene = get_scene(name)
    horizon = 20 * scene.time_step  # fast suite; full horizons in the slow test below
    trajectory = create(preset).run(scene, RunSettings(horizon=horizon))
    if "stiff" in scene.tags and trajectory.status is RunStatus.DIVERGED:
        # The stiff suite is built to break engines: a guard stopping it is a valid outcome
        # (measured: stiff-spring, whose explicit MuJoCo spring blows up), with the reason.
        assert GUARD_MESSAGE.search(trajectory.message), trajectory.message
        return
    assert trajectory.status is RunStatus.OK, trajectory.message
    assert trajectory.steps == 20
    assert trajectory.times[-1] == pytest.approx(horizon, rel=1e-9)
    nb, npair = len(scene.bodies), len(scene.all_contacts)
    assert trajectory.positions.shape == (21, nb, 3)
    assert trajectory.contact_force.shape == (21, npair, 3)
    assert trajectory.contact_names == tuple(c.name for c in scene.all_contacts)
    for array in (trajectory.positions, trajectory.orientations, trajectory.velocities,
                  trajectory.angular_velocities, trajectory.contact_force):
        assert np.isfinite(array).all()
    assert trajectory.build_seconds > 0 and trajectory.stepping_seconds > 0
    assert trajectory.engine == "mujoco" and trajectory.preset == preset


@pytest.mark.slow
@pytest.mark.parametrize("preset", ["default", "tuned"])
@pytest.mark.parametrize("name", NAMES)
def test_library_scene_runs_to_its_horizon_or_is_stopped_by_a_guard(name, preset):
    scene = get_scene(name)
    trajectory = create(preset).run(scene, RunSettings(record_every=10))
    if trajectory.status is RunStatus.OK:
        # Whole steps up to the horizon (the last may pass it when dt does not divide it).
        assert scene.horizon - 1e-9 <= trajectory.times[-1] < scene.horizon + scene.time_step
    else:
        # Measured: the Flores slider-crank with MuJoCo's default contacts (timeconst 0.02 s:
        # the slider sinks 35 mm into its guide) gains 11 % energy, and some scenes of the
        # stiff suite blow up; a guard stops them and says why. (The C-60 in the default
        # preset sinks through its joints but stays finite: status ok, its metrics say it.)
        assert trajectory.status is RunStatus.DIVERGED
        assert GUARD_MESSAGE.search(trajectory.message), trajectory.message


def _box_on_plane(friction: float = 0.5, tilt: float = 0.0, swap: bool = False) -> Scene:
    half = (0.1, 0.1, 0.05)
    c, s = math.cos(0.5 * tilt), math.sin(0.5 * tilt)
    normal = (math.sin(tilt), 0.0, math.cos(tilt))
    ground = Body("ground", motion=Motion.FIXED, orientation=(c, 0.0, s, 0.0),
                  shapes=(Plane("floor"),))
    box = Body("box", mass=2.0, inertia=solid_box(2.0, half),
               position=tuple(half[2] * n for n in normal), orientation=(c, 0.0, s, 0.0),
               shapes=(Box("box", half_extents=half),))
    pair = ContactPair("box_floor", body_a="box", shape_a="box", body_b="ground",
                       shape_b="floor", friction=friction) if swap else \
        ContactPair("box_floor", body_a="ground", shape_a="floor", body_b="box",
                    shape_b="box", friction=friction)
    return Scene(name="box-on-plane", horizon=0.5, time_step=1e-3, bodies=(ground, box),
                 contacts=(pair,))


@pytest.mark.parametrize("preset", ["default", "tuned"])
def test_static_box_contact_forces_sum_to_its_weight(preset):
    scene = _box_on_plane()
    trajectory = create(preset).run(scene)
    weight = 2.0 * G
    # At rest (0.5 s after release) the contact holds the weight exactly: the soft
    # constraint's steady state has zero acceleration; 1e-6 relative leaves room for the
    # residual motion of the settling (measured < 1e-9).
    assert trajectory.contact_normal_force[-1, 0] == pytest.approx(weight, rel=1e-6)
    assert np.allclose(trajectory.contact_force[-1, 0], [0.0, 0.0, weight], atol=1e-6 * weight)
    # Four corner contacts carry it (pyramidal and elliptic alike).
    assert trajectory.active_contacts[-1] == 4


def test_contact_force_acts_on_body_b_whatever_the_geom_order():
    weight = 2.0 * G
    # Pair (box, ground): the force on body B (the ground) is the reaction, -weight.
    trajectory = create("tuned").run(_box_on_plane(swap=True))
    assert np.allclose(trajectory.contact_force[-1, 0], [0.0, 0.0, -weight], atol=1e-6 * weight)
    assert trajectory.contact_normal_force[-1, 0] == pytest.approx(weight, rel=1e-6)


def test_box_sticking_on_an_incline_gets_friction_along_the_slope():
    tilt = math.radians(10.0)
    scene = _box_on_plane(friction=0.3, tilt=tilt)
    trajectory = create("tuned").run(scene, RunSettings(time_step=1e-4))
    weight = 2.0 * G
    # Normal force m g cos(tilt), friction m g sin(tilt) up the slope: together exactly the
    # weight, upward (1e-6 relative: residual creep of the soft contact, 0.07 um/s).
    assert trajectory.contact_normal_force[-1, 0] == pytest.approx(weight * math.cos(tilt),
                                                                   rel=1e-6)
    assert np.allclose(trajectory.contact_force[-1, 0], [0.0, 0.0, weight],
                       atol=1e-6 * weight)


def test_energy_guard_stops_a_run_with_a_too_stiff_contact():
    scene = get_scene("bouncing-ball-e0")
    # docs/engines/mujoco.md: solref 0.005 0.07 at dt 1e-3 launched a dropped ball 32x its height.
    trajectory = create("default").run(scene, RunSettings(options={"solref": (0.005, 0.07)}))
    assert trajectory.status is RunStatus.DIVERGED
    assert "energy gain" in trajectory.message
    assert trajectory.times[-1] < scene.horizon
    assert any("stiffness*dt^2" in w for w in trajectory.metadata["warnings"])
    # The same scene with the preset's own contacts runs to the end without warnings.
    fine = create("default").run(scene)
    assert fine.status is RunStatus.OK and fine.metadata["warnings"] == []


def test_blow_up_stops_the_run_without_an_energy_expectation():
    # An explicit spring with stiffness * dt^2 / mass = 1e4 grows ~1e4x per step.
    spring = LinearSpringDamper("stiff", body_a="ground", point_a=(0.0, 0.0, 0.0),
                                body_b="body", point_b=(0.0, 0.0, 0.0), stiffness=1e10,
                                rest_length=1.0)
    scene = _free_body_scene((spring,), mass=1.0, position=(1.01, 0.0, 0.0))
    trajectory = create("default").run(scene)
    assert trajectory.status is RunStatus.DIVERGED
    assert "non-finite" in trajectory.message or "MuJoCo warning" in trajectory.message
    assert trajectory.times[-1] < scene.horizon
    assert any("stiffness*dt^2/mass" in w for w in trajectory.metadata["warnings"])
    assert any("energy guard off" in note for note in trajectory.metadata["guards"])


@pytest.mark.parametrize("restitution, bound", [(0.5, 0.06), (0.9, 0.01)])
@pytest.mark.parametrize("time_step", [1e-3, 1e-4])
def test_restitution_mapping_reproduces_e_on_a_bouncing_ball(restitution, bound, time_step):
    scene = get_scene(f"bouncing-ball-e{restitution:g}")
    trajectory = create("tuned").run(scene, RunSettings(
        time_step=time_step, horizon=1.5, record_every=max(1, round(1e-4 / time_step))))
    first_apex = _figures(scene, trajectory, "apex_heights")["apex_1_relative_error"]
    measured = math.sqrt(1.0 + first_apex) * restitution  # apex ratio is e^2
    # The contact lasts 20 steps (restitution_contact_steps); where the impact and the
    # separation fall within a step changes e by up to ~1/20 of the damping work: measured
    # over drop heights 0.9-1.1 m, |error| <= 5.7 % for e = 0.5 and <= 0.8 % for e = 0.9.
    assert measured == pytest.approx(restitution, rel=bound)


def test_millimetre_scene_runs_in_si_and_returns_scene_units():
    scene = get_scene("clearance-pendulum")
    si = create("tuned").run(scene, RunSettings(horizon=0.05))
    mm = create("tuned").run(scene.rescaled(MM_G_MS), RunSettings(horizon=50.0))
    assert mm.internal_units.startswith("m-kg-s")
    assert mm.units == {"length": "mm", "mass": "g", "time": "ms"}
    assert mm.steps == si.steps
    # Both run the same SI model up to the round-off of rescaling (1e-16 relative), which
    # the contacts amplify; 1e-9 of the 1 m pendulum length is far below every figure.
    assert np.max(np.abs(mm.positions * 1e-3 - si.positions)) <= 1e-9
    assert np.max(np.abs(mm.times * 1e-3 - si.times)) <= 1e-15
    assert np.allclose(mm.contact_normal_force, si.contact_normal_force, rtol=1e-6,
                       atol=1e-6 * np.max(si.contact_normal_force))


def test_driver_prescribes_the_crank_exactly():
    scene = get_scene("slider-crank")
    trajectory = create("tuned").run(scene, RunSettings(time_step=1e-4, record_every=10))
    angle = metrics.output_values(scene, trajectory)["crank_angle"]
    # Position and velocity of the driven hinge are reset to the profile every step:
    # exact up to round-off (1e-10 rad over 1 s).
    assert np.allclose(angle, 10.0 * trajectory.times, atol=1e-10)
    kinematics = _figures(scene, trajectory, "kinematics")
    # Loop closure by two soft connects with solref (2 dt, 1): measured 0.27 um at 1e-4;
    # bound 1e-5 of the 0.1 m crank (1 um).
    assert kinematics["slider_position_relative_error"] < 1e-5


def test_translation_driver_on_a_free_body_leaves_the_other_components_free():
    # The C-60 plunger: x velocity switched on at t = 0.2, everything else free (here: falls).
    plunger = Body("plunger", mass=0.8, inertia=solid_sphere(0.8, 0.01), motion=Motion.DRIVEN,
                   center_of_mass=(0.01, 0.0, 0.0))
    scene = Scene(name="plunger", horizon=0.5, bodies=(plunger,),
                  drivers=(Driver("push", body="plunger", component="x",
                                  times=(0.0, 0.2, 0.2), values=(0.0, 0.0, 0.3)),))
    trajectory = create("default").run(scene)
    com = metrics.centre_of_mass_positions(scene, trajectory)[:, 0]
    t = trajectory.times
    expected_x = 0.01 + 0.3 * np.maximum(t - 0.2, 0.0)
    # Prescribed component exact at every sample (round-off).
    assert np.allclose(com[:, 0], expected_x, atol=1e-12)
    # Free components: free fall under gravity (semi-implicit Euler: g t (t + dt) / 2).
    dt = scene.time_step
    assert np.allclose(com[:, 2], -0.5 * G * t * (t + dt), atol=1e-12)


def _free_body_scene(loads, **body) -> Scene:
    fields = dict(mass=2.0, inertia=((0.1, 0, 0), (0, 0.2, 0), (0, 0, 0.3)))
    fields.update(body)
    return Scene(name="loaded", gravity=(0.0, 0.0, 0.0), horizon=0.4, time_step=1e-3,
                 bodies=(Body("ground", motion=Motion.FIXED), Body("body", **fields)),
                 loads=tuple(loads))


def test_time_switched_point_force_and_moment():
    force = PointForce("push", body="body", point=(0.0, 0.5, 0.0), force=(40.0, 0.0, 0.0),
                       start_time=0.1, end_time=0.11)
    moment = Moment("twist", body="body", moment=(0.0, 0.0, 0.6), frame="body",
                    start_time=0.25)
    scene = _free_body_scene((force, moment))
    trajectory = create("default").run(scene)
    v = trajectory.velocities[-1, 1]
    w = trajectory.angular_velocities[-1, 1]
    # Impulse 40 N x 0.01 s on 2 kg; its moment about the centre (0.5 m lever, -z); then
    # 0.6 N m about body z for 0.15 s on I_zz 0.3. Switching is resolved to the step
    # (1e-3 s): the windows hold exactly 10 and 150 steps. The lever turns by at most
    # 3.3 mrad while the force acts (cos: 6e-6 relative): bound 1e-5 of the rate.
    assert np.allclose(v, [0.2, 0.0, 0.0], atol=1e-9)
    expected = -40.0 * 0.5 * 0.01 / 0.3 + 0.6 * 0.15 / 0.3
    assert w[2] == pytest.approx(expected, rel=1e-5)


def test_linear_spring_with_preload_oscillates_about_its_shifted_rest_length():
    k, mass = 400.0, 2.0
    spring = LinearSpringDamper("spring", body_a="ground", point_a=(0.0, 0.0, 0.0),
                                body_b="body", point_b=(0.0, 0.0, 0.0), stiffness=k,
                                rest_length=1.0, preload=20.0)
    scene = _free_body_scene((spring,), mass=mass, position=(1.0, 0.0, 0.0))
    trajectory = create("default").run(scene, RunSettings(time_step=1e-4, horizon=1.0,
                                                          record_every=10))
    x = trajectory.positions[:, 1, 0]
    # Tension 20 + 400 (L - 1) vanishes at L = 0.95: oscillation 1 -> 0.9 about 0.95 with
    # omega = sqrt(k/m); semi-implicit Euler at omega dt = 1.4e-3 is within 1e-5 m.
    omega = math.sqrt(k / mass)
    expected = 0.95 + 0.05 * np.cos(omega * trajectory.times)
    assert np.max(np.abs(x - expected)) < 1e-4  # phase error omega^2 dt t / 2 ~ 7e-5 m
    energy = metrics.energy(scene, trajectory).total
    # Energy bookkeeping matches the metrics (preload included): conserved to 1e-3.
    assert np.ptp(energy) < 1e-3 * (0.5 * k * 0.05**2 + 20.0 * 0.05)


@pytest.mark.parametrize("joined", [True, False])
def test_torsional_spring_as_joint_stiffness_or_explicit_moment(joined):
    k, inertia_z = 3.0, 0.3
    spring = TorsionalSpringDamper("coil", body_a="ground", body_b="body",
                                   axis=(0.0, 0.0, 1.0), stiffness=k, rest_angle=0.1)
    joints = (RevoluteJoint("axle", body_a="ground", body_b="body", axis=(0.0, 0.0, 1.0)),) \
        if joined else ()
    scene = _free_body_scene((spring,))
    scene = Scene(name=scene.name, gravity=scene.gravity, horizon=2.0, time_step=1e-4,
                  bodies=scene.bodies, loads=scene.loads, joints=joints)
    trajectory = create("default").run(scene, RunSettings(record_every=10))
    angle = metrics.relative_angle(trajectory, 0, 1, (0.0, 0.0, 1.0))
    # Released at 0 with the rest angle at 0.1: phi = 0.1 (1 - cos(omega t)).
    omega = math.sqrt(k / inertia_z)
    expected = 0.1 * (1.0 - np.cos(omega * trajectory.times))
    # Semi-implicit Euler, omega dt = 3e-4, 2 s: phase error ~ 1e-4 of the amplitude.
    assert np.max(np.abs(angle - expected)) < 1e-4
    detail = "joint stiffness" if joined else "explicit moment"
    assert detail in create("default").capabilities(scene)["torsional_springs"].detail


def test_clearance_joint_forces_are_reported_on_its_own_pairs():
    scene = get_scene("clearance-pendulum", initial_angle=0.0)
    trajectory = create("tuned").run(scene, RunSettings(horizon=0.5))
    names = trajectory.contact_names
    rings = [names.index("pivot.ring_bottom"), names.index("pivot.ring_top")]
    flanges = [k for k, name in enumerate(names) if name.startswith("pivot.flange")]
    assert len(flanges) == 8  # four quarter arcs of each end face against its flange
    # Hanging at rest: the two bearing rings carry the weight; the force is the one on body
    # B of each pair, the journal's ground (-weight); the flanges carry nothing.
    total = trajectory.contact_force[-1, rings].sum(axis=0)
    assert total == pytest.approx([0.0, 0.0, -G], abs=1e-6 * G)
    assert np.all(trajectory.contact_normal_force[-1, flanges] == 0.0)
    excess = metrics.clearance_motion(scene, trajectory).excess
    # Soft contact with solref (2 dt, 1) at dt 1e-3: the journal sits a few micrometres
    # into the ring at rest (bound: 1 % of the 0.1 mm clearance).
    assert excess[-1, 0] < 1e-2 * scene.clearance_joints[0].radial_clearance


def test_energy_expectation_guard_states_when_it_is_off():
    trajectory = create("default").run(get_scene("slider-crank"), RunSettings(horizon=0.01))
    assert any("energy guard off" in note for note in trajectory.metadata["guards"])
    trajectory = create("default").run(get_scene("pendulum"), RunSettings(horizon=0.01))
    assert any("energy guard on" in note for note in trajectory.metadata["guards"])


def test_scene_with_an_energy_expectation_is_checked_by_the_shared_evaluator():
    scene = Scene(name="drop", horizon=0.3, bodies=(
        Body("ground", motion=Motion.FIXED, shapes=(Plane("floor"),)),
        Body("ball", mass=1.0, inertia=solid_sphere(1.0, 0.1), position=(0.0, 0.0, 0.3),
             shapes=(Sphere("s", radius=0.1),))),
        contacts=(ContactPair("c", body_a="ground", shape_a="floor", body_b="ball",
                              shape_b="s", restitution=0.5),),
        expectations=(Expectation("energy", kind="energy_non_increasing"),))
    trajectory = create("tuned").run(scene)
    assert trajectory.status is RunStatus.OK
    assert trajectory.energy_max_gain < 0.1
