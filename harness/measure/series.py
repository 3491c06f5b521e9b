"""Per-sample metric kernels, computed from a trajectory and its scene with the shared
geometry (never from an engine's own report of its penetration or energy).

Every metric takes the scene (as the engine was given it) and a :class:`Trajectory` and
returns arrays over the recorded samples, in the scene's units. The scales the metrics are
judged against (:func:`shape_size`, :func:`body_size`, :func:`energy_scale`) are here too.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from clearbench.adapters.trajectory import Trajectory
from clearbench.kernels.quaternion import (
    quat_conjugate_batch,
    quat_multiply_batch,
    quat_normalize_batch,
    quat_rotate_batch,
    quat_to_matrix_batch,
)
from clearbench.scenarios.bodies import Motion
from clearbench.scenarios.energy import Energy, mechanical_energy
from clearbench.scenarios.features import LOAD_FEATURES, WORK_FEATURES
from clearbench.scenarios.geometry import ring_encloses_axis, smallest_gaps
from clearbench.scenarios.loads import (
    LinearSpringDamper,
    TorsionalSpringDamper,
)
from clearbench.scenarios.outputs import BodyAngle, ContactForce, PointDistance, PointPosition
from clearbench.scenarios.scales import (
    body_size,
    contact_feature_sizes,
    scene_size,
    shape_dimensions,
)
from clearbench.scenarios.scene import Scene


def _poses(trajectory: Trajectory, body: int) -> tuple[np.ndarray, np.ndarray]:
    return trajectory.positions[:, body], quat_normalize_batch(trajectory.orientations[:, body])


#: The last (scene, trajectory, gaps) of :func:`contact_gaps`: a run's measurement asks for
#: the same gaps several times (penetration, contact energy, contact-free samples) and they cost
#: one geometry call per pair and sample.
_LAST_GAPS: list = [None, None, None]


def _pair_shapes(scene: Scene):
    """Per contact pair of ``scene.expanded``: (contact, body index A, shape A, body index B,
    shape B, encloses). ``encloses`` is True for a ring around a journal (a bearing ring of a
    clearance joint, a C-60 ring on its pin): at the scene's initial configuration the
    cylinder's axis crosses the ring inside it (:func:`ring_encloses_axis`)."""
    expanded = scene.expanded
    index = {b.name: i for i, b in enumerate(expanded.bodies)}
    for contact in expanded.contacts:
        a, b = index[contact.body_a], index[contact.body_b]
        body_a, body_b = expanded.bodies[a], expanded.bodies[b]
        shape_a, shape_b = body_a.shape(contact.shape_a), body_b.shape(contact.shape_b)
        encloses = ring_encloses_axis(shape_a, (body_a.position, body_a.orientation),
                                      shape_b, (body_b.position, body_b.orientation))
        yield contact, a, shape_a, b, shape_b, bool(encloses)


def contact_gaps(scene: Scene, trajectory: Trajectory) -> np.ndarray:
    """Smallest gap of each contact pair (explicit and clearance-joint pairs), minus its offset,
    (T, npair) [L]; +inf where a pair yields no candidate. Read-only; computed once per
    (scene, trajectory) pair in a row."""
    if _LAST_GAPS[0] is scene and _LAST_GAPS[1] is trajectory:
        return _LAST_GAPS[2]
    out = np.full((len(trajectory.times), len(scene.expanded.contacts)), np.inf)
    for k, (contact, a, shape_a, b, shape_b, encloses) in enumerate(_pair_shapes(scene)):
        out[:, k] = smallest_gaps(shape_a, _poses(trajectory, a), shape_b,
                                  _poses(trajectory, b), encloses) - contact.offset
    out.flags.writeable = False
    _LAST_GAPS[:] = [scene, trajectory, out]
    return out


#: Most interpolated configurations tested between two recorded samples of one pair.
MAX_SWEPT_SUBSTEPS = 1000


