"""The solid behind a plane face, and the signed distance of a point to it.

A face's solid, in the face's own frame (material below z = 0, +z out of it):

- plane: the half-space z <= 0;
- rectangle: the slab |x| <= half_x, |y| <= half_y, -depth <= z <= 0 (depth 0: unbounded below,
  the prism z <= 0);
- disc: x^2 + y^2 <= radius^2, -depth <= z <= 0 (depth 0: unbounded below).

:func:`face_solid_distance` is the exact signed distance to that solid: outside, the distance to
its closest point (the top face above it, an edge or a corner beyond its bound), whose gradient
is continuous outside a convex solid; inside, minus the distance to the nearest boundary face
(continuous, its gradient jumping across the medial planes). Every pair against a face takes
its gap from it, so a partner crossing the face's bound meets the face's edge instead of
vanishing, and a partner gone round behind the solid meets its back.
"""

from __future__ import annotations

import math

from clearbench.kernels.gaps.codes import DISC, PLANE
from clearbench.kernels.jit import njit


@njit(cache=True, inline="always")
def face_solid_parameters(kind, params):
    """(size_1, size_2, depth) of a face from its packed parameters: (half_x, half_y, depth)
    for a rectangle, (radius, 0, depth) for a disc, zeros for a plane [L]; depth 0: unbounded."""
    if kind == PLANE:
        return 0.0, 0.0, 0.0
    if kind == DISC:
        return params[0], 0.0, params[1]
    return params[0], params[1], params[2]


@njit(cache=True, inline="always")
def through_thickness(z, depth):
    """(q, side) of the thickness: q = signed distance to the nearer of the top (z = 0) and
    bottom (z = -depth) planes as a box coordinate (|z - centre| - half thickness), side = +1
    toward the top, -1 toward the bottom; depth 0: the top plane alone (q = z, side +1)."""
    if depth <= 0.0:
        return z, 1.0
    half = 0.5 * depth
    centred = z + half
    return abs(centred) - half, 1.0 if centred >= 0.0 else -1.0


@njit(cache=True, inline="always")
def product_distance(first, first_gradient, second, second_gradient):
    """Signed distance [L] to the product of two sets in orthogonal subspaces, and its unit
    gradient, from each set's signed distance (``first``, ``second``) and unit gradient
    (3-tuples, each in its own subspace): outside, the hypotenuse of the parts that are
    outside; inside, the larger (less negative) of the two, ``first`` on ties."""
    out_first = max(first, 0.0)
    out_second = max(second, 0.0)
    outside = math.hypot(out_first, out_second)
    if outside > 0.0:
        return outside, ((first_gradient[0] * out_first + second_gradient[0] * out_second)
                         / outside,
                         (first_gradient[1] * out_first + second_gradient[1] * out_second)
                         / outside,
                         (first_gradient[2] * out_first + second_gradient[2] * out_second)
                         / outside)
    if first >= second:
        return first, first_gradient
    return second, second_gradient


@njit(cache=True)
def face_solid_distance(kind, size_1, size_2, depth, local):
    """Signed distance [L] from the face-frame point ``local`` (3-tuple) to the face's solid
    (module docstring), and its unit gradient (face frame): > 0 outside, the direction from the
    solid's closest point to ``local``; < 0 inside, the outward normal of the nearest boundary
    face (the top face on ties). ``local - distance * gradient`` is the solid's surface point
    nearest ``local``.

    Parameters
    ----------
    kind : int
        PLANE, RECTANGLE or DISC.
    size_1, size_2, depth : float
        :func:`face_solid_parameters` [L].
    local : tuple of 3 floats
        The point in the face's frame [L].
    """
    x, y, z = local
    q_z, side_z = through_thickness(z, depth)
    if kind == PLANE:
        return z, (0.0, 0.0, 1.0)
    if kind == DISC:
        radial = math.hypot(x, y)
        if radial > 0.0:
            u_x, u_y = x / radial, y / radial
        else:
            u_x, u_y = 1.0, 0.0
        return product_distance(q_z, (0.0, 0.0, side_z), radial - size_1, (u_x, u_y, 0.0))
    side_x = 1.0 if x >= 0.0 else -1.0
    side_y = 1.0 if y >= 0.0 else -1.0
    q_x = abs(x) - size_1
    q_y = abs(y) - size_2
    out_x = max(q_x, 0.0)
    out_y = max(q_y, 0.0)
    out_z = max(q_z, 0.0)
    outside = math.sqrt(out_x * out_x + out_y * out_y + out_z * out_z)
    if outside > 0.0:
        return outside, (side_x * out_x / outside, side_y * out_y / outside,
                         side_z * out_z / outside)
    if q_z >= q_x and q_z >= q_y:
        return q_z, (0.0, 0.0, side_z)
    if q_x >= q_y:
        return q_x, (side_x, 0.0, 0.0)
    return q_y, (0.0, side_y, 0.0)
