"""Library scenes where a body crosses the bound of a face (tag ``edge``): a hoop sliding off a
plate's sharp edge, judged against its analytic path (:mod:`clearbench.scenarios.analytic.edges`).

SI units (m, kg, s), gravity -9.81 m/s^2 along world z.
"""

from __future__ import annotations

import math

from clearbench.scenarios import analytic
from clearbench.scenarios.bodies import Body, Motion
from clearbench.scenarios.contacts import ContactPair
from clearbench.scenarios.expectations import Expectation
from clearbench.scenarios.inertia import diagonal
from clearbench.scenarios.library.basic import GRAVITY
from clearbench.scenarios.registry import register
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.shapes import Circle, Rectangle
from clearbench.scenarios.tags import ANALYTIC, SMOKE

#: Quaternion of +90 degrees about world x: the hoop's circle (its frame's xy-plane) stands in
#: the world xz-plane.
STANDING = (math.sqrt(0.5), math.sqrt(0.5), 0.0, 0.0)


@register("hoop-off-edge", tags=(SMOKE, ANALYTIC, "edge"),
          summary="hoop sliding without friction off a plate's sharp edge: pivots about the "
          "edge, leaves it at cos(theta) = (2 + v0^2/(g r))/3")
def hoop_off_edge(radius: float = 0.1, speed_ratio: float = 0.5, edge_distance: float = 0.05,
                  mass: float = 0.1, plate_depth: float = 0.02) -> Scene:
    """A thin hoop (a circle, no tube) of ``radius`` r [m] stands in the xz-plane on a plate
    whose top face (z = 0) ends in a straight edge along y at x = 0, its lowest point
    ``edge_distance`` [m] before the edge, and slides toward it at v0 = ``speed_ratio``
    sqrt(g r), without friction and without spin. It reaches the edge at a / v0, pivots about
    it with its centre on the circle of radius r about the edge, leaves it at the angle theta1
    from the vertical with cos(theta1) = (2 + speed_ratio^2) / 3 (41.4 degrees at 0.5), and
    flies; the horizon ends 0.05 s after it leaves, while it is still clear of the plate."""
    g = GRAVITY
    v0 = speed_ratio * math.sqrt(g * radius)
    leave = analytic.hoop_over_edge_leave_angle(v0, radius, g)
    leave_time = edge_distance / v0 + analytic.hoop_over_edge_pivot_time(v0, radius, g)
    half_length = 2.0 * radius + edge_distance  # the plate reaches behind the hoop's start
    plate = Body("plate", motion=Motion.FIXED, position=(-half_length, 0.0, 0.0), shapes=(
        Rectangle("top", half_extents=(half_length, radius), depth=plate_depth),))
    # A thin ring: m r^2 about its axis (body z), m r^2 / 2 about a diameter.
    hoop = Body("hoop", mass=mass, inertia=diagonal(0.5 * mass * radius**2,
                                                    0.5 * mass * radius**2, mass * radius**2),
                position=(-edge_distance, 0.0, radius), orientation=STANDING,
                velocity=(v0, 0.0, 0.0), shapes=(Circle("ring", radius=radius),))
    return Scene(
        description=f"A hoop of radius {radius} m sliding at {v0:.4f} m/s, without friction, "
        f"off a plate's sharp edge: it pivots about the edge and leaves it at "
        f"{math.degrees(leave):.1f} degrees from the vertical, at {leave_time:.4f} s.",
        horizon=round(leave_time + 0.05, 3),
        time_step=1e-3,
        bodies=(plate, hoop),
        contacts=(ContactPair("ring_plate", body_a="plate", shape_a="top", body_b="hoop",
                              shape_b="ring"),),
        expectations=(
            Expectation("over_the_edge", kind="hoop_over_edge", body="hoop", parameters={
                "initial_speed": v0, "radius": radius, "gravity": g,
                "edge_distance": edge_distance}),
            Expectation("no_penetration", kind="no_penetration"),
            Expectation("energy", kind="energy_non_increasing"),
        ),
    )