def _rotation_angles(orientations: np.ndarray) -> np.ndarray:
    """(T - 1, nb) angle of the rotation of each body between consecutive samples [rad]."""
    q = quat_normalize_batch(orientations)
    dot = np.abs(np.sum(q[1:] * q[:-1], axis=-1))
    return 2.0 * np.arccos(np.clip(dot, 0.0, 1.0))


def _shape_reach(shape, fallback: float) -> float:
    """Farthest a point of the shape can be from its frame origin [L] (``fallback``, the
    scene's size, for an unbounded plane)."""
    dimensions = [float(d) for d in shape_dimensions(shape)]
    return float(np.linalg.norm(dimensions)) if dimensions else fallback


def _interpolated_poses(com0, com1, q0, q1, local_com, s: np.ndarray):
    """Body-frame poses (positions (m, 3), quaternions (m, 4)) at the fractions ``s`` (m,) of
    the straight path between two samples: centre of mass moved linearly, orientation
    normalised-linearly (nlerp on the short arc)."""
    q1 = q1 if float(np.dot(q0, q1)) >= 0.0 else -q1
    s = s[:, None]
    q = (1.0 - s) * q0 + s * q1
    q = q / np.linalg.norm(q, axis=1, keepdims=True)
    com = (1.0 - s) * com0 + s * com1
    return com - quat_rotate_batch(q, np.broadcast_to(local_com, com.shape)), q


def swept_penetration(scene: Scene, trajectory: Trajectory) -> np.ndarray:
    """Largest penetration max(0, -gap) of each contact pair on the straight path between two
    consecutive recorded samples, (npair,) [L] (0 where no interval needs testing).

    A body that crosses a thin shape between two samples (a ball through a plate) has a
    positive gap at both; this swept test catches it. For each pair and interval it bounds
    how far any point of either shape moves (shape origin displacement plus the shape's reach
    times its rotation angle); an interval is tested when that motion exceeds half the pair's
    smallest feature (:func:`~clearbench.scenarios.scales.contact_feature_sizes`: a slower
    crossing shows on a sample) and exceeds the smaller end gap (otherwise the shapes cannot
    meet in between). It is then cut into steps of at most half that feature (at most
    :data:`MAX_SWEPT_SUBSTEPS`), the poses interpolated by :func:`_interpolated_poses`.
    """
    gaps = contact_gaps(scene, trajectory)
    features = contact_feature_sizes(scene)
    out = np.zeros(len(features))
    count = len(trajectory.times)
    if count < 2 or not len(features):
        return out
    expanded = scene.expanded
    size = scene_size(scene)
    angles = _rotation_angles(trajectory.orientations)
    q = quat_normalize_batch(trajectory.orientations)
    local_coms = [np.asarray(b.center_of_mass, dtype=float) for b in expanded.bodies]
    coms = trajectory.positions + quat_rotate_batch(
        q, np.broadcast_to(np.array(local_coms), q.shape[:-1] + (3,)))
    for k, (contact, a, shape_a, b, shape_b, encloses) in enumerate(_pair_shapes(scene)):
        feature = float(features[k])
        if not math.isfinite(feature) or feature <= 0.0:
            continue
        motion = np.zeros(count - 1)
        for body, shape in ((a, shape_a), (b, shape_b)):
            origin = trajectory.positions[:, body] + quat_rotate_batch(
                q[:, body], np.broadcast_to(np.asarray(shape.position, dtype=float),
                                            (count, 3)))
            motion += np.linalg.norm(np.diff(origin, axis=0), axis=1)
            motion += _shape_reach(shape, size) * angles[:, body]
        ends = np.minimum(gaps[:-1, k], gaps[1:, k])
        for i in np.nonzero((motion > 0.5 * feature) & (ends < motion))[0]:
            steps = min(MAX_SWEPT_SUBSTEPS, math.ceil(motion[i] / (0.5 * feature)))
            if steps < 2:
                continue
            fractions = np.arange(1, steps) / steps
            poses_a = _interpolated_poses(coms[i, a], coms[i + 1, a], q[i, a], q[i + 1, a],
                                          local_coms[a], fractions)
            poses_b = _interpolated_poses(coms[i, b], coms[i + 1, b], q[i, b], q[i + 1, b],
                                          local_coms[b], fractions)
            gaps_between = smallest_gaps(shape_a, poses_a, shape_b, poses_b,
                                         encloses) - contact.offset
            finite = gaps_between[np.isfinite(gaps_between)]
            if len(finite):
                out[k] = max(out[k], float(-finite.min()))
    return out


