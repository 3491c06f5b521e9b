"""Sphere (B) against sphere, box, capsule and cylinder (A): the closest point of the solid."""

from __future__ import annotations

import math

from clearbench.kernels.gaps.staging import stage_contact
from clearbench.kernels.gaps.vectors import (
    axpy,
    clamp,
    column_of,
    dot,
    norm,
    rotate,
    scaled,
    sub,
    to_local,
    to_world,
)
from clearbench.kernels.jit import njit


@njit(cache=True)
def sphere_sphere(centre_a, radius_a, centre_b, radius_b, stage):
    d = sub(centre_b, centre_a)
    distance = norm(d)
    if distance > 0.0:
        normal = scaled(d, 1.0 / distance)
    else:
        normal = (0.0, 0.0, 1.0)  # concentric: any direction is a closest direction
    stage_contact(stage, 0, distance - radius_a - radius_b, axpy(radius_a, normal, centre_a),
                  normal)
    return 1


@njit(cache=True)
def box_sphere(box_position, box_rotation, h, centre, radius, stage):
    local = to_local(box_position, box_rotation, centre)
    closest = (clamp(local[0], -h[0], h[0]), clamp(local[1], -h[1], h[1]),
               clamp(local[2], -h[2], h[2]))
    offset = sub(local, closest)
    distance = norm(offset)
    if distance > 0.0:
        normal_local = scaled(offset, 1.0 / distance)
        surface_local = closest
        signed = distance
    else:
        # Centre inside (or on) the box: leave through the nearest face.
        best = 0
        best_depth = h[0] - abs(local[0])
        for i in range(1, 3):
            depth = h[i] - abs(local[i])
            if depth < best_depth:
                best, best_depth = i, depth
        side = 1.0 if local[best] >= 0.0 else -1.0
        if best == 0:
            normal_local = (side, 0.0, 0.0)
            surface_local = (side * h[0], local[1], local[2])
        elif best == 1:
            normal_local = (0.0, side, 0.0)
            surface_local = (local[0], side * h[1], local[2])
        else:
            normal_local = (0.0, 0.0, side)
            surface_local = (local[0], local[1], side * h[2])
        signed = -best_depth
    stage_contact(stage, 0, signed - radius, to_world(box_position, box_rotation, surface_local),
                  rotate(box_rotation, normal_local))
    return 1


@njit(cache=True)
def capsule_sphere(position, rotation, capsule_radius, half_length, centre, radius, stage):
    axis = column_of(rotation, 2)
    t = clamp(dot(sub(centre, position), axis), -half_length, half_length)
    on_axis = axpy(t, axis, position)
    offset = sub(centre, on_axis)
    distance = norm(offset)
    if distance > 0.0:
        normal = scaled(offset, 1.0 / distance)
    else:
        normal = column_of(rotation, 0)
    stage_contact(stage, 0, distance - capsule_radius - radius,
                  axpy(capsule_radius, normal, on_axis),
                  normal)
    return 1


@njit(cache=True)
def cylinder_sphere(position, rotation, cylinder_radius, half_length, centre, radius, stage):
    """Sphere against the SOLID finite cylinder (lateral surface and flat ends)."""
    local = to_local(position, rotation, centre)
    radial = math.hypot(local[0], local[1])
    if radial > 0.0:
        radial_direction = (local[0] / radial, local[1] / radial, 0.0)
    else:
        radial_direction = (1.0, 0.0, 0.0)
    if radial > cylinder_radius or abs(local[2]) > half_length:
        r = min(radial, cylinder_radius)
        closest = (radial_direction[0] * r, radial_direction[1] * r,
                   clamp(local[2], -half_length, half_length))
        offset = sub(local, closest)
        distance = norm(offset)
        normal_local = scaled(offset, 1.0 / distance)
        surface_local = closest
        signed = distance
    else:
        radial_depth = cylinder_radius - radial
        axial_depth = half_length - abs(local[2])
        if radial_depth < axial_depth:
            normal_local = radial_direction
            surface_local = (radial_direction[0] * cylinder_radius,
                             radial_direction[1] * cylinder_radius, local[2])
            signed = -radial_depth
        else:
            side = 1.0 if local[2] >= 0.0 else -1.0
            normal_local = (0.0, 0.0, side)
            surface_local = (local[0], local[1], side * half_length)
            signed = -axial_depth
    stage_contact(stage, 0, signed - radius, to_world(position, rotation, surface_local),
                  rotate(rotation, normal_local))
    return 1
