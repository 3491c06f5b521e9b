"""Plane (A) against sphere, box, capsule and cylinder (B). The plane's material is below its
shape-frame z = 0; its +z axis is the normal (from A toward B)."""

from __future__ import annotations

import math

from clearbench.kernels.gaps.staging import stage_contact
from clearbench.kernels.gaps.vectors import (
    add,
    axpy,
    column_of,
    cross,
    dot,
    scaled,
    sub,
    to_world,
)
from clearbench.kernels.jit import njit


@njit(cache=True, inline="always")
def plane_point(plane_position, normal, point, radius, index, stage):
    """Contact of ``point`` swept by ``radius`` (a sphere; 0 for a bare point)."""
    height = dot(sub(point, plane_position), normal)
    stage_contact(stage, index, height - radius, axpy(-height, normal, point), normal)


@njit(cache=True)
def plane_sphere(plane_position, plane_rotation, centre, radius, stage):
    plane_point(plane_position, column_of(plane_rotation, 2), centre, radius, 0, stage)
    return 1


@njit(cache=True)
def plane_box(plane_position, plane_rotation, box_position, box_rotation, half_extents,
              stage):
    normal = column_of(plane_rotation, 2)
    for index in range(8):
        sx = 1.0 if index & 4 else -1.0
        sy = 1.0 if index & 2 else -1.0
        sz = 1.0 if index & 1 else -1.0
        local = (sx * half_extents[0], sy * half_extents[1], sz * half_extents[2])
        corner = to_world(box_position, box_rotation, local)
        plane_point(plane_position, normal, corner, 0.0, index, stage)
    return 8


@njit(cache=True)
def plane_capsule(plane_position, plane_rotation, position, rotation, radius, half_length,
                  stage):
    normal = column_of(plane_rotation, 2)
    axis = column_of(rotation, 2)
    plane_point(plane_position, normal, axpy(-half_length, axis, position), radius, 0, stage)
    plane_point(plane_position, normal, axpy(half_length, axis, position), radius, 1, stage)
    return 2


@njit(cache=True)
def lowest_direction(normal, rotation):
    """Unit vector in the shape's xy-plane most opposed to ``normal`` (the shape's x axis when
    that plane is parallel to the contact plane), and ``z x lowest``, 90 degrees further.

    Built from the normal's components along the shape's x and y axes, so it lies in that
    plane to round-off even when the axis is parallel to the normal: there the components are
    round-off, their direction arbitrary, but every rim point is then as low as any other (a
    projection ``normal - (normal . z) z`` would leave a round-off vector along the axis,
    whose normalised direction puts the "rim" points a radius off the rim)."""
    e1 = column_of(rotation, 0)
    e2 = column_of(rotation, 1)
    along_1 = dot(normal, e1)
    along_2 = dot(normal, e2)
    length = math.hypot(along_1, along_2)
    if length > 0.0:
        lowest = add(scaled(e1, -along_1 / length), scaled(e2, -along_2 / length))
    else:
        lowest = e1
    return lowest, cross(column_of(rotation, 2), lowest)


@njit(cache=True, inline="always")
def cylinder_rim_point(index, position, axis, lowest, quarter, radius, half_length):
    """Rim candidate ``index`` (0..7) of a cylinder: on the end rim -half_length (even index)
    or +half_length (odd), the point ``index // 2`` quarter turns from ``lowest``."""
    end = -half_length if index % 2 == 0 else half_length
    turn = index // 2  # 0, 1, 2, 3 quarter turns from the lowest point
    if turn == 0:
        offset = scaled(lowest, radius)
    elif turn == 1:
        offset = scaled(quarter, radius)
    elif turn == 2:
        offset = scaled(lowest, -radius)
    else:
        offset = scaled(quarter, -radius)
    return add(axpy(end, axis, position), offset)


@njit(cache=True)
def plane_cylinder(plane_position, plane_rotation, position, rotation, radius, half_length,
                   stage):
    """Eight rim candidates: on each end rim the lowest point and the points 90, 180 and 270
    degrees further round. Indices 0 and 1 are the two lowest rim points (the support of a
    lying cylinder); a standing cylinder gets 4 points on its bottom rim."""
    normal = column_of(plane_rotation, 2)
    axis = column_of(rotation, 2)
    lowest, quarter = lowest_direction(normal, rotation)
    for index in range(8):
        point = cylinder_rim_point(index, position, axis, lowest, quarter, radius, half_length)
        plane_point(plane_position, normal, point, 0.0, index, stage)
    return 8