def penetration(scene: Scene, trajectory: Trajectory) -> np.ndarray:
    """Penetration max(0, -gap) of each contact pair, (T, npair) [L]."""
    gaps = contact_gaps(scene, trajectory)
    return np.maximum(0.0, -np.where(np.isfinite(gaps), gaps, 0.0))


def rebuild_overlaps(scene: Scene, trajectory: Trajectory) -> np.ndarray:
    """(npair,) how deep each pair's exact surfaces can overlap while the engine's rebuilt
    shapes only touch [L] (:attr:`Trajectory.rebuild_overlap`; 0 for a pair it models
    exactly)."""
    declared = trajectory.rebuild_overlap
    return np.array([float(declared.get(contact.name, 0.0))
                     for contact in scene.expanded.contacts])


def penetration_beyond_rebuild(scene: Scene, trajectory: Trajectory,
                               depth: np.ndarray | None = None) -> np.ndarray:
    """Penetration beyond the engine's rebuild overlap, max(0, depth - overlap) of each pair,
    (T, npair) [L]: the part of :func:`penetration` that the engine's approximation of the
    shapes (a ring of spheres, a bore's polygon lining) cannot explain. ``depth``: the
    penetration when already computed."""
    depth = penetration(scene, trajectory) if depth is None else depth
    return np.maximum(0.0, depth - rebuild_overlaps(scene, trajectory)[None, :])


@dataclass(frozen=True)
class ClearanceMotion:
    """Per clearance joint (T, nj): eccentricity of the journal in its bore at each bearing
    ring (the larger of the two) and its excess over the radial clearance [L]."""

    names: tuple
    eccentricity: np.ndarray
    excess: np.ndarray


def clearance_motion(scene: Scene, trajectory: Trajectory) -> ClearanceMotion:
    """Eccentricity = radial clearance - (ring gap), evaluated with the shared ring-journal
    gap, so that a tilted journal counts exactly; excess = max(0, eccentricity - clearance).

    With parallel axes the eccentricity is the distance of the journal axis from the bore
    axis at the ring; the ring's gap is signed as a ring that must enclose its journal
    (:func:`contact_gaps`), so the eccentricity is never negative and grows without bound as
    the journal leaves the bore (it is not capped at the journal radius)."""
    names = tuple(j.name for j in scene.clearance_joints)
    if not names:
        empty = np.zeros((len(trajectory.times), 0))
        return ClearanceMotion(names, empty, empty)
    gaps = contact_gaps(scene, trajectory)
    contact_names = [c.name for c in scene.expanded.contacts]
    ecc = np.zeros((len(trajectory.times), len(names)))
    for j, joint in enumerate(scene.clearance_joints):
        columns = [contact_names.index(f"{joint.name}.ring_{side}")
                   for side in ("bottom", "top")]
        ecc[:, j] = joint.radial_clearance - np.min(gaps[:, columns], axis=1)
    radial = np.array([j.radial_clearance for j in scene.clearance_joints])
    return ClearanceMotion(names, ecc, np.maximum(0.0, ecc - radial[None, :]))


@dataclass(frozen=True)
class JointViolation:
    """Per ideal joint (T, nj): distance between the two anchor points [L] and angle between
    the constrained directions [rad] (axis misalignment for revolute joints, relative rotation
    for prismatic and fixed joints)."""

    names: tuple
    distance: np.ndarray
    angle: np.ndarray


def _in_body_frame(body, world_point=None, world_direction=None) -> np.ndarray:
    """A world point or direction of the scene's initial configuration in ``body``'s frame
    (the body's pose as the scene describes it, not as an engine returned it)."""
    q = np.asarray(body.orientation, dtype=float)[None, :]
    q = quat_conjugate_batch(quat_normalize_batch(q))
    if world_point is not None:
        vector = np.asarray(world_point, dtype=float) - np.asarray(body.position, dtype=float)
    else:
        vector = np.asarray(world_direction, dtype=float)
    return quat_rotate_batch(q, vector[None, :])[0]


