"""Unit quaternions (w, x, y, z): the one quaternion module of clearbench.

Conventions
-----------
- Storage order (w, x, y, z); ``w`` is the scalar part. All arrays are float64.
- A unit quaternion ``q`` represents the active rotation ``v -> q * (0, v) * conj(q)``, whose
  matrix :func:`quat_to_matrix` maps vectors expressed in a body (or shape) frame to the world
  (parent) frame: ``v_world = R(q) @ v_body``. This is the convention of scipy's ``Rotation``
  (which stores (x, y, z, w)) and of MuJoCo.
- Composition: ``R(p * q) = R(p) @ R(q)``: ``q`` is applied first, in the frame of ``p``.
- Angular velocity ``Omega`` is in BODY axes; the kinematics is ``dq/dt = 1/2 q * (0, Omega)``
  (:func:`quat_kinematic_matrix`), and the Lie-group update over a step ``h`` is
  ``q_{k+1} = q_k * exp(h Omega)`` (:func:`quat_integrate`).
- ``q`` and ``-q`` are the same rotation. Functions that must pick one (:func:`quat_from_matrix`,
  :func:`quat_log`) return the representative with ``w >= 0`` (rotation angle in [0, pi]).

Two families of functions
-------------------------
- ``quat_*``: scalar-style kernels on one quaternion (4,) / vector (3,) / matrix (3, 3), compiled
  with ``numba.njit(cache=True)`` so that compiled loops (the reference solver, geometry kernels)
  call them. They also work from Python (compiled on first call).
- ``quat_*_batch``: vectorised numpy versions over leading axes, shapes (..., 4), (..., 3),
  (..., 3, 3), for metrics and adapters. Leading axes broadcast.

Angles are in radians; rotation vectors (axis times angle) in radians.
"""

from __future__ import annotations

import math

import numpy as np

from clearbench.kernels.jit import njit

__all__ = [
    "EXP_TAYLOR_THRESHOLD",
    "quat_angular_distance",
    "quat_angular_distance_batch",
    "quat_conjugate",
    "quat_conjugate_batch",
    "quat_exp",
    "quat_exp_batch",
    "quat_from_axis_angle",
    "quat_from_axis_angle_batch",
    "quat_from_matrix",
    "quat_from_matrix_batch",
    "quat_integrate",
    "quat_kinematic_matrix",
    "quat_kinematic_matrix_batch",
    "quat_log",
    "quat_log_batch",
    "quat_multiply",
    "quat_multiply_batch",
    "quat_normalize",
    "quat_normalize_batch",
    "quat_rotate",
    "quat_rotate_batch",
    "quat_rotate_inverse",
    "quat_rotate_inverse_batch",
    "quat_to_matrix",
    "quat_to_matrix_batch",
]

#: Below this rotation angle (rad) :func:`quat_exp` evaluates sin(theta/2)/theta by its Taylor
#: series 1/2 - theta^2/48 + theta^4/3840. The first omitted term, theta^6/1290240, is below
#: 1e-18 (relative 2e-18, under a tenth of an ulp) for theta < 1e-2.
EXP_TAYLOR_THRESHOLD = 1e-2

#: Below this |vector part| (with w ~ 1) :func:`quat_log` evaluates atan(t)/t by its Taylor
#: series 1 - t^2/3 + t^4/5; the first omitted term t^6/7 is < 1.5e-25 for t < 1e-4.
LOG_TAYLOR_THRESHOLD = 1e-4


# ------------------------------------------------------------------------------------------------
# Scalar-style kernels (numba)
# ------------------------------------------------------------------------------------------------


@njit(cache=True)
def quat_multiply(p, q):
    """Hamilton product ``p * q``.

    Parameters
    ----------
    p, q : ndarray (4,)
        Quaternions (w, x, y, z).

    Returns
    -------
    ndarray (4,)
        ``p * q``; for unit quaternions the rotation "first q, then p".
    """
    pw, px, py, pz = p[0], p[1], p[2], p[3]
    qw, qx, qy, qz = q[0], q[1], q[2], q[3]
    out = np.empty(4)
    out[0] = pw * qw - px * qx - py * qy - pz * qz
    out[1] = pw * qx + px * qw + py * qz - pz * qy
    out[2] = pw * qy - px * qz + py * qw + pz * qx
    out[3] = pw * qz + px * qy - py * qx + pz * qw
    return out


