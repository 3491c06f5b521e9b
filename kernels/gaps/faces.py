"""Faces with a solid behind them (plane, rectangle, disc; A) against sphere, cylinder and ring
(B): every candidate's gap is its signed distance to the face's solid
(:func:`~.face_solids.face_solid_distance`), so a partner crossing a bounded face's edge meets
the edge (its gap and normal continuous), and one gone round behind the solid meets its back.
"""

from __future__ import annotations

from clearbench.kernels.gaps.codes import ARC, CIRCLE, CYLINDER, SPHERE, TWO_PI
from clearbench.kernels.gaps.face_solids import face_solid_distance, face_solid_parameters
from clearbench.kernels.gaps.planes import cylinder_rim_point, lowest_direction
from clearbench.kernels.gaps.ring_faces import ring_face
from clearbench.kernels.gaps.staging import stage_contact
from clearbench.kernels.gaps.vectors import column_of, rotate, scaled, sub, to_local, to_world
from clearbench.kernels.jit import njit


@njit(cache=True, inline="always")
def _stage_point(index, point, radius, kind, size_1, size_2, depth, face_position,
                 face_rotation, stage):
    """Stage the contact of the world ``point`` swept by ``radius`` (0: a bare point) with the
    face's solid: gap = the point's signed distance to the solid - radius."""
    local = to_local(face_position, face_rotation, point)
    distance, gradient = face_solid_distance(kind, size_1, size_2, depth, local)
    on_face = sub(local, scaled(gradient, distance))
    stage_contact(stage, index, distance - radius, to_world(face_position, face_rotation,
                                                            on_face),
                  rotate(face_rotation, gradient))


@njit(cache=True)
def face_sphere(kind, size_1, size_2, depth, face_position, face_rotation, centre, radius,
                stage):
    """Sphere (B) against a bounded face's solid (A): one candidate, its centre's distance to
    the solid minus its radius."""
    _stage_point(0, centre, radius, kind, size_1, size_2, depth, face_position, face_rotation,
                 stage)
    return 1


@njit(cache=True)
def face_cylinder(kind, size_1, size_2, depth, face_position, face_rotation, position,
                  rotation, radius, half_length, stage):
    """Cylinder (B) against a bounded face's solid (A): the eight rim points of the plane pair
    (:func:`~.planes.plane_cylinder`, chosen with respect to the face's normal), each with its
    distance to the solid. The lateral surface against the face's edge is not a candidate."""
    normal = column_of(face_rotation, 2)
    axis = column_of(rotation, 2)
    lowest, quarter = lowest_direction(normal, rotation)
    for index in range(8):
        point = cylinder_rim_point(index, position, axis, lowest, quarter, radius, half_length)
        _stage_point(index, point, 0.0, kind, size_1, size_2, depth, face_position,
                     face_rotation, stage)
    return 8


@njit(cache=True, inline="always")
def face_contacts(kind_a, params_a, position_a, rotation_a, kind_b, params_b, position_b,
                  rotation_b, stage):
    """Candidates of a face's solid (A: plane, rectangle, disc) against X (B: sphere,
    cylinder, circle, arc); -1 for an X this module does not pair with a face."""
    size_1, size_2, depth = face_solid_parameters(kind_a, params_a)
    if kind_b == SPHERE:
        return face_sphere(kind_a, size_1, size_2, depth, position_a, rotation_a, position_b,
                           params_b[0], stage)
    if kind_b == CYLINDER:
        return face_cylinder(kind_a, size_1, size_2, depth, position_a, rotation_a,
                             position_b, rotation_b, params_b[0], params_b[1], stage)
    if kind_b == CIRCLE:
        return ring_face(kind_a, size_1, size_2, depth, position_a, rotation_a, position_b,
                         rotation_b, params_b[0], 0.0, TWO_PI, False, stage)
    if kind_b == ARC:
        return ring_face(kind_a, size_1, size_2, depth, position_a, rotation_a, position_b,
                         rotation_b, params_b[0], params_b[1], params_b[2] - params_b[1], True,
                         stage)
    return -1