def joint_violation(scene: Scene, trajectory: Trajectory) -> JointViolation:
    """How far each ideal joint is from holding, on every sample.

    The joint's frame on each body comes from the scene: the anchor (and axis) are world
    values of the initial configuration, turned into each body's frame with the body's pose
    in the scene. An engine that starts a body elsewhere than the scene says (a wrong
    starting pose, bodies swapped) therefore shows as joint error from t = 0, where a frame
    taken from the trajectory's own first sample would read zero."""
    names = tuple(j.name for j in scene.joints)
    count = len(trajectory.times)
    distance = np.zeros((count, len(names)))
    angle = np.zeros((count, len(names)))
    for j, joint in enumerate(scene.joints):
        a = scene.body_index(joint.body_a)
        b = scene.body_index(joint.body_b)
        body_a, body_b = scene.bodies[a], scene.bodies[b]
        xa, qa = _poses(trajectory, a)
        xb, qb = _poses(trajectory, b)
        local_a = np.broadcast_to(_in_body_frame(body_a, world_point=joint.anchor), (count, 3))
        local_b = np.broadcast_to(_in_body_frame(body_b, world_point=joint.anchor), (count, 3))
        pa = xa + quat_rotate_batch(qa, local_a)
        pb = xb + quat_rotate_batch(qb, local_b)
        axis = np.asarray(getattr(joint, "axis", (0.0, 0.0, 1.0)), dtype=float)
        axis_a = quat_rotate_batch(qa, np.broadcast_to(
            _in_body_frame(body_a, world_direction=axis), (count, 3)))
        if joint.kind != "prismatic":
            distance[:, j] = np.linalg.norm(pb - pa, axis=1)
        else:
            d = pb - pa
            distance[:, j] = np.linalg.norm(d - np.sum(d * axis_a, axis=1)[:, None] * axis_a,
                                            axis=1)
        if joint.kind == "revolute":
            axis_b = quat_rotate_batch(qb, np.broadcast_to(
                _in_body_frame(body_b, world_direction=axis), (count, 3)))
            cross = np.linalg.norm(np.cross(axis_a, axis_b), axis=1)
            angle[:, j] = np.arctan2(cross, np.sum(axis_a * axis_b, axis=1))
        elif joint.kind in ("prismatic", "fixed"):
            qa0 = quat_normalize_batch(np.asarray(body_a.orientation, dtype=float)[None, :])
            qb0 = quat_normalize_batch(np.asarray(body_b.orientation, dtype=float)[None, :])
            relative0 = quat_multiply_batch(quat_conjugate_batch(qa0), qb0)
            relative = quat_multiply_batch(quat_conjugate_batch(qa), qb)
            error = quat_multiply_batch(relative, quat_conjugate_batch(
                np.broadcast_to(relative0, relative.shape)))
            angle[:, j] = 2.0 * np.arctan2(np.linalg.norm(error[:, 1:], axis=1),
                                           np.abs(error[:, 0]))
    return JointViolation(names, distance, angle)


def driver_deviation(scene: Scene, trajectory: Trajectory) -> np.ndarray:
    """|followed - prescribed| displacement of every driver's component since t = 0, (T, nd)
    [L for translations, rad for rotations]: the centre of mass along the driver's world axis,
    or the body's rotation about it (:func:`body_angle`), against
    :meth:`~clearbench.scenarios.drivers.Driver.displacement`."""
    out = np.zeros((len(trajectory.times), len(scene.drivers)))
    com = centre_of_mass_positions(scene, trajectory)
    for d, driver in enumerate(scene.drivers):
        b = scene.body_index(driver.body)
        if driver.is_rotation:
            axis = np.zeros(3)
            axis[driver.axis_index] = 1.0
            followed = body_angle(trajectory, b, axis)
        else:
            followed = com[:, b, driver.axis_index] - com[0, b, driver.axis_index]
        prescribed = np.asarray(driver.displacement(trajectory.times - trajectory.times[0]),
                                dtype=float)
        out[:, d] = np.abs(followed - prescribed)
    return out