@njit(cache=True)
def quat_conjugate(q):
    """Conjugate (w, -x, -y, -z): the inverse rotation of a unit quaternion. (4,) -> (4,)."""
    out = np.empty(4)
    out[0] = q[0]
    out[1] = -q[1]
    out[2] = -q[2]
    out[3] = -q[3]
    return out


@njit(cache=True)
def quat_normalize(q):
    """``q / |q|``, (4,) -> (4,). A zero quaternion gives the identity (1, 0, 0, 0)."""
    norm = math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    out = np.empty(4)
    if norm == 0.0:
        out[0] = 1.0
        out[1] = 0.0
        out[2] = 0.0
        out[3] = 0.0
        return out
    inverse = 1.0 / norm
    for i in range(4):
        out[i] = q[i] * inverse
    return out


@njit(cache=True)
def quat_rotate(q, v):
    """Rotate the vector ``v`` (3,) by the unit quaternion ``q`` (4,): ``R(q) @ v`` (3,).

    Uses ``v + 2 w (u x v) + 2 u x (u x v)`` with u the vector part (no matrix built).
    """
    w, x, y, z = q[0], q[1], q[2], q[3]
    # t = 2 (u x v)
    tx = 2.0 * (y * v[2] - z * v[1])
    ty = 2.0 * (z * v[0] - x * v[2])
    tz = 2.0 * (x * v[1] - y * v[0])
    out = np.empty(3)
    out[0] = v[0] + w * tx + (y * tz - z * ty)
    out[1] = v[1] + w * ty + (z * tx - x * tz)
    out[2] = v[2] + w * tz + (x * ty - y * tx)
    return out


@njit(cache=True)
def quat_rotate_inverse(q, v):
    """Rotate ``v`` (3,) by the inverse of the unit quaternion ``q``: ``R(q).T @ v`` (3,)."""
    return quat_rotate(quat_conjugate(q), v)


@njit(cache=True)
def quat_to_matrix(q):
    """Rotation matrix (3, 3) of the unit quaternion ``q`` (4,).

    Columns are the rotated frame's axes in world coordinates. ``q`` is assumed unit; no
    normalisation is done here (call :func:`quat_normalize` first if it may not be).
    """
    w, x, y, z = q[0], q[1], q[2], q[3]
    xx, yy, zz = x * x, y * y, z * z
    xy, xz, yz = x * y, x * z, y * z
    wx, wy, wz = w * x, w * y, w * z
    out = np.empty((3, 3))
    out[0, 0] = 1.0 - 2.0 * (yy + zz)
    out[0, 1] = 2.0 * (xy - wz)
    out[0, 2] = 2.0 * (xz + wy)
    out[1, 0] = 2.0 * (xy + wz)
    out[1, 1] = 1.0 - 2.0 * (xx + zz)
    out[1, 2] = 2.0 * (yz - wx)
    out[2, 0] = 2.0 * (xz - wy)
    out[2, 1] = 2.0 * (yz + wx)
    out[2, 2] = 1.0 - 2.0 * (xx + yy)
    return out


