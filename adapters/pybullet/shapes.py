"""Collision shapes of PyBullet from the pieces of :mod:`.geometry`."""

from __future__ import annotations

import numpy as np

from clearbench.adapters.pybullet.frames import IDENTITY, to_pb
from clearbench.adapters.pybullet.geometry import check_compound
from clearbench.adapters.pybullet.library import pb


def create_shape(client: int, pieces: tuple) -> int:
    """A collision shape for ``pieces`` in the frame :func:`object_frame` gives: a single piece
    in its own frame (no child transform, so that its margin stays settable), several pieces as
    a compound placed in the body frame (at most 16: PyBullet drops the rest silently)."""
    if len(pieces) == 1:
        return _single_shape(client, pieces[0])
    check_compound(pieces)  # PyBullet would drop the children beyond 16 without a word
    types, radii, halves, lengths, positions, orientations, normals = [], [], [], [], [], [], []
    for piece in pieces:
        kind, radius, half, length = _primitive(piece)
        types.append(kind)
        radii.append(radius)
        halves.append(half)
        lengths.append(length)
        normals.append([0.0, 0.0, 1.0])
        positions.append([float(c) for c in piece.position])
        orientations.append(to_pb(piece.orientation))
    return pb.createCollisionShapeArray(
        shapeTypes=types, radii=radii, halfExtents=halves, lengths=lengths,
        planeNormals=normals, collisionFramePositions=positions,
        collisionFrameOrientations=orientations, physicsClientId=client)


def _primitive(piece) -> tuple[int, float, list, float]:
    """(PyBullet type, radius, half extents, height) of a piece."""
    if piece.kind == "sphere":
        return pb.GEOM_SPHERE, piece.size[0], [0.0, 0.0, 0.0], 0.0
    if piece.kind == "box":
        return pb.GEOM_BOX, 0.0, list(piece.size), 0.0
    if piece.kind == "capsule":  # height: the segment between the centres of the end spheres
        return pb.GEOM_CAPSULE, piece.size[0], [0.0, 0.0, 0.0], 2.0 * piece.size[1]
    if piece.kind == "cylinder":  # height: the full length
        return pb.GEOM_CYLINDER, piece.size[0], [0.0, 0.0, 0.0], 2.0 * piece.size[1]
    if piece.kind == "plane":
        return pb.GEOM_PLANE, 0.0, [0.0, 0.0, 0.0], 0.0
    raise TypeError(f"unhandled piece kind {piece.kind!r}")  # pragma: no cover


def _single_shape(client: int, piece) -> int:
    kind, radius, half, length = _primitive(piece)
    if kind == pb.GEOM_SPHERE:
        return pb.createCollisionShape(kind, radius=radius, physicsClientId=client)
    if kind == pb.GEOM_BOX:
        return pb.createCollisionShape(kind, halfExtents=half, physicsClientId=client)
    if kind == pb.GEOM_PLANE:
        return pb.createCollisionShape(kind, planeNormal=[0, 0, 1], physicsClientId=client)
    return pb.createCollisionShape(kind, radius=radius, height=length, physicsClientId=client)


def object_frame(group: tuple) -> tuple[np.ndarray, np.ndarray]:
    """Body-frame pose of a collision object's own frame: the piece's frame when alone, the
    body frame for a compound."""
    if len(group) == 1:
        return np.asarray(group[0].position, float), np.asarray(group[0].orientation, float)
    return np.zeros(3), IDENTITY.copy()