def quaternion_norm_error(trajectory: Trajectory) -> np.ndarray:
    """| |p| - 1 | of every body, (T, nb), as the engine returned it (not renormalised)."""
    return np.abs(np.linalg.norm(trajectory.orientations, axis=2) - 1.0)


def centre_of_mass_positions(scene: Scene, trajectory: Trajectory) -> np.ndarray:
    """(T, nb, 3) world centre-of-mass positions [L]."""
    com = np.array([b.center_of_mass for b in scene.bodies], dtype=float)
    q = quat_normalize_batch(trajectory.orientations)
    return trajectory.positions + quat_rotate_batch(q, np.broadcast_to(com, q.shape[:-1] + (3,)))


def displacement(scene: Scene, trajectory: Trajectory, body: str) -> np.ndarray:
    """Distance of the body's centre of mass from its initial position, (T,) [L]."""
    com = centre_of_mass_positions(scene, trajectory)[:, scene.body_index(body)]
    return np.linalg.norm(com - com[0], axis=1)


@dataclass(frozen=True)
class Stiction:
    """Largest displacement [L] and mean creep rate [L/T] of a body that must stick over a
    window (least-squares slope of the displacement)."""

    displacement: float
    creep_rate: float


def stiction(scene: Scene, trajectory: Trajectory, body: str, start: float = 0.0,
             end: float | None = None) -> Stiction:
    times = trajectory.times
    window = (times >= start) & (times <= (times[-1] if end is None else end))
    moved = displacement(scene, trajectory, body)[window]
    t = times[window]
    if not len(t):
        # No sample in the window (a run shorter than its start): nothing to judge.
        return Stiction(math.nan, math.nan)
    moved = moved - moved[0]
    rate = float(np.polyfit(t, moved, 1)[0]) if len(t) > 1 else 0.0
    return Stiction(float(np.max(np.abs(moved))) if len(moved) else 0.0, rate)


def contact_energy(scene: Scene, trajectory: Trajectory) -> np.ndarray:
    """Elastic energy stored in the contacts, (T,) [M L^2 / T^2]: per pair, half the normal
    force times the penetration, the work of a linear contact spring pressed to that depth,
    summed over the pairs.

    The force is the engine's (``contact_normal_force``, the mean over the recorded step, summed
    over the pair's points), the penetration the harness's (deepest point of the pair). A rigid
    engine has no penetration and so no stored energy; a compliant one stores, at the deepest
    moment of an impact, the kinetic energy it took. Engines with rigid contacts (metadata
    ``rigid_contacts``: the reference and Siconos) store none. Damping in the engine's force law, a
    nonlinear law, and a pair loaded on several points unevenly make this an estimate; a
    pulling (negative) normal force stores nothing."""
    count = len(trajectory.times)
    if not scene.all_contacts or trajectory.contact_normal_force.shape != (
            count, len(scene.expanded.contacts)):
        return np.zeros(count)
    if trajectory.rigid_contacts:
        # A nonsmooth engine's recorded force is an impulse over the step: times the
        # penetration of a step that captured an impact, it is no stored energy (it read as a
        # 34 % energy gain of Siconos's bouncing ball, whose contact-free energy is exact).
        return np.zeros(count)
    depth = penetration(scene, trajectory)
    force = np.maximum(0.0, np.nan_to_num(trajectory.contact_normal_force, nan=0.0))
    return 0.5 * np.sum(force * depth, axis=1)


