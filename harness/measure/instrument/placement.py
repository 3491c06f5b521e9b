"""World placement of a shape's own frame from its body's pose, with scipy's rotations.

The instrument computes placements itself (not with :mod:`clearbench.kernels.quaternion`), so
that an error in the kernels' quaternion arithmetic cannot hide in both figures.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation


def _rotations(quaternions) -> Rotation:
    """scipy rotations of (T, 4) or (4,) quaternions (w, x, y, z); scipy normalises them."""
    q = np.atleast_2d(np.asarray(quaternions, dtype=np.float64))
    return Rotation.from_quat(q, scalar_first=True)


def shape_placements(shape, body_positions, body_quaternions) -> tuple[np.ndarray, np.ndarray]:
    """World position (T, 3) [L] and rotation (T, 3, 3) (columns: the shape's axes in world) of
    a shape's frame at T poses of its body.

    Parameters
    ----------
    shape : clearbench.scenarios.shapes.Shape
        The shape, with ``position`` (3,) [L] and ``orientation`` (4,) (w, x, y, z) in its
        body's frame.
    body_positions : array_like (T, 3) or (3,)
        World positions of the body frame's origin [L].
    body_quaternions : array_like (T, 4) or (4,)
        World orientations of the body frame, quaternions (w, x, y, z), normalised here.
    """
    body = _rotations(body_quaternions)
    positions = np.atleast_2d(np.asarray(body_positions, dtype=np.float64))
    local = _rotations(shape.orientation)[0]
    world = body * local
    return positions + body.apply(np.asarray(shape.position, dtype=np.float64)), \
        world.as_matrix()


def relative_transforms(rotation_a, position_a, rotation_b, position_b
                        ) -> tuple[np.ndarray, np.ndarray]:
    """The map from shape A's frame to shape B's frame at T configurations: ``q = M p + d``,
    ``M`` (T, 3, 3) = R_B^T R_A, ``d`` (T, 3) [L] = R_B^T (t_A - t_B)."""
    rotation_b_t = np.swapaxes(rotation_b, 1, 2)
    return (np.einsum("tij,tjk->tik", rotation_b_t, rotation_a),
            np.einsum("tij,tj->ti", rotation_b_t, position_a - position_b))
