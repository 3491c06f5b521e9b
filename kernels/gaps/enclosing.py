"""A ring that must enclose a journal: the sign of its gap beyond the ring (the measurement
side, plain Python: no compiled caller)."""

from __future__ import annotations

import math

import numpy as np

from clearbench.kernels.gaps.codes import TWO_PI


def axis_crosses_inside_ring(ring_position, ring_rotation, ring_radius, start_angle, span,
                             axis_point, axis_direction) -> bool:
    """True when the line through ``axis_point`` along ``axis_direction`` (the journal axis)
    crosses the plane of the ring inside its circle: the journal is in the bore.

    An arc (``span`` < 2 pi) also counts the crossing as inside when it lies beyond the circle
    at an angle the arc does not cover (the journal left through the opening, not through the
    material). A line parallel to the ring's plane is inside when its distance from the ring's
    centre is below the radius.

    Parameters
    ----------
    ring_position : array_like (3,)
        World centre of the ring [L].
    ring_rotation : array_like (3, 3)
        World rotation of the ring's frame (columns: x, y in the ring's plane, z its normal).
    ring_radius : float
        [L].
    start_angle, span : float
        The arc's first angle and angular extent [rad] (a full circle: 0, 2 pi).
    axis_point, axis_direction : array_like (3,)
        A point of the journal axis [L] and its direction (any length > 0).
    """
    rotation = np.asarray(ring_rotation, dtype=float)
    normal = rotation[:, 2]
    direction = np.asarray(axis_direction, dtype=float)
    offset = np.asarray(axis_point, dtype=float) - np.asarray(ring_position, dtype=float)
    along = float(direction @ normal)
    if abs(along) <= 1e-12 * float(np.linalg.norm(direction)):
        unit = direction / np.linalg.norm(direction)
        return bool(np.linalg.norm(offset - (offset @ unit) * unit) < ring_radius)
    crossing = offset - (float(offset @ normal) / along) * direction
    local = rotation.T @ crossing
    if math.hypot(local[0], local[1]) < ring_radius:
        return True
    if span >= TWO_PI:
        return False
    return (math.atan2(local[1], local[0]) - start_angle) % TWO_PI > span


def enclosing_ring_gap(gap: float, cylinder_radius: float, inside: bool) -> float:
    """Signed gap of a ring that must enclose a journal [L], from the ring-cylinder gap
    ``gap`` (nearest ring point's distance from the axis minus the cylinder radius,
    :func:`ring_cylinder`) and whether the axis crosses inside the ring
    (:func:`axis_crosses_inside_ring`).

    Inside, the gap is unchanged (parallel axes at eccentricity e: R_ring - R_cyl - e). Beyond
    the ring the nearest ring point is on the far side of the axis and the unsigned gap grows
    with the distance again (e - R_ring - R_cyl), a journal out of its bore reading as
    separated; counted through the wall the distance is negative: -(gap + R_cyl) - R_cyl, i.e.
    R_ring - R_cyl - e again, continuous where the axis crosses the ring (distance 0) and
    decreasing without bound as the journal moves away.
    """
    return gap if inside else -gap - 2.0 * cylinder_radius
