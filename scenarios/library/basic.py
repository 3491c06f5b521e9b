"""Library scenes with one body on a ground plane: impacts, friction, rolling, rocking, stacks.

All in SI units (m, kg, s), gravity -9.81 m/s^2 along world z unless stated. Each scene carries
the expectation it is judged by (see :mod:`.expectations`).
"""

from __future__ import annotations

import math

from clearbench.scenarios import analytic
from clearbench.scenarios.bodies import Body, Motion
from clearbench.scenarios.contacts import ContactPair
from clearbench.scenarios.expectations import Expectation
from clearbench.scenarios.inertia import solid_box, solid_sphere
from clearbench.scenarios.outputs import PointPosition
from clearbench.scenarios.registry import register
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.shapes import Box, Plane, Sphere
from clearbench.scenarios.tags import ANALYTIC, SMOKE

GRAVITY = 9.81  # m/s^2


def ground(name: str = "ground", orientation: tuple = (1.0, 0.0, 0.0, 0.0)) -> Body:
    """A fixed body carrying the plane z = 0 (rotated by ``orientation``)."""
    return Body(name, motion=Motion.FIXED, orientation=orientation, shapes=(Plane("floor"),))


def _tilt_about_y(angle: float) -> tuple:
    """Quaternion of a rotation by ``angle`` about world y (a slope descending toward +x)."""
    return (math.cos(0.5 * angle), 0.0, math.sin(0.5 * angle), 0.0)


def bouncing_ball(restitution: float, drop_height: float = 1.0, radius: float = 0.1,
                  mass: float = 1.0) -> Scene:
    """Ball dropped from rest, its lowest point ``drop_height`` [m] above the plane."""
    v0 = math.sqrt(2.0 * GRAVITY * drop_height)
    rest = (v0 / GRAVITY) * (1.0 + restitution) / (1.0 - restitution)
    return Scene(
        description=f"Ball dropped from {drop_height} m onto a plane, Newton restitution "
        f"{restitution}, no friction; apex heights e^(2k) h0, at rest after {rest:.3f} s.",
        horizon=round(rest + 0.5, 3),
        time_step=1e-3,
        bodies=(
            ground(),
            Body("ball", mass=mass, inertia=solid_sphere(mass, radius),
                 position=(0.0, 0.0, drop_height + radius),
                 shapes=(Sphere("sphere", radius=radius),)),
        ),
        contacts=(ContactPair("ball_floor", body_a="ground", shape_a="floor",
                              body_b="ball", shape_b="sphere", restitution=restitution),),
        expectations=(
            Expectation("apex_heights", kind="bounce_apex", body="ball", parameters={
                "drop_height": drop_height, "restitution": restitution, "gravity": GRAVITY}),
            Expectation("no_penetration", kind="no_penetration"),
            Expectation("energy", kind="energy_non_increasing"),
        ),
    )


for _e in (0.0, 0.5, 0.9):
    register(f"bouncing-ball-e{_e:g}", tags=(SMOKE, ANALYTIC, "impact"),
             summary=f"ball dropped 1 m on a plane, restitution {_e:g}",
             restitution=_e)(bouncing_ball)


def _box_on_incline(angle: float, friction: float, summary: str) -> Scene:
    half = (0.1, 0.1, 0.05)
    mass = 1.0
    tilt = _tilt_about_y(angle)
    # Box centre one half-height above the origin along the tilted plane's normal.
    normal = (math.sin(angle), 0.0, math.cos(angle))
    centre = tuple(half[2] * n for n in normal)
    sticks = math.tan(angle) <= friction
    expectation = (
        Expectation("stick", kind="incline_stick", body="box",
                    parameters={"angle": angle, "friction": friction})
        if sticks else
        Expectation("slide", kind="incline_slide", body="box",
                    parameters={"angle": angle, "friction": friction, "gravity": GRAVITY})
    )
    return Scene(
        description=summary,
        horizon=1.0,
        time_step=1e-3,
        bodies=(
            ground(orientation=tilt),
            Body("box", mass=mass, inertia=solid_box(mass, half), position=centre,
                 orientation=tilt, shapes=(Box("box", half_extents=half),)),
        ),
        contacts=(ContactPair("box_floor", body_a="ground", shape_a="floor", body_b="box",
                              shape_b="box", friction=friction),),
        expectations=(expectation, Expectation("no_penetration", kind="no_penetration"),
                      Expectation("energy", kind="energy_non_increasing")),
    )


@register("incline-stick", tags=(SMOKE, ANALYTIC, "friction"),
          summary="box on a 10 degree incline, mu 0.3: must not move")
