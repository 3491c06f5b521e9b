"""MuJoCo adapter on the C-60: every feature mapped (approximations stated), bores as rings of
boxes within their stated radius error, law loads equal to the reference's own evaluation, and
short runs that return a finite trajectory or a diverged status."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from clearbench.adapters.base import RunSettings, Support
from clearbench.adapters.mujoco.build import build_model
from clearbench.adapters.mujoco.engine import create
from clearbench.adapters.mujoco.geometry import (
    bore_piece_count,
    bore_radius_error,
    shape_geoms,
)
from clearbench.adapters.mujoco.run import Runner
from clearbench.adapters.mujoco.settings import resolve_settings
from clearbench.adapters.trajectory import RunStatus
from clearbench.harness.measure import series as metrics
from clearbench.kernels.quaternion import quat_from_axis_angle, quat_to_matrix
from clearbench.ref_solver.forces import element_forces, no_angle_memory
from clearbench.ref_solver.scene_system import build_system
from clearbench.scenarios.library import get_scene, scene_names
from clearbench.scenarios.shapes import Bore

C60 = scene_names("c60")
APPROXIMATED = ("shape:bore", "shape:disc", "shape:rectangle", "angle_law_loads",
                "distance_law_loads")


@pytest.mark.parametrize("name", C60)
@pytest.mark.parametrize("preset", ["default", "tuned"])
def test_c60_capabilities_list_no_unsupported_feature_and_state_the_approximations(name, preset):
    capabilities = create(preset).capabilities(get_scene(name))
    unsupported = {f: c.detail for f, c in capabilities.items()
                   if c.support is Support.UNSUPPORTED}
    assert not unsupported, unsupported
    for feature in APPROXIMATED:
        assert capabilities[feature].support is Support.APPROXIMATED
    assert "explicit, one step lag" in capabilities["angle_law_loads"].detail
    assert "explicit, one step lag" in capabilities["distance_law_loads"].detail
    bore = capabilities["shape:bore"].detail
    # The plunger's sleeve: N, the radius error and the clearance it distorts are stated.
    assert "64 boxes" in bore and "radius error" in bore
    assert "pair plunger_bearing: radial clearance 0.099 mm" in bore
    assert "0.5 mm (its depth)" in capabilities["shape:rectangle"].detail


def test_a_polygon_error_larger_than_the_clearance_is_said_plainly():
    # 4 boxes on the plunger's sleeve: R (1/cos(pi/4) - 1) = 0.53 mm > the 0.099 mm clearance.
    scene = get_scene("c60-on")
    detail = create("tuned").capabilities(scene, {"bore_pieces": 4})["shape:bore"].detail
    assert "EXCEEDS THIS CLEARANCE 0.099 mm" in detail


def _ray_entry(origin, direction, centre, rotation, half) -> float:
    """Distance along the ray to where it enters the box (inf when it misses): slab method."""
    o = rotation.T @ (origin - centre)
    d = rotation.T @ direction
    with np.errstate(divide="ignore", invalid="ignore"):
        t1 = (-half - o) / d
        t2 = (half - o) / d
    near = np.where(d == 0, np.where(np.abs(o) <= half, -np.inf, np.inf), np.minimum(t1, t2))
    far = np.where(d == 0, np.where(np.abs(o) <= half, np.inf, -np.inf), np.maximum(t1, t2))
    enter, leave = near.max(), far.min()
    return enter if enter <= leave and leave >= 0 else math.inf


@pytest.mark.parametrize("start, end", [(0.0, 2.0 * math.pi), (2.1, 2.1 + 0.51)])
@pytest.mark.parametrize("pieces", [8, 64])
def test_bore_boxes_approximate_its_radius_within_the_stated_error(start, end, pieces):
    """Rays from the bore's axis hit the boxes between R and R + the stated error, at every
    angle of the bore and every height: the inner faces are tangent to the circle (distance R
    at a face's middle) and a ray at angle phi from a face's middle meets it at R / cos(phi),
    |phi| <= step / 2, so the error is at most R (1/cos(step/2) - 1), reached at the corners."""
    settings = resolve_settings("tuned", {"bore_pieces": pieces})
    radius, half_length = 1.29, 5.0
    bore = Bore("sleeve", position=(0.3, -0.2, 1.0),
                orientation=tuple(quat_from_axis_angle(np.array([1.0, 2.0, 0.5]) / math.sqrt(
                    5.25), 0.7)), radius=radius, half_length=half_length, start_angle=start,
                end_angle=end)
    scene = get_scene("c60-on")
    geoms, info = shape_geoms(scene, "frame", bore, settings, length_scale=10.0)
    count = bore_piece_count(bore, settings)
    assert len(geoms) == count == info.pieces
    error = bore_radius_error(bore, settings)
    step = (end - start) / count
    assert error == pytest.approx(radius * (1.0 / math.cos(0.5 * step) - 1.0), rel=1e-15)
    frame = quat_to_matrix(np.asarray(bore.orientation))
    centre = np.asarray(bore.position)
    boxes = [(np.asarray(g.position), quat_to_matrix(np.asarray(g.orientation)),
              np.asarray(g.size))
             for g in geoms]
    assert all(g.kind == "box" for g in geoms)
    # Angles of every box's middle and corners, and between them; heights over the length.
    angles = np.concatenate([start + step * np.arange(count + 1),
                             start + step * (np.arange(count) + 0.5),
                             np.linspace(start, end, 7 * count + 3)])
    reach = []
    for z in (-0.99 * half_length, 0.0, 0.99 * half_length):
        origin = centre + frame @ np.array([0.0, 0.0, z])
        for angle in angles:
            direction = frame @ np.array([math.cos(angle), math.sin(angle), 0.0])
            reach.append(min(_ray_entry(origin, direction, *box) for box in boxes))
    reach = np.array(reach)
    # Every ray meets a box (no gap between pieces); round-off of the box poses: 1e-12 of R.
    assert np.isfinite(reach).all()
    assert reach.min() >= radius - 1e-12 * radius
    assert reach.max() <= radius + error + 1e-12 * radius
    # The bound is attained at the corners (the first angles sampled are the corners).
    assert reach.max() == pytest.approx(radius + error, rel=1e-12)


def _perturbed_model(scene, seed: int = 3):
    """The C-60 built in MuJoCo (SI inside), every moving body turned by up to 0.2 rad and
    moved by up to 0.3 mm from the ON pose: a configuration unlike the initial one."""
    settings = resolve_settings("tuned")
    internal = create().internal_scene(scene, settings)
    built = build_model(internal, settings, 1e-6)
    model, data = built.model, built.data
    rng = np.random.default_rng(seed)
    for j in range(model.njnt):
        address = int(model.jnt_qposadr[j])
        if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE:
            data.qpos[address:address + 3] += rng.uniform(-3e-4, 3e-4, 3)
            turn = quat_from_axis_angle(_unit(rng.normal(size=3)), rng.uniform(-0.2, 0.2))
            quaternion = np.empty(4)
            mujoco.mju_mulQuat(quaternion, data.qpos[address + 3:address + 7], turn)
            data.qpos[address + 3:address + 7] = quaternion
    mujoco.mj_kinematics(model, data)
    return built


def _unit(v):
    return v / np.linalg.norm(v)


def test_law_loads_equal_the_reference_force_evaluation_at_the_same_state():
    scene = get_scene("c60-on")  # mm, g, ms: forces in N, moments in N mm
    built = _perturbed_model(scene)
    data = built.data
    wrench = built.law_forces.wrenches(data)  # SI: N and N m about the centre of mass, world
    # The reference's own system, in the scene's units, at the same configuration.
    system = build_system(scene)
    ids = np.array([built.model.body(name).id for name in system.body_names])
    x = data.xipos[ids] * 1e3  # m -> mm
    rotation = data.xmat[ids].reshape(-1, 3, 3).copy()
    expected = np.zeros((len(ids), 6))
    zeros = np.zeros_like(x)
    # springs_only skips the time-switched moment; the C-60 has no other spring: only laws.
    element_forces(0.0, x, rotation, zeros, zeros, system.force_kind, system.force_body_a,
                   system.force_body_b, system.force_parameters,
                   no_angle_memory(system.force_kind.shape[0]), True, expected)
    moment_world = np.einsum("bij,bj->bi", rotation, expected[:, 3:])
    scale = np.abs(expected).max()
    assert scale > 1.0  # the laws act (N, N mm): the comparison is not of zeros
    # Same function, same state: equal up to the round-off of the mm <-> m rescaling of the
    # scene's parameters and positions (about 1e-15 relative, a few operations deep).
    assert np.allclose(wrench[:, :3], expected[:, :3], rtol=0, atol=1e-12 * scale)
    assert np.allclose(wrench[:, 3:] * 1e3, moment_world, rtol=0, atol=1e-12 * scale)


def test_the_run_loop_applies_the_law_loads_and_the_moment_every_step():
    scene = get_scene("c60-on")
    settings = resolve_settings("tuned")
    built = _perturbed_model(scene)
    runner = Runner(create().internal_scene(scene, settings), built, settings, steps=1,
                    record_every=1)
    mujoco.mj_step1(built.model, built.data)
    runner.apply_loads()
    expected = built.law_forces.wrenches(built.data)
    bar = built.model.body("tripping_bar").id
    row = list(built.law_forces.body_ids).index(bar)
    # The tripping-bar moment: -15 N mm about world z for t < 1 ms, i.e. -0.015 N m.
    expected[row, 5] += -0.015
    applied = built.data.xfrc_applied[built.law_forces.body_ids]
    # The same numbers summed in another order: round-off of the largest wrench.
    assert np.allclose(applied, expected, rtol=0, atol=1e-12 * np.abs(expected).max())


def test_short_c60_on_run_stays_assembled_in_the_tuned_preset():
    scene = get_scene("c60-on", horizon=1.0)
    trajectory = create("tuned").run(scene, RunSettings(horizon=1.0, record_every=10))
    assert trajectory.status is RunStatus.OK, trajectory.message
    assert np.isfinite(trajectory.positions).all() and np.isfinite(trajectory.velocities).all()
    depth = metrics.penetration(scene, trajectory)
    # Measured 1.0 um with solref (2 dt, 1): well below the smallest joint clearance of the
    # C-60 (6 um at the needle's S3 bearing), so the mechanism has not come apart.
    assert depth.max() < 6e-3
    names = trajectory.contact_names
    latch = [i for i, n in enumerate(names) if n.startswith(("Hook_Tbar_C4", "Tbar_Hook_C5"))]
    c7 = names.index("Mcontact_Fcontact_bot_1_C7")
    # Still latched and closed at 1 ms: the hook's latch and the main contact carry force
    # (measured FC-1 7.3 N; the reference study's figure for this preload is 7.35 N).
    assert trajectory.contact_normal_force[-1, latch].sum() > 0.0
    assert 5.0 < trajectory.contact_normal_force[-1, c7] < 10.0


def test_short_c60_on_run_in_the_default_preset_is_finite_or_diverged():
    # MuJoCo's default contacts (timeconst 20 ms) are soft for a mechanism of ms and mm: it
    # sinks through its joints (measured 1.3 mm in 1 ms). A diverged status is a valid outcome.
    scene = get_scene("c60-on", horizon=0.2)
    trajectory = create("default").run(scene, RunSettings(horizon=0.2, record_every=10))
    assert trajectory.status in (RunStatus.OK, RunStatus.DIVERGED), trajectory.message
    if trajectory.status is RunStatus.OK:
        assert np.isfinite(trajectory.positions).all()
        assert np.isfinite(trajectory.velocities).all()