@njit(cache=True)
def quat_from_matrix(matrix):
    """Unit quaternion (4,) of a rotation matrix (3, 3), by Shepperd's method.

    The largest of 4 w^2, 4 x^2, 4 y^2, 4 z^2 (from the trace and the diagonal) is taken as the
    pivot, so no division by a small number occurs for any rotation. The result is normalised
    and has ``w >= 0``. The input should be orthonormal with determinant +1; small departures
    (round-off) are absorbed by the normalisation.
    """
    m00, m01, m02 = matrix[0, 0], matrix[0, 1], matrix[0, 2]
    m10, m11, m12 = matrix[1, 0], matrix[1, 1], matrix[1, 2]
    m20, m21, m22 = matrix[2, 0], matrix[2, 1], matrix[2, 2]
    trace = m00 + m11 + m22
    out = np.empty(4)
    if trace >= m00 and trace >= m11 and trace >= m22:
        s = 2.0 * math.sqrt(max(1.0 + trace, 0.0))  # s = 4 w
        out[0] = 0.25 * s
        out[1] = (m21 - m12) / s
        out[2] = (m02 - m20) / s
        out[3] = (m10 - m01) / s
    elif m00 >= m11 and m00 >= m22:
        s = 2.0 * math.sqrt(max(1.0 + m00 - m11 - m22, 0.0))  # s = 4 x
        out[0] = (m21 - m12) / s
        out[1] = 0.25 * s
        out[2] = (m01 + m10) / s
        out[3] = (m02 + m20) / s
    elif m11 >= m22:
        s = 2.0 * math.sqrt(max(1.0 + m11 - m00 - m22, 0.0))  # s = 4 y
        out[0] = (m02 - m20) / s
        out[1] = (m01 + m10) / s
        out[2] = 0.25 * s
        out[3] = (m12 + m21) / s
    else:
        s = 2.0 * math.sqrt(max(1.0 + m22 - m00 - m11, 0.0))  # s = 4 z
        out[0] = (m10 - m01) / s
        out[1] = (m02 + m20) / s
        out[2] = (m12 + m21) / s
        out[3] = 0.25 * s
    norm = math.sqrt(out[0] ** 2 + out[1] ** 2 + out[2] ** 2 + out[3] ** 2)
    sign = 1.0 if out[0] >= 0.0 else -1.0
    for i in range(4):
        out[i] = sign * out[i] / norm
    return out


@njit(cache=True)
def quat_from_axis_angle(axis, angle):
    """Unit quaternion (4,) of the rotation by ``angle`` (rad) about ``axis`` (3,).

    ``axis`` need not be unit; it is normalised. A zero axis gives the identity.
    """
    norm = math.sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2])
    out = np.empty(4)
    if norm == 0.0:
        out[0] = 1.0
        out[1] = 0.0
        out[2] = 0.0
        out[3] = 0.0
        return out
    half = 0.5 * angle
    scale = math.sin(half) / norm
    out[0] = math.cos(half)
    out[1] = axis[0] * scale
    out[2] = axis[1] * scale
    out[3] = axis[2] * scale
    return out


@njit(cache=True)
def _exp_parts(rx, ry, rz):
    """(cos(theta/2), sin(theta/2)/theta) for the rotation vector (rx, ry, rz), theta = |r|."""
    theta_squared = rx * rx + ry * ry + rz * rz
    theta = math.sqrt(theta_squared)
    if theta < EXP_TAYLOR_THRESHOLD:
        # sin(t/2)/t = 1/2 - t^2/48 + t^4/3840 - ...; see EXP_TAYLOR_THRESHOLD.
        sinc_half = 0.5 - theta_squared / 48.0 + theta_squared * theta_squared / 3840.0
    else:
        sinc_half = math.sin(0.5 * theta) / theta
    return math.cos(0.5 * theta), sinc_half


@njit(cache=True)
def quat_exp(rotation_vector):
    """Exponential map: rotation vector (3,) (axis times angle, rad) -> unit quaternion (4,).

    ``exp(r) = (cos(|r|/2), sin(|r|/2) r/|r|)``. Tiny angles (below EXP_TAYLOR_THRESHOLD) use a
    Taylor series of sin(|r|/2)/|r|, so the result is unit to round-off for every input,
    including ``r = 0`` exactly. With ``r = h Omega`` (body angular velocity times step) this is
    the Lie-group increment of :func:`quat_integrate`.
    """
    w, sinc_half = _exp_parts(rotation_vector[0], rotation_vector[1], rotation_vector[2])
    out = np.empty(4)
    out[0] = w
    out[1] = rotation_vector[0] * sinc_half
    out[2] = rotation_vector[1] * sinc_half
    out[3] = rotation_vector[2] * sinc_half
    return out


