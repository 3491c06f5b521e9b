"""Per-sample metric kernels, computed from a trajectory and its scene with the shared
geometry (never from an engine's own report of its penetration or energy).

Every metric takes the scene (as the engine was given it) and a :class:`Trajectory` and
returns arrays over the recorded samples, in the scene's units. The scales the metrics are
judged against (:func:`shape_size`, :func:`body_size`, :func:`energy_scale`) are here too.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

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
from clearbench.scenarios.geometry import contacts_between
from clearbench.scenarios.loads import (
    AngleLawLoad,
    DistanceLawLoad,
    LinearSpringDamper,
    Moment,
    PointForce,
    TorsionalSpringDamper,
)
from clearbench.scenarios.outputs import BodyAngle, ContactForce, PointDistance, PointPosition
from clearbench.scenarios.scales import body_size
from clearbench.scenarios.scene import Scene


def _poses(trajectory: Trajectory, body: int) -> tuple[np.ndarray, np.ndarray]:
    return trajectory.positions[:, body], quat_normalize_batch(trajectory.orientations[:, body])


def contact_gaps(scene: Scene, trajectory: Trajectory) -> np.ndarray:
    """Smallest gap of each contact pair (explicit and clearance-joint pairs), minus its offset,
    (T, npair) [L]; +inf where a pair yields no candidate."""
    expanded = scene.expanded
    index = {b.name: i for i, b in enumerate(expanded.bodies)}
    out = np.full((len(trajectory.times), len(expanded.contacts)), np.inf)
    for k, contact in enumerate(expanded.contacts):
        body_a = expanded.bodies[index[contact.body_a]]
        body_b = expanded.bodies[index[contact.body_b]]
        shape_a = body_a.shape(contact.shape_a)
        shape_b = body_b.shape(contact.shape_b)
        xa, qa = _poses(trajectory, index[contact.body_a])
        xb, qb = _poses(trajectory, index[contact.body_b])
        for t in range(len(trajectory.times)):
            result = contacts_between(shape_a, (xa[t], qa[t]), shape_b, (xb[t], qb[t]))
            if len(result.gap):
                out[t, k] = float(np.min(result.gap)) - contact.offset
    return out


def penetration(scene: Scene, trajectory: Trajectory) -> np.ndarray:
    """Penetration max(0, -gap) of each contact pair, (T, npair) [L]."""
    gaps = contact_gaps(scene, trajectory)
    return np.maximum(0.0, -np.where(np.isfinite(gaps), gaps, 0.0))


@dataclass(frozen=True)
class ClearanceMotion:
    """Per clearance joint (T, nj): eccentricity of the bore centre from the journal axis at
    each bearing ring (the larger of the two) and its excess over the radial clearance [L]."""

    names: tuple
    eccentricity: np.ndarray
    excess: np.ndarray


def clearance_motion(scene: Scene, trajectory: Trajectory) -> ClearanceMotion:
    """Eccentricity = radial clearance - (ring gap), evaluated with the shared ring-journal
    gap, so that a tilted journal counts exactly; excess = max(0, eccentricity - clearance)."""
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


def joint_violation(scene: Scene, trajectory: Trajectory) -> JointViolation:
    names = tuple(j.name for j in scene.joints)
    count = len(trajectory.times)
    distance = np.zeros((count, len(names)))
    angle = np.zeros((count, len(names)))
    for j, joint in enumerate(scene.joints):
        a = scene.body_index(joint.body_a)
        b = scene.body_index(joint.body_b)
        xa, qa = _poses(trajectory, a)
        xb, qb = _poses(trajectory, b)
        qa0, qb0 = qa[0], qb[0]
        anchor = np.asarray(joint.anchor, dtype=float)
        local_a = quat_rotate_batch(quat_conjugate_batch(qa0), anchor - xa[0])
        local_b = quat_rotate_batch(quat_conjugate_batch(qb0), anchor - xb[0])
        pa = xa + quat_rotate_batch(qa, local_a)
        pb = xb + quat_rotate_batch(qb, local_b)
        if joint.kind != "prismatic":
            distance[:, j] = np.linalg.norm(pb - pa, axis=1)
        else:
            axis_a = quat_rotate_batch(qa, quat_rotate_batch(quat_conjugate_batch(qa0),
                                                             np.asarray(joint.axis)))
            d = pb - pa
            distance[:, j] = np.linalg.norm(d - np.sum(d * axis_a, axis=1)[:, None] * axis_a,
                                            axis=1)
        if joint.kind == "revolute":
            axis = np.asarray(joint.axis, dtype=float)
            axis_a = quat_rotate_batch(qa, quat_rotate_batch(quat_conjugate_batch(qa0), axis))
            axis_b = quat_rotate_batch(qb, quat_rotate_batch(quat_conjugate_batch(qb0), axis))
            cross = np.linalg.norm(np.cross(axis_a, axis_b), axis=1)
            angle[:, j] = np.arctan2(cross, np.sum(axis_a * axis_b, axis=1))
        elif joint.kind in ("prismatic", "fixed"):
            relative0 = quat_multiply_batch(quat_conjugate_batch(qa0), qb0)
            relative = quat_multiply_batch(quat_conjugate_batch(qa), qb)
            error = quat_multiply_batch(relative, quat_conjugate_batch(relative0))
            angle[:, j] = 2.0 * np.arctan2(np.linalg.norm(error[:, 1:], axis=1),
                                           np.abs(error[:, 0]))
    return JointViolation(names, distance, angle)


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


@dataclass(frozen=True)
class Energy:
    """(T,) kinetic, gravitational potential and spring potential energy, and their total
    [M L^2 / T^2]. Time-switched forces, moments and drivers do work not counted here, and so
    do law loads (``angle_law``, ``distance_law``): their forces are not the gradient of a
    potential in general (a torsion law applied as a force on a body-fixed lever, a distance
    law pushing along a body axis), so no potential energy exists to count for them; see
    :func:`non_conservative_loads`."""

    kinetic: np.ndarray
    gravity: np.ndarray
    springs: np.ndarray

    @property
    def total(self) -> np.ndarray:
        return self.kinetic + self.gravity + self.springs


def energy(scene: Scene, trajectory: Trajectory) -> Energy:
    count = len(trajectory.times)
    kinetic = np.zeros(count)
    potential = np.zeros(count)
    com = centre_of_mass_positions(scene, trajectory)
    gravity = np.asarray(scene.gravity, dtype=float)
    for b, body in enumerate(scene.bodies):
        if body.motion is Motion.FIXED:
            continue
        v = trajectory.velocities[:, b]
        w = trajectory.angular_velocities[:, b]
        inertia = np.asarray(body.inertia, dtype=float)
        kinetic += 0.5 * body.mass * np.sum(v * v, axis=1)
        kinetic += 0.5 * np.einsum("ti,ij,tj->t", w, inertia, w)
        potential -= body.mass * com[:, b] @ gravity
    springs = np.zeros(count)
    q = quat_normalize_batch(trajectory.orientations)
    for load in scene.loads:
        if isinstance(load, LinearSpringDamper):
            a, b = scene.body_index(load.body_a), scene.body_index(load.body_b)
            pa = trajectory.positions[:, a] + quat_rotate_batch(q[:, a], np.asarray(load.point_a))
            pb = trajectory.positions[:, b] + quat_rotate_batch(q[:, b], np.asarray(load.point_b))
            stretch = np.linalg.norm(pb - pa, axis=1) - load.rest_length
            springs += load.preload * stretch + 0.5 * load.stiffness * stretch**2
        elif isinstance(load, TorsionalSpringDamper):
            phi = relative_angle(trajectory, scene.body_index(load.body_a),
                                 scene.body_index(load.body_b), load.axis)
            springs += load.preload * phi + 0.5 * load.stiffness * (phi - load.rest_angle) ** 2
    return Energy(kinetic, potential, springs)


def non_conservative_loads(scene: Scene) -> tuple[str, ...]:
    """Names of the loads whose work :func:`energy` cannot count (law loads, time-switched
    forces and moments): an energy expectation is meaningless while they act."""
    return tuple(load.name for load in scene.loads
                 if isinstance(load, AngleLawLoad | DistanceLawLoad | PointForce | Moment))


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


def energy_growth(scene: Scene, trajectory: Trajectory,
                  values: Energy | None = None) -> tuple[float, float]:
    """Largest rise of the total energy above its running minimum, and the energy scale it is
    judged against, both [M L^2/T^2] and both over the same samples.

    Measured on the samples where every contact is open when there are at least two of them:
    a compliant engine stores energy in a closed contact that :func:`energy` does not count
    (its contact potential), and gives it back, which would read as a gain; between contacts
    the count is complete. Scenes that never leave contact are measured on every sample.
    """
    values = values if values is not None else energy(scene, trajectory)
    free = contact_free(scene, trajectory)
    if np.count_nonzero(free) >= 2:
        values = Energy(values.kinetic[free], values.gravity[free], values.springs[free])
    total = values.total
    return float(np.max(total - np.minimum.accumulate(total))), energy_scale(scene, values)
