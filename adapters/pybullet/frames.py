"""Poses as (position (3,), unit quaternion (w, x, y, z)) pairs, PyBullet's quaternion order,
and the principal inertial frame of a body. Pure numpy: no ``pybullet`` import."""

from __future__ import annotations

import numpy as np

from clearbench.kernels.quaternion import (
    quat_conjugate,
    quat_from_matrix,
    quat_multiply,
    quat_to_matrix,
)

IDENTITY = np.array([1.0, 0.0, 0.0, 0.0])


# ---------------------------------------------------------------------------- frames
def to_pb(q) -> list:
    """(w, x, y, z) -> PyBullet's (x, y, z, w)."""
    w, x, y, z = (float(c) for c in q)
    return [x, y, z, w]


def from_pb(q) -> np.ndarray:
    """PyBullet's (x, y, z, w) -> (w, x, y, z)."""
    x, y, z, w = q
    return np.array([w, x, y, z], dtype=float)


def compose(a: tuple, b: tuple) -> tuple[np.ndarray, np.ndarray]:
    """Pose ``b`` expressed in frame ``a``, composed: world pose of b."""
    (pa, qa), (pb_, qb) = a, b
    return (np.asarray(pa, float) + quat_to_matrix(qa) @ np.asarray(pb_, float),
            unit_quaternion(quat_multiply(np.asarray(qa, float), np.asarray(qb, float))))


def inverse(a: tuple) -> tuple[np.ndarray, np.ndarray]:
    p, q = a
    conjugate = quat_conjugate(np.asarray(q, float))
    return -(quat_to_matrix(conjugate) @ np.asarray(p, float)), conjugate


def relative(parent: tuple, child: tuple) -> tuple[np.ndarray, np.ndarray]:
    """Pose of ``child`` in the frame of ``parent`` (both world poses)."""
    return compose(inverse(parent), child)


def unit_quaternion(q) -> np.ndarray:
    """``q`` normalised, with w >= 0 (w, x, y, z)."""
    q = np.asarray(q, dtype=float)
    q = q / np.linalg.norm(q)
    return q if q[0] >= 0 else -q


def principal_frame(inertia) -> tuple[np.ndarray, np.ndarray]:
    """Principal moments (3,) and the rotation (w, x, y, z) from principal to body axes."""
    moments, axes = np.linalg.eigh(np.asarray(inertia, dtype=float))
    if np.linalg.det(axes) < 0:
        axes[:, 2] = -axes[:, 2]
    return moments, unit_quaternion(quat_from_matrix(axes))