@njit(cache=True)
def quat_log(q):
    """Logarithm: unit quaternion (4,) -> rotation vector (3,) (axis times angle, rad).

    The representative with ``w >= 0`` is used, so the angle is in [0, pi] and
    ``quat_exp(quat_log(q))`` equals ``q`` if ``q[0] >= 0`` and ``-q`` otherwise (same rotation).
    Accurate for tiny angles (Taylor branch, LOG_TAYLOR_THRESHOLD). ``q`` need not be exactly
    unit: the angle comes from atan2, which is scale-free.
    """
    w, x, y, z = q[0], q[1], q[2], q[3]
    if w < 0.0:
        w, x, y, z = -w, -x, -y, -z
    s = math.sqrt(x * x + y * y + z * z)
    out = np.empty(3)
    if s < LOG_TAYLOR_THRESHOLD * w:
        # 2 atan(t)/t / w with t = s/w; atan(t)/t = 1 - t^2/3 + t^4/5 - ...
        t2 = (s / w) ** 2
        factor = 2.0 * (1.0 - t2 / 3.0 + t2 * t2 / 5.0) / w
    else:
        factor = 2.0 * math.atan2(s, w) / s
    out[0] = x * factor
    out[1] = y * factor
    out[2] = z * factor
    return out


@njit(cache=True)
def quat_integrate(q, rotation_vector):
    """One Lie-group step ``q * exp(rotation_vector)`` (4,), followed by a first-order norm fix.

    ``rotation_vector`` (3,) is ``h * Omega`` (step in s times body angular velocity in rad/s).
    Exact arithmetic keeps ``|q| = 1``; in floating point each product adds a few ulp of norm
    error, which would random-walk over millions of steps. The correction
    ``q * (3 - |q|^2) / 2`` (one Newton step for 1/sqrt) removes it to second order, so the norm
    stays within a few ulp of 1 indefinitely. It is a round-off correction, not a projection:
    it changes ``q`` by O(1e-16).
    """
    out = quat_multiply(q, quat_exp(rotation_vector))
    norm_squared = out[0] ** 2 + out[1] ** 2 + out[2] ** 2 + out[3] ** 2
    factor = 0.5 * (3.0 - norm_squared)
    for i in range(4):
        out[i] *= factor
    return out


@njit(cache=True)
def quat_angular_distance(p, q):
    """Angle (rad, in [0, pi]) of the rotation taking ``p`` to ``q``: angle of ``conj(p) * q``.

    ``q`` and ``-q`` are at distance 0. Computed with atan2, accurate for tiny angles.
    """
    relative = quat_multiply(quat_conjugate(p), q)
    s = math.sqrt(relative[1] ** 2 + relative[2] ** 2 + relative[3] ** 2)
    return 2.0 * math.atan2(s, abs(relative[0]))


@njit(cache=True)
def quat_kinematic_matrix(q):
    """Matrix G (4, 3) with ``dq/dt = G @ Omega`` for ``dq/dt = 1/2 q * (0, Omega)``.

    ``Omega`` (3,) is the angular velocity in BODY axes (rad/s); ``dq/dt`` in 1/s.
    ``G.T @ G = |q|^2 / 4 * I``.
    """
    w, x, y, z = 0.5 * q[0], 0.5 * q[1], 0.5 * q[2], 0.5 * q[3]
    out = np.empty((4, 3))
    out[0, 0], out[0, 1], out[0, 2] = -x, -y, -z
    out[1, 0], out[1, 1], out[1, 2] = w, -z, y
    out[2, 0], out[2, 1], out[2, 2] = z, w, -x
    out[3, 0], out[3, 1], out[3, 2] = -y, x, w
    return out


# ------------------------------------------------------------------------------------------------
# Vectorised numpy versions over leading axes
# ------------------------------------------------------------------------------------------------


def _as_float(array) -> np.ndarray:
    return np.asarray(array, dtype=np.float64)


