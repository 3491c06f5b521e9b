"""Bounded plane faces (rectangle, disc; A) against X (B): the plane kernels, then the candidates
whose point on the face lies outside its boundary, or deeper than its depth, are dropped."""

from __future__ import annotations

from clearbench.kernels.gaps.codes import ARC, CIRCLE, CYLINDER, DISC, SPHERE, TWO_PI
from clearbench.kernels.gaps.planes import plane_cylinder, plane_sphere
from clearbench.kernels.gaps.rings import plane_ring
from clearbench.kernels.gaps.staging import copy_staged, within_depth
from clearbench.kernels.gaps.vectors import to_local
from clearbench.kernels.jit import njit


@njit(cache=True, inline="always")
def inside_face(plane_position, plane_rotation, half_x, half_y, radius, depth, stage, k):
    """True if the staged contact ``k`` lies in the face: its point on A (row 1 of the stage)
    within |x| <= half_x and |y| <= half_y (rectangle, radius < 0) or x^2 + y^2 <= radius^2
    (disc) in the face's frame, and its gap not below -depth (depth 0: no bound)."""
    if not within_depth(depth, stage, k):
        return False
    point = (stage[k, 1, 0], stage[k, 1, 1], stage[k, 1, 2])
    local = to_local(plane_position, plane_rotation, point)
    if radius >= 0.0:
        return local[0] * local[0] + local[1] * local[1] <= radius * radius
    return abs(local[0]) <= half_x and abs(local[1]) <= half_y


@njit(cache=True)
def keep_inside_face(plane_position, plane_rotation, half_x, half_y, radius, depth, count,
                     stage):
    """Keep the staged contacts that lie in the face (:func:`inside_face`). Returns the
    number kept (compacted to the front, order preserved)."""
    kept = 0
    for k in range(count):
        if inside_face(plane_position, plane_rotation, half_x, half_y, radius, depth, stage,
                       k):
            if kept != k:
                copy_staged(stage, k, kept)
            kept += 1
    return kept


@njit(cache=True, inline="always")
def face_candidates(plane_position, plane_rotation, kind_b, params_b, position_b, rotation_b,
                    stage):
    """Candidates of a bounded face's plane (A) against X (B) before the face's bounds apply;
    -1 for an X no bounded face is paired with."""
    if kind_b == SPHERE:
        return plane_sphere(plane_position, plane_rotation, position_b, params_b[0], stage)
    if kind_b == CYLINDER:
        return plane_cylinder(plane_position, plane_rotation, position_b, rotation_b,
                              params_b[0], params_b[1], stage)
    if kind_b == CIRCLE:
        return plane_ring(plane_position, plane_rotation, position_b, rotation_b, params_b[0],
                          0.0, TWO_PI, False, stage)
    if kind_b == ARC:
        return plane_ring(plane_position, plane_rotation, position_b, rotation_b, params_b[0],
                          params_b[1], params_b[2] - params_b[1], True, stage)
    return -1


@njit(cache=True, inline="always")
def face_bounds(kind, params):
    """(radius, depth) of a bounded face: a disc's radius, -1 for a rectangle; depth 0: no
    bound."""
    radius = params[0] if kind == DISC else -1.0
    depth = params[1] if kind == DISC else params[2]
    return radius, depth