def energy(scene: Scene, trajectory: Trajectory) -> Energy:
    """Energy of every sample, (T,) each [M L^2 / T^2]
    (:func:`~clearbench.scenarios.energy.mechanical_energy`, torsional springs at their
    :func:`relative_angle`), with the contacts' stored energy (:func:`contact_energy`)."""
    q = quat_normalize_batch(trajectory.orientations)

    def spring_points(load: LinearSpringDamper) -> tuple[np.ndarray, np.ndarray]:
        a, b = scene.body_index(load.body_a), scene.body_index(load.body_b)
        return (trajectory.positions[:, a] + quat_rotate_batch(q[:, a], np.asarray(load.point_a)),
                trajectory.positions[:, b] + quat_rotate_batch(q[:, b], np.asarray(load.point_b)))

    torsion = {load.name: relative_angle(trajectory, scene.body_index(load.body_a),
                                         scene.body_index(load.body_b), load.axis)
               for load in scene.loads if isinstance(load, TorsionalSpringDamper)}
    parts = mechanical_energy(scene, centre_of_mass_positions(scene, trajectory),
                              trajectory.velocities, trajectory.angular_velocities,
                              spring_points, torsion)
    return replace(parts, contacts=contact_energy(scene, trajectory))


def non_conservative_loads(scene: Scene) -> tuple[str, ...]:
    """Names of the loads whose work :func:`energy` cannot count (those of the
    :data:`~clearbench.scenarios.features.WORK_FEATURES`: law loads, point forces and moments):
    an energy expectation is meaningless while they act."""
    return tuple(load.name for load in scene.loads if LOAD_FEATURES[load.kind] in WORK_FEATURES)


def energy_balance_applies(scene: Scene) -> bool:
    """True when :func:`energy` counts every energy the scene exchanges: no driver, point
    force, moment or law load (:data:`~clearbench.scenarios.features.WORK_FEATURES`). Then the
    energy may only decrease (friction, dampers and restitution e <= 1 dissipate)."""
    return not scene.features & set(WORK_FEATURES)


def relative_angle(trajectory: Trajectory, body_a: int, body_b: int, axis) -> np.ndarray:
    """Unwrapped rotation of B relative to A about ``axis`` (world, fixed in A at t = 0) since
    t = 0, (T,) [rad]."""
    q = quat_normalize_batch(trajectory.orientations)
    qa, qb = q[:, body_a], q[:, body_b]
    relative = quat_multiply_batch(quat_conjugate_batch(qa), qb)
    change = quat_multiply_batch(quat_conjugate_batch(relative[0]), relative)
    axis_a = quat_rotate_batch(quat_conjugate_batch(qa[0]), np.asarray(axis, dtype=float))
    twist = 2.0 * np.arctan2(change[:, 1:] @ axis_a, change[:, 0])
    return np.unwrap(twist)


def body_angle(trajectory: Trajectory, body: int, axis) -> np.ndarray:
    """Unwrapped rotation of a body about a world axis since t = 0, (T,) [rad]."""
    q = quat_normalize_batch(trajectory.orientations[:, body])
    change = quat_multiply_batch(q, quat_conjugate_batch(q[0]))
    twist = 2.0 * np.arctan2(change[:, 1:] @ np.asarray(axis, dtype=float), change[:, 0])
    return np.unwrap(twist)


def output_values(scene: Scene, trajectory: Trajectory) -> dict[str, np.ndarray]:
    """Every named output of the scene, (T,) each, in the output's unit."""
    out: dict[str, np.ndarray] = {}
    q = quat_normalize_batch(trajectory.orientations)
    components = {"x": 0, "y": 1, "z": 2}

    def point(body: str, local) -> np.ndarray:
        b = scene.body_index(body)
        return trajectory.positions[:, b] + quat_rotate_batch(q[:, b], np.asarray(local))

    for output in scene.outputs:
        if isinstance(output, PointPosition):
            p = point(output.body, output.point)
            value = np.linalg.norm(p, axis=1) if output.component == "norm" \
                else p[:, components[output.component]]
        elif isinstance(output, PointDistance):
            d = point(output.body_b, output.point_b) - point(output.body_a, output.point_a)
            value = np.linalg.norm(d, axis=1) if output.component == "norm" \
                else d[:, components[output.component]]
        elif isinstance(output, BodyAngle):
            value = body_angle(trajectory, scene.body_index(output.body), output.axis)
        elif isinstance(output, ContactForce):
            k = trajectory.contact_index(output.contact)
            if output.component == "normal":
                value = trajectory.contact_normal_force[:, k]
            else:
                total = trajectory.contact_force[:, k]
                normal = trajectory.contact_normal_force[:, k]
                value = np.sqrt(np.maximum(0.0, np.sum(total**2, axis=1) - normal**2))
        else:  # pragma: no cover
            raise TypeError(f"unhandled output kind {output.kind!r}")
        out[output.name] = value
    return out


