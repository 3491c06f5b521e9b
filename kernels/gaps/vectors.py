"""Small helpers on 3-tuples (points, directions) and rotations as tuples of 3 rows: the
arithmetic every pair kernel is written in (tuples and scalars only, no arrays, hence no reference
counting in the compiled hot path)."""

from __future__ import annotations

import math

from clearbench.kernels.jit import njit


@njit(cache=True, inline="always")
def column_of(rotation, j):
    return (rotation[0][j], rotation[1][j], rotation[2][j])


@njit(cache=True, inline="always")
def add(a, b):
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


@njit(cache=True, inline="always")
def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


@njit(cache=True, inline="always")
def scaled(a, s):
    return (a[0] * s, a[1] * s, a[2] * s)


@njit(cache=True, inline="always")
def axpy(s, a, b):
    """b + s a"""
    return (b[0] + s * a[0], b[1] + s * a[1], b[2] + s * a[2])


@njit(cache=True, inline="always")
def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@njit(cache=True, inline="always")
def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


@njit(cache=True, inline="always")
def norm(a):
    return math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])


@njit(cache=True, inline="always")
def rotate(rotation, local):
    """rotation @ local"""
    return (dot(rotation[0], local), dot(rotation[1], local), dot(rotation[2], local))


@njit(cache=True, inline="always")
def to_world(position, rotation, local):
    """position + rotation @ local"""
    return add(position, rotate(rotation, local))


@njit(cache=True, inline="always")
def to_local(position, rotation, world):
    """rotation.T @ (world - position)"""
    d = sub(world, position)
    return (
        rotation[0][0] * d[0] + rotation[1][0] * d[1] + rotation[2][0] * d[2],
        rotation[0][1] * d[0] + rotation[1][1] * d[1] + rotation[2][1] * d[2],
        rotation[0][2] * d[0] + rotation[1][2] * d[1] + rotation[2][2] * d[2],
    )


@njit(cache=True, inline="always")
def rotate_back(rotation, world):
    """rotation.T @ world (a direction in the rotation's own frame)"""
    return (
        rotation[0][0] * world[0] + rotation[1][0] * world[1] + rotation[2][0] * world[2],
        rotation[0][1] * world[0] + rotation[1][1] * world[1] + rotation[2][1] * world[2],
        rotation[0][2] * world[0] + rotation[1][2] * world[1] + rotation[2][2] * world[2],
    )


@njit(cache=True, inline="always")
def clamp(value, low, high):
    return min(max(value, low), high)


@njit(cache=True)
def any_perpendicular(axis):
    """A unit vector perpendicular to the unit vector ``axis`` (deterministic)."""
    if abs(axis[0]) < 0.6:
        other = (1.0, 0.0, 0.0)
    else:
        other = (0.0, 1.0, 0.0)
    v = cross(axis, other)
    return scaled(v, 1.0 / norm(v))