def quat_multiply_batch(p, q) -> np.ndarray:
    """Hamilton products ``p * q`` of (..., 4) arrays (broadcast) -> (..., 4)."""
    p, q = _as_float(p), _as_float(q)
    pw, px, py, pz = np.moveaxis(p, -1, 0)
    qw, qx, qy, qz = np.moveaxis(q, -1, 0)
    return np.stack(
        (
            pw * qw - px * qx - py * qy - pz * qz,
            pw * qx + px * qw + py * qz - pz * qy,
            pw * qy - px * qz + py * qw + pz * qx,
            pw * qz + px * qy - py * qx + pz * qw,
        ),
        axis=-1,
    )


def quat_conjugate_batch(q) -> np.ndarray:
    """Conjugates of (..., 4) quaternions -> (..., 4)."""
    q = _as_float(q)
    return q * np.array([1.0, -1.0, -1.0, -1.0])


def quat_normalize_batch(q) -> np.ndarray:
    """``q / |q|`` over (..., 4); zero quaternions give the identity."""
    q = _as_float(q)
    norm = np.linalg.norm(q, axis=-1, keepdims=True)
    identity = np.broadcast_to(np.array([1.0, 0.0, 0.0, 0.0]), q.shape)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(norm > 0.0, q / np.where(norm > 0.0, norm, 1.0), identity)


def quat_rotate_batch(q, v) -> np.ndarray:
    """``R(q) @ v`` for unit quaternions (..., 4) and vectors (..., 3) (broadcast) -> (..., 3)."""
    q, v = _as_float(q), _as_float(v)
    w = q[..., :1]
    u = q[..., 1:]
    t = 2.0 * np.cross(u, v)
    return v + w * t + np.cross(u, t)


def quat_rotate_inverse_batch(q, v) -> np.ndarray:
    """``R(q).T @ v`` for unit quaternions (..., 4) and vectors (..., 3) -> (..., 3)."""
    return quat_rotate_batch(quat_conjugate_batch(q), v)


def quat_to_matrix_batch(q) -> np.ndarray:
    """Rotation matrices (..., 3, 3) of unit quaternions (..., 4)."""
    q = _as_float(q)
    w, x, y, z = np.moveaxis(q, -1, 0)
    xx, yy, zz = x * x, y * y, z * z
    xy, xz, yz = x * y, x * z, y * z
    wx, wy, wz = w * x, w * y, w * z
    rows = (
        (1.0 - 2.0 * (yy + zz), 2.0 * (xy - wz), 2.0 * (xz + wy)),
        (2.0 * (xy + wz), 1.0 - 2.0 * (xx + zz), 2.0 * (yz - wx)),
        (2.0 * (xz - wy), 2.0 * (yz + wx), 1.0 - 2.0 * (xx + yy)),
    )
    return np.stack([np.stack(row, axis=-1) for row in rows], axis=-2)


def quat_from_matrix_batch(matrix) -> np.ndarray:
    """Unit quaternions (..., 4), ``w >= 0``, of rotation matrices (..., 3, 3) (Shepperd)."""
    matrix = _as_float(matrix)
    m = matrix
    diagonal = np.stack((m[..., 0, 0], m[..., 1, 1], m[..., 2, 2]), axis=-1)
    trace = diagonal.sum(axis=-1)
    # 4 w^2 - 1, 4 x^2 - 1, 4 y^2 - 1, 4 z^2 - 1 (each up to the same constant): pick the largest.
    candidates = np.stack(
        (
            trace,
            2.0 * diagonal[..., 0] - trace,
            2.0 * diagonal[..., 1] - trace,
            2.0 * diagonal[..., 2] - trace,
        ),
        axis=-1,
    )
    pivot = np.argmax(candidates, axis=-1)
    s = 2.0 * np.sqrt(np.maximum(1.0 + np.take_along_axis(candidates, pivot[..., None], -1), 0.0))
    s = s[..., 0]
    d21 = m[..., 2, 1] - m[..., 1, 2]
    d02 = m[..., 0, 2] - m[..., 2, 0]
    d10 = m[..., 1, 0] - m[..., 0, 1]
    s01 = m[..., 0, 1] + m[..., 1, 0]
    s02 = m[..., 0, 2] + m[..., 2, 0]
    s12 = m[..., 1, 2] + m[..., 2, 1]
    options = np.stack(
        (
            np.stack((0.25 * s, d21 / s, d02 / s, d10 / s), axis=-1),
            np.stack((d21 / s, 0.25 * s, s01 / s, s02 / s), axis=-1),
            np.stack((d02 / s, s01 / s, 0.25 * s, s12 / s), axis=-1),
            np.stack((d10 / s, s02 / s, s12 / s, 0.25 * s), axis=-1),
        ),
        axis=-2,
    )
    q = np.take_along_axis(options, pivot[..., None, None], axis=-2)[..., 0, :]
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    return np.where(q[..., :1] < 0.0, -q, q)


