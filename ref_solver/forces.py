"""Applied forces: gravity and the force elements of a :class:`~.system.MultibodySystem`.

Generalised force per body, shape (nb, 6): force (3,) in world axes and torque (3,) in BODY axes
about the centre of mass. Gyroscopic terms are not included (the stepper treats them with a
momentum-conserving update). Parameter layout of ``force_parameters`` rows (points relative to
the centre of mass, body axes):

- linear spring: [0:3] point on A, [3:6] point on B, [6] stiffness, [7] damping,
  [8] rest length, [9] preload. Tension T = preload + k (L - L0) + c dL/dt pulls the points
  together.
- torsional spring: [0:3] axis in A's body axes, [3:6] reference vector in A, [6:9] the same
  reference vector in B (equal in world at t = 0), [9] stiffness, [10] damping, [11] rest angle,
  [12] preload. Moment on B about the axis: -(preload + k (phi - rest) + c dphi/dt), phi in
  (-pi, pi]; the opposite on A.
- point force: [0:3] point on the body, [3:6] force, [6] 0 world / 1 body axes, [7] start time,
  [8] end time (active start <= t < end).
- moment: [0:3] moment, [3] 0 world / 1 body axes, [4] start time, [5] end time.
- angle law (one element per application of a scene's law load; at most two law bodies, A and
  B, equal when the law has one body): [0:3] world axis, [3] stiffness, [4] offset, [5], [6]
  coefficients of theta(A) and theta(B); s = k (offset + c_A theta_A + c_B theta_B), theta the
  body's twist angle about the axis (2 atan2(a . vee(R - R^T), 1 + tr R), in (-pi, pi]) made
  continuous by ``angle_memory`` (see :func:`continuous_angle`).
- distance law: [0:3] point on A, [3:6] point on B, [17] stiffness, [18] rest length;
  s = k (rest - |p_B - p_A|).
- both laws, the application: [7] 0 on A / 1 on B, [8] 0 force / 1 moment, [9] 0 world / 1 body
  axes, [10:13] unit direction, [13:16] point of a force (relative to the centre of mass, body
  axes), [16] gain: the force or moment is gain * s along the direction.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from clearbench.kernels.quaternion import quat_exp, quat_multiply, quat_to_matrix
from clearbench.ref_solver.linalg3 import cross, dot, mat_t_vec, mat_vec
from clearbench.ref_solver.system import (
    CONFIGURATION_FORCES,
    FORCE_ANGLE_LAW,
    FORCE_DISTANCE_LAW,
    FORCE_LINEAR_SPRING,
    FORCE_MOMENT,
    FORCE_POINT_FORCE,
    FORCE_TORSIONAL_SPRING,
)

_CONFIGURATION_FORCES = np.array(CONFIGURATION_FORCES, dtype=np.int64)


@njit(cache=True)
def rotation_matrices(p):
    """(nb, 3, 3) rotation matrices of the quaternions p (nb, 4)."""
    out = np.empty((p.shape[0], 3, 3))
    for b in range(p.shape[0]):
        out[b] = quat_to_matrix(p[b])
    return out


@njit(cache=True, inline="always")
def _add_force_at(out, body, x, rotation, point_world, force):
    for i in range(3):
        out[body, i] += force[i]
    torque_world = cross(point_world - x[body], force)
    torque_body = mat_t_vec(rotation[body], torque_world)
    for i in range(3):
        out[body, 3 + i] += torque_body[i]


@njit(cache=True, inline="always")
def _add_torque(out, body, rotation, torque_world):
    torque_body = mat_t_vec(rotation[body], torque_world)
    for i in range(3):
        out[body, 3 + i] += torque_body[i]


@njit(cache=True, inline="always")
def _point_velocity(v, omega, rotation, body, local):
    return v[body] + mat_vec(rotation[body], cross(omega[body], local))


@njit(cache=True, inline="always")
def twist_angle(rotation, axis):
    """Absolute rotation angle [rad] of a body about the unit world ``axis``: 2 atan2(q . axis,
    q_w) for its quaternion q with q_w >= 0, from its rotation matrix (3, 3)."""
    vee_x = rotation[2, 1] - rotation[1, 2]
    vee_y = rotation[0, 2] - rotation[2, 0]
    vee_z = rotation[1, 0] - rotation[0, 1]
    trace = rotation[0, 0] + rotation[1, 1] + rotation[2, 2]
    return 2.0 * math.atan2(axis[0] * vee_x + axis[1] * vee_y + axis[2] * vee_z, 1.0 + trace)


@njit(cache=True)
def continuous_angle(raw, previous):
    """``raw`` (in (-pi, pi]) plus the whole turns that bring it nearest ``previous`` [rad].

    ``previous`` is the law body's continuous angle at the last step (NaN: none yet, the raw
    angle is taken). A body turning through the cut of the raw angle would otherwise make its
    angle law's moment jump by k 2 pi; as long as a body turns less than pi in one step the
    angle stays continuous. Returns ``raw`` unchanged (bitwise) while no turn is added.
    """
    if math.isnan(previous):
        return raw
    turns = round((previous - raw) / (2.0 * math.pi))
    if turns == 0.0:
        return raw
    return raw + 2.0 * math.pi * turns


@njit(cache=True)
def remember_angles(rotation, kinds, body_a, body_b, parameters, angle_memory):
    """Store in ``angle_memory`` (nf, 2) each angle law's continuous angles of its bodies A and B
    at the configuration ``rotation`` (nb, 3, 3): called once per step, after the step."""
    for e in range(kinds.shape[0]):
        if kinds[e] == FORCE_ANGLE_LAW:
            axis = parameters[e, 0:3]
            angle_memory[e, 0] = continuous_angle(twist_angle(rotation[body_a[e]], axis),
                                                  angle_memory[e, 0])
            angle_memory[e, 1] = continuous_angle(twist_angle(rotation[body_b[e]], axis),
                                                  angle_memory[e, 1])


def no_angle_memory(n_elements: int) -> np.ndarray:
    """An ``angle_memory`` (n_elements, 2) with no angle remembered (raw angles)."""
    return np.full((n_elements, 2), np.nan)


@njit(cache=True, inline="always")
def _apply_law(out, x, rotation, body, prm, scalar):
    """Apply ``scalar`` through the application stored in prm[8:17] to ``body``."""
    direction = prm[10:13].copy()
    if prm[9] > 0.5:
        direction = mat_vec(rotation[body], direction)
    value = prm[16] * scalar
    if prm[8] > 0.5:
        _add_torque(out, body, rotation, value * direction)
    else:
        point = x[body] + mat_vec(rotation[body], prm[13:16])
        _add_force_at(out, body, x, rotation, point, value * direction)


@njit(cache=True)
def element_forces(t, x, rotation, v, omega, kinds, body_a, body_b, parameters, angle_memory,
                   springs_only, out):
    """Add the force elements' generalised forces to ``out`` (nb, 6).

    ``angle_memory`` (nf, 2): the angle laws' continuous angles at the last step (NaN: none;
    :func:`remember_angles`). With ``springs_only`` the time-switched point forces and moments
    are skipped (used for the stiffness Jacobian).
    """
    for e in range(kinds.shape[0]):
        kind = kinds[e]
        prm = parameters[e]
        a = body_a[e]
        b = body_b[e]
        if kind == FORCE_LINEAR_SPRING:
            pa = x[a] + mat_vec(rotation[a], prm[0:3])
            pb = x[b] + mat_vec(rotation[b], prm[3:6])
            d = pb - pa
            length = math.sqrt(dot(d, d))
            if length == 0.0:
                continue
            e_ab = d / length
            rate = dot(e_ab, _point_velocity(v, omega, rotation, b, prm[3:6])
                       - _point_velocity(v, omega, rotation, a, prm[0:3]))
            tension = prm[9] + prm[6] * (length - prm[8]) + prm[7] * rate
            _add_force_at(out, a, x, rotation, pa, tension * e_ab)
            _add_force_at(out, b, x, rotation, pb, -tension * e_ab)
        elif kind == FORCE_TORSIONAL_SPRING:
            axis = mat_vec(rotation[a], prm[0:3])
            ref_a = mat_vec(rotation[a], prm[3:6])
            ref_b = mat_vec(rotation[b], prm[6:9])
            ref_b = ref_b - dot(ref_b, axis) * axis
            angle = math.atan2(dot(axis, cross(ref_a, ref_b)), dot(ref_a, ref_b))
            rate = dot(axis, mat_vec(rotation[b], omega[b]) - mat_vec(rotation[a], omega[a]))
            moment = -(prm[12] + prm[9] * (angle - prm[11]) + prm[10] * rate)
            _add_torque(out, b, rotation, moment * axis)
            _add_torque(out, a, rotation, -moment * axis)
        elif kind == FORCE_ANGLE_LAW:
            axis = prm[0:3]
            theta_a = continuous_angle(twist_angle(rotation[a], axis), angle_memory[e, 0])
            theta_b = continuous_angle(twist_angle(rotation[b], axis), angle_memory[e, 1])
            scalar = prm[3] * (prm[4] + prm[5] * theta_a + prm[6] * theta_b)
            _apply_law(out, x, rotation, b if prm[7] > 0.5 else a, prm, scalar)
        elif kind == FORCE_DISTANCE_LAW:
            pa = x[a] + mat_vec(rotation[a], prm[0:3])
            pb = x[b] + mat_vec(rotation[b], prm[3:6])
            d = pb - pa
            scalar = prm[17] * (prm[18] - math.sqrt(dot(d, d)))
            _apply_law(out, x, rotation, b if prm[7] > 0.5 else a, prm, scalar)
        elif kind == FORCE_POINT_FORCE and not springs_only:
            if prm[7] <= t < prm[8]:
                force = prm[3:6].copy()
                if prm[6] > 0.5:
                    force = mat_vec(rotation[a], force)
                _add_force_at(out, a, x, rotation, x[a] + mat_vec(rotation[a], prm[0:3]), force)
        elif kind == FORCE_MOMENT and not springs_only:
            if prm[4] <= t < prm[5]:
                moment = prm[0:3].copy()
                if prm[3] > 0.5:
                    moment = mat_vec(rotation[a], moment)
                _add_torque(out, a, rotation, moment)


@njit(cache=True)
def applied_forces(t, x, rotation, v, omega, mass, gravity, fixed, kinds, body_a, body_b,
                   parameters, angle_memory):
    """Gravity plus every force element at time ``t``: (nb, 6)."""
    nb = mass.shape[0]
    out = np.zeros((nb, 6))
    for b in range(nb):
        if not fixed[b]:
            for i in range(3):
                out[b, i] = mass[b] * gravity[i]
    element_forces(t, x, rotation, v, omega, kinds, body_a, body_b, parameters, angle_memory,
                   np.bool_(False), out)
    for b in range(nb):
        if fixed[b]:
            out[b, :] = 0.0
    return out


@njit(cache=True)
def spring_jacobians(t, x, p, v, omega, fixed, kinds, body_a, body_b, parameters,
                     angle_memory, length_step):
    """Stiffness K = dF/dxi and damping C = dF/dnu of the spring elements, (6 nb, 6 nb).

    xi is the generalised displacement (world translation, body-axes rotation vector applied as
    p * exp(dtheta)), nu the twist (v world, omega body). K by central differences with steps
    ``length_step`` [L] and 1e-6 rad; C exactly by unit forward differences (spring forces are
    affine in the velocities).
    """
    nb = x.shape[0]
    n = 6 * nb
    stiffness = np.zeros((n, n))
    damping = np.zeros((n, n))
    involved = np.zeros(nb, dtype=np.bool_)
    for e in range(kinds.shape[0]):
        for code in _CONFIGURATION_FORCES:
            if kinds[e] == code:
                involved[body_a[e]] = True
                involved[body_b[e]] = True
    rotation = rotation_matrices(p)
    base = np.zeros((nb, 6))
    element_forces(t, x, rotation, v, omega, kinds, body_a, body_b, parameters, angle_memory,
                   np.bool_(True), base)
    for b in range(nb):
        if fixed[b] or not involved[b]:
            continue
        for k in range(6):
            column = 6 * b + k
            step = length_step if k < 3 else 1e-6
            plus = np.zeros((nb, 6))
            minus = np.zeros((nb, 6))
            for sign in (1.0, -1.0):
                xs = x.copy()
                rs = rotation.copy()
                if k < 3:
                    xs[b, k] += sign * step
                else:
                    rv = np.zeros(3)
                    rv[k - 3] = sign * step
                    rs[b] = quat_to_matrix(quat_multiply(p[b], quat_exp(rv)))
                target = plus if sign > 0 else minus
                element_forces(t, xs, rs, v, omega, kinds, body_a, body_b, parameters,
                               angle_memory, np.bool_(True), target)
            for r in range(nb):
                for i in range(6):
                    stiffness[6 * r + i, column] = (plus[r, i] - minus[r, i]) / (2.0 * step)
            vs = v.copy()
            ws = omega.copy()
            if k < 3:
                vs[b, k] += 1.0
            else:
                ws[b, k - 3] += 1.0
            bumped = np.zeros((nb, 6))
            element_forces(t, x, rotation, vs, ws, kinds, body_a, body_b, parameters,
                           angle_memory, np.bool_(True), bumped)
            for r in range(nb):
                for i in range(6):
                    damping[6 * r + i, column] = bumped[r, i] - base[r, i]
    for b in range(nb):
        if fixed[b]:
            stiffness[6 * b:6 * b + 6, :] = 0.0
            damping[6 * b:6 * b + 6, :] = 0.0
    return stiffness, damping
