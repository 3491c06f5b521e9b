"""Contact frames: a right-handed orthonormal basis (n, t1, t2) built from a unit normal n.

The frame is a function of the normal alone, so every engine and metric expresses tangential
quantities in the same axes. Rows of the (3, 3) frame matrix are (n, t1, t2), with
``t1 x t2 = n`` (determinant +1).

Construction (the "pole" construction of Frisvad 2012, with the numerically careful evaluation
and re-orthogonalisation that Duff et al. 2017, "Building an orthonormal basis, revisited",
JCGT 6(1), show to be needed): t1 is the image of a fixed unit vector ``e1`` under the minimal
rotation taking a fixed pole ``p`` to ``n``, made exactly orthogonal to ``n`` and unit; then
``t2 = n x t1``.

Discontinuity set: the single direction ``n = -p`` (:data:`FRAME_SINGULAR_DIRECTION`), where the
minimal rotation is undefined. The frame is defined there too, as (-p, -e1, e2) (the limit
along the rotation by pi about e2), and is accurate to round-off, but the tangents turn quickly
for normals within a few degrees of it. Everywhere else the frame is a smooth (C-infinity)
function of n.
Duff et al.'s own two-chart formula switches hemispheres at n_z = 0, which would make the frame
discontinuous on the whole great circle of normals perpendicular to z, exactly where a journal
with its axis along z puts its contact normals; a single, deliberately generic singular
direction avoids that. The pole is ``p = (2, 3, 6) / 7``, ``e1 = (3, -2, 0) / sqrt(13)``: the
singular direction is at least 24.6 degrees away from every axis direction (+-x, +-y, +-z),
face diagonal and body diagonal, so no normal of an axis-aligned configuration comes near it.

Accuracy: ``|F F^T - I| <= ~4 ulp`` and ``det F = 1`` to round-off for every unit normal,
including the normals at and near the singular direction (tested).
"""

from __future__ import annotations

import math

import numpy as np

from clearbench.kernels.jit import njit

__all__ = [
    "FRAME_POLE",
    "FRAME_SINGULAR_DIRECTION",
    "contact_frame",
    "contact_frames_batch",
    "frame_tangent",
    "write_contact_frame",
    "write_unit_contact_frame",
]

_POLE = np.array([2.0, 3.0, 6.0]) / 7.0
_E1 = np.array([3.0, -2.0, 0.0]) / math.sqrt(13.0)  # unit, orthogonal to the pole
_E2 = np.cross(_POLE, _E1)  # (e1, e2, pole) right-handed

#: The pole p: the normal whose frame is exactly (p, e1, e2).
FRAME_POLE = tuple(float(x) for x in _POLE)
#: The one normal direction (-p) where the frame is discontinuous.
FRAME_SINGULAR_DIRECTION = tuple(float(-x) for x in _POLE)

_PX, _PY, _PZ = (float(x) for x in _POLE)
_E1X, _E1Y, _E1Z = (float(x) for x in _E1)


@njit(cache=True, error_model="numpy")
def frame_tangent(nx, ny, nz):
    """First tangent t1 (3-tuple) of the frame of the normal (nx, ny, nz), unit to round-off.

    No arrays: compiled callers use it without reference counting. The second tangent is
    ``t2 = n x t1``. See the module docstring for the construction.
    """
    # v = p x n, c = p . n: the minimal rotation p -> n is I + [v]x + [v]x^2 / (1 + c).
    vx = _PY * nz - _PZ * ny
    vy = _PZ * nx - _PX * nz
    vz = _PX * ny - _PY * nx
    c = _PX * nx + _PY * ny + _PZ * nz
    v_squared = vx * vx + vy * vy + vz * vz
    # [v]x e1 = v x e1; [v]x^2 e1 = v (v . e1) - e1 |v|^2.
    cx = vy * _E1Z - vz * _E1Y
    cy = vz * _E1X - vx * _E1Z
    cz = vx * _E1Y - vy * _E1X
    v_dot_e1 = vx * _E1X + vy * _E1Y + vz * _E1Z
    if c >= 0.0:
        factor = 1.0 / (1.0 + c)
    elif v_squared > 0.0:
        # 1 + c = |v|^2 / (1 - c) without cancellation near c = -1.
        factor = (1.0 - c) / v_squared
    else:
        # n = -p exactly: the limit along the rotation by pi about e2 (t1 = -e1).
        return -_E1X, -_E1Y, -_E1Z
    tx = _E1X + cx + (vx * v_dot_e1 - _E1X * v_squared) * factor
    ty = _E1Y + cy + (vy * v_dot_e1 - _E1Y * v_squared) * factor
    tz = _E1Z + cz + (vz * v_dot_e1 - _E1Z * v_squared) * factor
    # Re-orthogonalise against n and normalise (exact orthonormality near the singular point).
    along = tx * nx + ty * ny + tz * nz
    tx, ty, tz = tx - along * nx, ty - along * ny, tz - along * nz
    inverse_norm = 1.0 / math.sqrt(tx * tx + ty * ty + tz * tz)
    return tx * inverse_norm, ty * inverse_norm, tz * inverse_norm


@njit(cache=True)
def write_unit_contact_frame(nx, ny, nz, out, index):
    """Write the frame of (nx, ny, nz), a normal already unit to round-off, into ``out[index]``
    (rows n, t1, t2). The normal is written as given (no renormalisation: the frame of ``-n``
    then has exactly ``-n`` as first row)."""
    tx, ty, tz = frame_tangent(nx, ny, nz)
    out[index, 0, 0] = nx
    out[index, 0, 1] = ny
    out[index, 0, 2] = nz
    out[index, 1, 0] = tx
    out[index, 1, 1] = ty
    out[index, 1, 2] = tz
    out[index, 2, 0] = ny * tz - nz * ty
    out[index, 2, 1] = nz * tx - nx * tz
    out[index, 2, 2] = nx * ty - ny * tx


@njit(cache=True)
def write_contact_frame(nx, ny, nz, out, index):
    """Write the frame of the normal (nx, ny, nz) into ``out[index]`` (rows n, t1, t2).

    Parameters
    ----------
    nx, ny, nz : float
        Normal; it is normalised here, and the first row written is n / |n|.
    out : ndarray (K, 3, 3)
        Output frames.
    index : int
        Which frame of ``out`` to write.
    """
    inverse_norm = 1.0 / math.sqrt(nx * nx + ny * ny + nz * nz)
    write_unit_contact_frame(nx * inverse_norm, ny * inverse_norm, nz * inverse_norm, out, index)


@njit(cache=True)
def contact_frame(normal):
    """Frame (3, 3) with rows (n, t1, t2) of the unit normal ``normal`` (3,); see module doc."""
    out = np.empty((1, 3, 3))
    write_contact_frame(normal[0], normal[1], normal[2], out, 0)
    return out[0]


@njit(cache=True)
def _frames_flat(normals, out):
    for i in range(normals.shape[0]):
        write_contact_frame(normals[i, 0], normals[i, 1], normals[i, 2], out, i)


def contact_frames_batch(normals) -> np.ndarray:
    """Frames (..., 3, 3) of unit normals (..., 3); same function as :func:`contact_frame`."""
    normals = np.asarray(normals, dtype=np.float64)
    flat = np.ascontiguousarray(normals.reshape(-1, 3))
    out = np.empty((flat.shape[0], 3, 3))
    _frames_flat(flat, out)
    return out.reshape(normals.shape[:-1] + (3, 3))