def quat_from_axis_angle_batch(axis, angle) -> np.ndarray:
    """Unit quaternions (..., 4) from axes (..., 3) (normalised here) and angles (...) in rad."""
    axis, angle = _as_float(axis), _as_float(angle)
    norm = np.linalg.norm(axis, axis=-1, keepdims=True)
    half = 0.5 * angle[..., None]
    with np.errstate(invalid="ignore", divide="ignore"):
        vector = np.where(norm > 0.0, axis * np.sin(half) / np.where(norm > 0, norm, 1.0), 0.0)
    w = np.where(norm > 0.0, np.cos(half), 1.0)
    w = np.broadcast_to(w, vector.shape[:-1] + (1,))
    return np.concatenate((w, vector), axis=-1)


def quat_exp_batch(rotation_vector) -> np.ndarray:
    """Exponential map over (..., 3) rotation vectors (rad) -> unit quaternions (..., 4)."""
    r = _as_float(rotation_vector)
    theta_squared = np.sum(r * r, axis=-1)
    theta = np.sqrt(theta_squared)
    small = theta < EXP_TAYLOR_THRESHOLD
    with np.errstate(invalid="ignore", divide="ignore"):
        direct = np.sin(0.5 * theta) / np.where(small, 1.0, theta)
    taylor = 0.5 - theta_squared / 48.0 + theta_squared * theta_squared / 3840.0
    sinc_half = np.where(small, taylor, direct)
    return np.concatenate((np.cos(0.5 * theta)[..., None], r * sinc_half[..., None]), axis=-1)


def quat_log_batch(q) -> np.ndarray:
    """Logarithm over (..., 4) quaternions -> rotation vectors (..., 3), angle in [0, pi]."""
    q = _as_float(q)
    q = np.where(q[..., :1] < 0.0, -q, q)
    w = q[..., 0]
    u = q[..., 1:]
    s = np.linalg.norm(u, axis=-1)
    small = s < LOG_TAYLOR_THRESHOLD * w
    with np.errstate(invalid="ignore", divide="ignore"):
        t2 = (s / np.where(w > 0.0, w, 1.0)) ** 2
        taylor = 2.0 * (1.0 - t2 / 3.0 + t2 * t2 / 5.0) / np.where(w > 0.0, w, 1.0)
        direct = 2.0 * np.arctan2(s, w) / np.where(s > 0.0, s, 1.0)
    factor = np.where(small, taylor, direct)
    return u * factor[..., None]


def quat_angular_distance_batch(p, q) -> np.ndarray:
    """Angles (rad, in [0, pi]) between rotations (..., 4) and (..., 4) -> (...)."""
    relative = quat_multiply_batch(quat_conjugate_batch(p), q)
    s = np.linalg.norm(relative[..., 1:], axis=-1)
    return 2.0 * np.arctan2(s, np.abs(relative[..., 0]))


def quat_kinematic_matrix_batch(q) -> np.ndarray:
    """Matrices G (..., 4, 3) with ``dq/dt = G @ Omega`` (Omega in body axes) over (..., 4)."""
    q = 0.5 * _as_float(q)
    w, x, y, z = np.moveaxis(q, -1, 0)
    rows = ((-x, -y, -z), (w, -z, y), (z, w, -x), (-y, x, w))
    return np.stack([np.stack(row, axis=-1) for row in rows], axis=-2)