def incline_stick(angle_degrees: float = 10.0, friction: float = 0.3) -> Scene:
    return _box_on_incline(
        math.radians(angle_degrees), friction,
        f"Box released on a {angle_degrees} degree incline with mu {friction} "
        "(tan(angle) < mu): exact stick, it must not move.",
    )


@register("incline-slide", tags=(ANALYTIC, "friction"),
          summary="box on a 30 degree incline, mu 0.3: slides at g(sin - mu cos)")
def incline_slide(angle_degrees: float = 30.0, friction: float = 0.3) -> Scene:
    return _box_on_incline(
        math.radians(angle_degrees), friction,
        f"Box released on a {angle_degrees} degree incline with mu {friction} "
        "(tan(angle) > mu): slides with acceleration g (sin - mu cos).",
    )


@register("sliding-box", tags=(SMOKE, ANALYTIC, "friction"),
          summary="box launched at 2 m/s on a plane, mu 0.3: stops at v0^2/(2 mu g)")
def sliding_box(initial_speed: float = 2.0, friction: float = 0.3) -> Scene:
    half = (0.1, 0.1, 0.05)
    mass = 1.0
    stop = initial_speed / (friction * GRAVITY)
    return Scene(
        description=f"Box launched at {initial_speed} m/s on a plane with mu {friction}: "
        f"stops after {stop:.4f} s at {initial_speed**2 / (2 * friction * GRAVITY):.4f} m.",
        horizon=round(stop + 0.3, 3),
        time_step=1e-3,
        bodies=(
            ground(),
            Body("box", mass=mass, inertia=solid_box(mass, half), position=(0.0, 0.0, half[2]),
                 velocity=(initial_speed, 0.0, 0.0), shapes=(Box("box", half_extents=half),)),
        ),
        contacts=(ContactPair("box_floor", body_a="ground", shape_a="floor", body_b="box",
                              shape_b="box", friction=friction),),
        expectations=(
            Expectation("stop", kind="sliding_stop", body="box", parameters={
                "initial_speed": initial_speed, "friction": friction, "gravity": GRAVITY}),
            Expectation("no_penetration", kind="no_penetration"),
            Expectation("energy", kind="energy_non_increasing"),
        ),
    )


@register("rolling-sphere", tags=(ANALYTIC, "friction"),
          summary="sphere launched sliding without spin: rolls from 2 v0/(7 mu g) at 5 v0/7")
def rolling_sphere(initial_speed: float = 2.0, friction: float = 0.2,
                   radius: float = 0.1) -> Scene:
    mass = 1.0
    transition = 2.0 * initial_speed / (7.0 * friction * GRAVITY)
    return Scene(
        description=f"Solid sphere launched at {initial_speed} m/s without spin, mu {friction}: "
        f"rolls without slip from {transition:.4f} s at {5 * initial_speed / 7:.4f} m/s.",
        horizon=round(transition + 0.3, 3),
        time_step=1e-3,
        bodies=(
            ground(),
            Body("ball", mass=mass, inertia=solid_sphere(mass, radius),
                 position=(0.0, 0.0, radius), velocity=(initial_speed, 0.0, 0.0),
                 shapes=(Sphere("sphere", radius=radius),)),
        ),
        contacts=(ContactPair("ball_floor", body_a="ground", shape_a="floor", body_b="ball",
                              shape_b="sphere", friction=friction),),
        expectations=(
            Expectation("rolling", kind="rolling_transition", body="ball", parameters={
                "initial_speed": initial_speed, "friction": friction, "gravity": GRAVITY,
                "radius": radius}),
            Expectation("no_penetration", kind="no_penetration"),
            Expectation("energy", kind="energy_non_increasing"),
        ),
    )


@register("rolling-incline", tags=(ANALYTIC, "friction"),
          summary="sphere released on a 20 degree incline, mu 0.5: rolls at 5/7 g sin")
