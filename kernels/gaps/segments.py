"""Segments: the closest points of two axis segments (Ericson), and capsule against capsule."""

from __future__ import annotations

from clearbench.kernels.gaps.staging import stage_contact
from clearbench.kernels.gaps.vectors import (
    any_perpendicular,
    axpy,
    clamp,
    column_of,
    cross,
    dot,
    norm,
    scaled,
    sub,
)
from clearbench.kernels.jit import njit

#: |a x b| below which two capsule axes are treated as parallel (two contacts on the overlap).
_PARALLEL_SINE = 1e-6


@njit(cache=True)
def segment_parameters(centre_a, axis_a, half_a, centre_b, axis_b, half_b):
    """Parameters (s, t) of the closest points ``centre_a + s axis_a`` and
    ``centre_b + t axis_b`` of two segments (unit axes, |s| <= half_a, |t| <= half_b).

    Ericson, Real-Time Collision Detection, 5.1.9. Parallel axes give the point of A nearest
    the middle of the overlap (one of the closest pairs)."""
    r = sub(centre_a, centre_b)
    b = dot(axis_a, axis_b)
    c = dot(axis_a, r)
    f = dot(axis_b, r)
    denominator = 1.0 - b * b
    if denominator > 1e-14:
        s = clamp((b * f - c) / denominator, -half_a, half_a)
    else:
        # Parallel: middle of the overlap of B's projection onto A (clamped to A).
        low = max(-half_a, -c - half_b * abs(b))
        high = min(half_a, -c + half_b * abs(b))
        s = clamp(0.5 * (low + high), -half_a, half_a)
    t = b * s + f
    if t < -half_b:
        t = -half_b
        s = clamp(b * t - c, -half_a, half_a)
    elif t > half_b:
        t = half_b
        s = clamp(b * t - c, -half_a, half_a)
    return s, t


@njit(cache=True, inline="always")
def _swept_points(point_a, radius_a, point_b, radius_b, fallback_normal, index, stage):
    """Contact between two points swept by radii (spheres on segment points)."""
    d = sub(point_b, point_a)
    distance = norm(d)
    if distance > 0.0:
        normal = scaled(d, 1.0 / distance)
    else:
        normal = fallback_normal
    stage_contact(stage, index, distance - radius_a - radius_b, axpy(radius_a, normal, point_a),
                  normal)


@njit(cache=True)
def capsule_capsule(position_a, rotation_a, radius_a, half_a, position_b, rotation_b, radius_b,
                    half_b, stage):
    """One contact at the closest points of the two axes; two (at the ends of the overlap) when
    the axes are parallel within _PARALLEL_SINE, where the closest set is a segment."""
    axis_a = column_of(rotation_a, 2)
    axis_b = column_of(rotation_b, 2)
    fallback = any_perpendicular(axis_a)
    if norm(cross(axis_a, axis_b)) < _PARALLEL_SINE:
        b = dot(axis_a, axis_b)
        c = dot(axis_a, sub(position_a, position_b))
        low = max(-half_a, -c - half_b * abs(b))
        high = min(half_a, -c + half_b * abs(b))
        if low < high:
            for index in range(2):
                s = low if index == 0 else high
                point_a = axpy(s, axis_a, position_a)
                t = clamp(dot(sub(point_a, position_b), axis_b), -half_b, half_b)
                _swept_points(point_a, radius_a, axpy(t, axis_b, position_b), radius_b,
                              fallback, index, stage)
            return 2
    s, t = segment_parameters(position_a, axis_a, half_a, position_b, axis_b, half_b)
    _swept_points(axpy(s, axis_a, position_a), radius_a, axpy(t, axis_b, position_b),
                  radius_b, fallback, 0, stage)
    return 1