def rotation_matrices(trajectory: Trajectory) -> np.ndarray:
    """(T, nb, 3, 3) body-to-world rotations."""
    return quat_to_matrix_batch(quat_normalize_batch(trajectory.orientations))


def energy_scale(scene: Scene, energy: Energy) -> float:
    """Energy a run is judged against [M L^2/T^2]: the largest of the peak kinetic energy, the
    range of potential energy, and the sum of m |g| size over the moving bodies."""
    gravity = float(np.linalg.norm(scene.gravity))
    weight = sum(b.mass * gravity * body_size(b) for b in scene.bodies
                 if b.motion is not Motion.FIXED)
    potential = energy.gravity + energy.springs
    scale = max(float(np.max(energy.kinetic)), float(np.ptp(potential)), weight)
    return scale if scale > 0 else 1.0


def contact_free(scene: Scene, trajectory: Trajectory) -> np.ndarray:
    """(T,) True where every contact pair is strictly open (gap > 0)."""
    if not scene.all_contacts:
        return np.ones(len(trajectory.times), dtype=bool)
    return np.all(contact_gaps(scene, trajectory) > 0.0, axis=1)


def _largest_rise(values: Energy) -> float:
    total = values.total
    return float(np.max(total - np.minimum.accumulate(total)))


def energy_growth(scene: Scene, trajectory: Trajectory,
                  values: Energy | None = None) -> tuple[float, float]:
    """Largest rise of the total energy, contact energy included (:func:`contact_energy`),
    above its running minimum, on every sample, and the energy scale it is judged against
    (:func:`energy_scale`), both [M L^2/T^2]. A compliant engine stores the energy of an
    elastic impact in the contact and gives it back: counted, that is no gain."""
    values = values if values is not None else energy(scene, trajectory)
    return _largest_rise(values), energy_scale(scene, values)


def energy_growth_contact_free(scene: Scene, trajectory: Trajectory,
                               values: Energy | None = None) -> tuple[float, float]:
    """The cross-check of :func:`energy_growth` that needs no contact force: the same rise
    and scale without the contact energy, on the samples where every contact is open (all
    samples when fewer than two are). It misses growth during contact, and a scene that never
    opens every contact (a row of balls on a floor) is measured on every sample without the
    energy stored in its contacts."""
    values = values if values is not None else energy(scene, trajectory)
    free = contact_free(scene, trajectory)
    values = Energy(values.kinetic, values.gravity, values.springs)
    if np.count_nonzero(free) >= 2:
        values = values.at(free)
    return _largest_rise(values), energy_scale(scene, values)


def energy_loss(scene: Scene, trajectory: Trajectory,
                values: Energy | None = None) -> tuple[float, float]:
    """Largest fall of the total energy below its initial value [M L^2/T^2], and the energy
    scale (:func:`energy_scale`). Judged on the samples where every contact is open when
    there are at least two (the mechanical energy is then exact, with no estimate of the
    energy stored in a compliant contact: measured, MuJoCo's elastic bouncing ball reads a
    1.7 % fall mid-contact with the estimate and 0.04 % at its end), else on every sample
    with the contact energy (a row of balls resting on a floor never opens every contact)."""
    values = values if values is not None else energy(scene, trajectory)
    total = values.total
    free = contact_free(scene, trajectory)
    if np.count_nonzero(free) >= 2:
        mechanical = Energy(values.kinetic, values.gravity, values.springs).total
        fall = float(total[0] - np.min(mechanical[free]))
    else:
        fall = float(total[0] - np.min(total))
    return max(fall, 0.0), energy_scale(scene, values)