def rolling_incline(angle_degrees: float = 20.0, friction: float = 0.5,
                    radius: float = 0.1) -> Scene:
    mass = 1.0
    angle = math.radians(angle_degrees)
    tilt = _tilt_about_y(angle)
    # Centre one radius above the origin along the tilted plane's normal; the slope descends
    # toward +x along (cos, 0, -sin).
    centre = (radius * math.sin(angle), 0.0, radius * math.cos(angle))
    acceleration = analytic.rolling_incline_acceleration(angle, GRAVITY, 0.4)  # 2/5 m r^2
    probe_time = 0.5  # s
    travel = 0.5 * acceleration * probe_time**2
    return Scene(
        description=f"Solid sphere released at rest on a {angle_degrees} degree incline with "
        f"mu {friction} (tan(angle) <= 7/2 mu): rolls without slipping at "
        f"{acceleration:.4f} m/s^2.",
        horizon=0.7,
        time_step=1e-3,
        bodies=(
            ground(orientation=tilt),
            Body("ball", mass=mass, inertia=solid_sphere(mass, radius), position=centre,
                 orientation=tilt, shapes=(Sphere("sphere", radius=radius),)),
        ),
        contacts=(ContactPair("ball_floor", body_a="ground", shape_a="floor", body_b="ball",
                              shape_b="sphere", friction=friction),),
        outputs=(PointPosition("ball_x", body="ball", component="x"),),
        expectations=(
            Expectation("rolling", kind="rolling_incline", body="ball", parameters={
                "angle": angle, "gravity": GRAVITY, "radius": radius}),
            # The centre's x at 0.5 s, within 2 % of the distance travelled by then (the
            # rolling criterion's 2 %).
            Expectation("ball_x_at_half_second", kind="output_value", output="ball_x",
                        parameters={"value": centre[0] + travel * math.cos(angle),
                                    "absolute_tolerance": 0.02 * travel * math.cos(angle),
                                    "time": probe_time}),
            Expectation("no_penetration", kind="no_penetration"),
            Expectation("energy", kind="energy_non_increasing"),
        ),
    )


@register("rocking-block", tags=(ANALYTIC, "impact", "friction"),
          summary="Housner rocking block: angular-velocity ratio 1 - 1.5 sin^2(alpha)")
def rocking_block(half_width: float = 0.05, half_height: float = 0.25,
                  initial_tilt: float = 0.1, friction: float = 1.0) -> Scene:
    """Slender block released from rest tilted by ``initial_tilt`` [rad] about its corner.

    High friction and plastic impacts (e = 0) are Housner's assumptions: no sliding, no bounce.
    """
    mass = 1.0
    half = (half_width, 0.05, half_height)
    # Rotate about world y by +tilt around the corner (+half_width, 0, 0) that stays on the
    # plane; the opposite bottom corner rises by 2 half_width sin(tilt).
    tilt = initial_tilt
    corner = (half_width, 0.0, 0.0)
    offset = (-half_width, 0.0, half_height)  # centre relative to that corner, untilted
    c, s = math.cos(tilt), math.sin(tilt)
    centre = (corner[0] + c * offset[0] + s * offset[2], 0.0, -s * offset[0] + c * offset[2])
    return Scene(
        description=f"Block {2 * half_width} x {2 * half_height} m released tilted by "
        f"{initial_tilt} rad on its corner (mu {friction}, e = 0): Housner's rocking, "
        "angular-velocity ratio 1 - 1.5 sin^2(alpha) at each impact.",
        horizon=1.5,
        time_step=1e-3,
        bodies=(
            ground(),
            Body("block", mass=mass, inertia=solid_box(mass, half), position=centre,
                 orientation=_tilt_about_y(tilt), shapes=(Box("box", half_extents=half),)),
        ),
        contacts=(ContactPair("block_floor", body_a="ground", shape_a="floor", body_b="block",
                              shape_b="box", friction=friction),),
        expectations=(
            Expectation("housner", kind="rocking_ratio", body="block", parameters={
                "half_width": half_width, "half_height": half_height, "gravity": GRAVITY}),
            Expectation("no_penetration", kind="no_penetration"),
            Expectation("energy", kind="energy_non_increasing"),
        ),
    )


@register("box-grid", tags=("many_contacts", "friction"),
          summary="26 boxes resting on a plane: 104 active corner contacts")
def box_grid(count: int = 26, friction: float = 0.5) -> Scene:
    """``count`` boxes side by side on a plane, dropped 1 mm: a scene with 4 x count
    simultaneously active contacts for benchmarks and the many-contacts stability case."""
    half = (0.05, 0.05, 0.05)
    mass = 1.0
    bodies = [ground()]
    contacts = []
    columns = math.ceil(math.sqrt(count))
    for index in range(count):
        row, column = divmod(index, columns)
        name = f"box{index:03d}"
        bodies.append(Body(name, mass=mass, inertia=solid_box(mass, half),
                           position=(0.15 * column, 0.15 * row, half[2] + 1e-3),
                           shapes=(Box("box", half_extents=half),)))
        contacts.append(ContactPair(f"{name}_floor", body_a="ground", shape_a="floor",
                                    body_b=name, shape_b="box", friction=friction))
    return Scene(
        description=f"{count} boxes dropped 1 mm onto a plane (mu {friction}); they settle with "
        f"{4 * count} active corner contacts.",
        horizon=0.2,
        time_step=1e-3,
        bodies=tuple(bodies),
        contacts=tuple(contacts),
        expectations=(Expectation("no_penetration", kind="no_penetration"),
                      Expectation("energy", kind="energy_non_increasing")),
    )
