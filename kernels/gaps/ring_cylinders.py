"""A ring or arc against a cylinder's solid: its point of smallest signed distance to the disc
rho <= radius times |z| <= half_length.

:func:`.rings.ring_cylinder` stages the ring point nearest the cylinder's axis with the radial
gap, the cylinder taken as infinitely long. That point is the ring's nearest to the finite
solid, and the radial gap its signed distance, when it lies within the cylinder's length
outside the lateral surface, or inside the solid no deeper than its distance to the nearer end
face: every other ring point is then at least as far from the axis, so no nearer (outside) or no
deeper (inside). Otherwise (a ring passing the cylinder's end, or through the solid nearer an
end face than the lateral surface) :func:`.round_solids.ring_solid_minimum` gives the point.
"""

from __future__ import annotations

from clearbench.kernels.gaps.rings import ring_cylinder
from clearbench.kernels.gaps.round_solids import CYLINDER_SOLID, ring_solid_minimum
from clearbench.kernels.gaps.staging import stage_contact
from clearbench.kernels.gaps.vectors import (
    column_of,
    rotate,
    rotate_back,
    scaled,
    to_local,
    to_world,
)
from clearbench.kernels.jit import njit


@njit(cache=True)
def ring_cylinder_solid(ring_position, ring_rotation, ring_radius, start_angle, span, is_arc,
                        cylinder_position, cylinder_rotation, cylinder_radius,
                        cylinder_half_length, stage):
    """Ring (A; an arc from ``start_angle`` over ``span`` [rad] when ``is_arc``) against the
    cylinder's solid (B): one candidate, its point on the ring, the normal from A into B (the
    solid's inward direction there). Returns 1."""
    ring_cylinder(ring_position, ring_rotation, ring_radius, start_angle, span, is_arc,
                  cylinder_position, cylinder_rotation, cylinder_radius, stage)
    gap = stage[0, 2, 0]
    ring_point = (stage[0, 1, 0], stage[0, 1, 1], stage[0, 1, 2])
    beyond_end = abs(to_local(cylinder_position, cylinder_rotation, ring_point)[2]) \
        - cylinder_half_length
    if beyond_end <= 0.0 and (gap >= 0.0 or beyond_end <= gap):
        return 1
    _, smallest, point, gradient = ring_solid_minimum(
        CYLINDER_SOLID, to_local(cylinder_position, cylinder_rotation, ring_position),
        rotate_back(cylinder_rotation, column_of(ring_rotation, 0)),
        rotate_back(cylinder_rotation, column_of(ring_rotation, 1)), ring_radius, start_angle,
        span, is_arc, cylinder_radius, cylinder_half_length, 0.0, 0.0, 0.0)
    stage_contact(stage, 0, smallest, to_world(cylinder_position, cylinder_rotation, point),
                  rotate(cylinder_rotation, scaled(gradient, -1.0)))
    return 1
