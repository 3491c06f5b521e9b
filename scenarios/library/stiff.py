"""The stiff and extreme suite: variants of the library scenes that stress an engine.

Each variant is built from a library factory with other parameters, or from its scene with
:func:`dataclasses.replace`, and is registered with the tag ``stiff`` (``clearbench
stability`` runs every scene with that tag). SI units. Every variant keeps expectations that say
what physics requires, so that the harness can tell a stable but wrong run from a right one.
"""

from __future__ import annotations

import dataclasses
import math

from clearbench.scenarios.bodies import Body, Motion
from clearbench.scenarios.contacts import ContactPair
from clearbench.scenarios.expectations import Expectation
from clearbench.scenarios.inertia import solid_sphere
from clearbench.scenarios.library.basic import GRAVITY, bouncing_ball, box_grid, incline_stick
from clearbench.scenarios.library.mechanisms import clearance_pendulum, slider_crank
from clearbench.scenarios.loads import LinearSpringDamper
from clearbench.scenarios.outputs import PointPosition
from clearbench.scenarios.registry import register
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.shapes import Box
from clearbench.scenarios.tags import STIFF
from clearbench.scenarios.units import UnitSystem


def _described(scene: Scene, description: str, **changes) -> Scene:
    """The scene with a new description (the registry gives it its name and tags)."""
    return dataclasses.replace(scene, description=description, **changes)


@register("stiff-tight-clearance", tags=(STIFF, "clearance"),
          summary="clearance pendulum with radial and axial clearance 1e-5 of the journal radius")
def tight_clearance(relative_clearance: float = 1e-5) -> Scene:
    journal_radius = 0.01
    clearance = relative_clearance * journal_radius
    scene = clearance_pendulum(radial_clearance=clearance, axial_clearance=clearance,
                               journal_radius=journal_radius)
    return _described(
        scene, f"The clearance pendulum with radial and axial clearance {clearance:g} m "
        f"({relative_clearance:g} of the journal radius): the journal must stay in "
        "its bore without chatter or drift.", horizon=1.0)


@register("stiff-mass-ratio", tags=(STIFF, "joints"),
          summary="slider-crank whose slider is 1e4 times heavier than its connecting rod")
def mass_ratio(ratio: float = 1e4) -> Scene:
    scene = slider_crank()
    rod = scene.body("rod")
    slider = scene.body("slider")
    factor = ratio * rod.mass / slider.mass
    heavy = dataclasses.replace(
        slider, mass=slider.mass * factor,
        inertia=tuple(tuple(factor * value for value in row) for row in slider.inertia))
    bodies = tuple(heavy if b.name == "slider" else b for b in scene.bodies)
    return _described(
        scene, f"The driven slider-crank with a slider {ratio:g} times heavier than the "
        "rod across the wrist pin: the kinematics must still hold.", bodies=bodies)


@register("stiff-spring", tags=(STIFF, "springs"),
          summary="ball on a linear spring with omega * dt = 10 at the comfortable step")
def stiff_spring(omega_dt: float = 10.0, time_step: float = 1e-3,
                 initial_stretch: float = 1e-3) -> Scene:
    """A 1 kg ball hung on an undamped spring of stiffness m (omega_dt / dt)^2 [N/m] (period
    far shorter than the step), released stretched by ``initial_stretch`` [m]: energy must not
    grow (an explicit method explodes)."""
    ball = bouncing_ball(restitution=0.5).body("ball")
    stiffness = ball.mass * (omega_dt / time_step) ** 2
    length = 0.5
    anchor = (0.0, 0.0, ball.position[2] + length)
    spring = LinearSpringDamper("spring", body_a="anchor", point_a=anchor, body_b="ball",
                                stiffness=stiffness, rest_length=length - initial_stretch)
    return Scene(
        description=f"Ball ({ball.mass} kg) on an undamped spring of stiffness {stiffness:.3g} "
        f"N/m (omega dt = {omega_dt:g} at dt = {time_step:g} s), released stretched by "
        f"{initial_stretch} m: energy must not grow.",
        horizon=0.5,
        time_step=time_step,
        bodies=(Body("anchor", motion=Motion.FIXED), dataclasses.replace(ball, shapes=())),
        loads=(spring,),
        outputs=(PointPosition("height", body="ball", component="z"),),
        expectations=(Expectation("energy", kind="energy_non_increasing"),),
    )


@register("stiff-large-step-ball", tags=(STIFF, "impact"),
          summary="bouncing ball (e = 0.5) at a step 10 times the comfortable one")
def large_step_ball(step_factor: float = 10.0) -> Scene:
    scene = bouncing_ball(restitution=0.5)
    return _described(
        scene, f"{scene.description} Run at {step_factor:g} times the comfortable step.",
        time_step=scene.time_step * step_factor)


@register("stiff-large-step-clearance", tags=(STIFF, "clearance"),
          summary="clearance pendulum at a step 10 times the comfortable one")
def large_step_clearance(step_factor: float = 10.0) -> Scene:
    scene = clearance_pendulum()
    return _described(
        scene, f"{scene.description} Run at {step_factor:g} times the comfortable step.",
        time_step=scene.time_step * step_factor)


@register("stiff-tunnelling", tags=(STIFF, "impact"),
          summary="5 mm ball at 50 m/s onto a 2 mm plate: 50 mm per step, it must not tunnel")
def tunnelling(speed: float = 50.0, radius: float = 0.005,
               plate_half_thickness: float = 0.001) -> Scene:
    """A ball of radius ``radius`` [m] launched at ``speed`` [m/s] onto a thin fixed plate (top
    face at z = 0) with e = 0: it must come to rest on the plate and stay there (a discrete
    collision test misses the plate when speed * dt exceeds the plate and ball thickness)."""
    mass = 0.1
    scene = bouncing_ball(restitution=0.0, radius=radius, mass=mass, drop_height=0.05)
    ball = scene.body("ball")
    ball = dataclasses.replace(ball, inertia=solid_sphere(mass, radius),
                               velocity=(0.0, 0.0, -speed))
    plate = Body("plate", motion=Motion.FIXED, position=(0.0, 0.0, -plate_half_thickness),
                 shapes=(Box("plate", half_extents=(0.5, 0.5, plate_half_thickness)),))
    contact = ContactPair("ball_plate", body_a="plate", shape_a="plate", body_b="ball",
                          shape_b="sphere", friction=0.3)
    horizon = 0.2
    arrival = 0.05 / speed
    return Scene(
        description=f"A {2000 * radius:g} mm ball at {speed} m/s onto a "
        f"{2000 * plate_half_thickness:g} mm plate (e = 0): {1000 * speed * scene.time_step:g} "
        "mm per step at the "
        "comfortable step; it must rest on the plate, not pass through.",
        horizon=horizon,
        time_step=scene.time_step,
        bodies=(plate, ball),
        contacts=(contact,),
        outputs=(PointPosition("height", body="ball", component="z"),),
        expectations=(
            Expectation("rests_on_plate", kind="sticks", body="ball",
                        parameters={"start_time": max(10 * arrival, 0.02),
                                    "end_time": horizon}),
            Expectation("no_penetration", kind="no_penetration"),
            Expectation("energy", kind="energy_non_increasing"),
        ),
    )


@register("stiff-high-friction", tags=(STIFF, "friction"),
          summary="box on a 60 degree incline with mu = 2: must not move")
def high_friction(friction: float = 2.0, angle_degrees: float = 60.0) -> Scene:
    scene = incline_stick(angle_degrees=angle_degrees, friction=friction)
    return scene


@register("stiff-elastic", tags=(STIFF, "impact"),
          summary="ball bouncing with e = 1: energy must not grow, apex must not change")
def elastic(drop_height: float = 1.0) -> Scene:
    scene = bouncing_ball(restitution=0.9, drop_height=drop_height)
    contacts = tuple(dataclasses.replace(c, restitution=1.0) for c in scene.contacts)
    expectations = (
        Expectation("apex_heights", kind="bounce_apex", body="ball", parameters={
            "drop_height": drop_height, "restitution": 1.0, "gravity": GRAVITY}),
        Expectation("no_penetration", kind="no_penetration"),
        Expectation("energy", kind="energy_non_increasing"),
    )
    period = 2.0 * math.sqrt(2.0 * drop_height / GRAVITY)
    return _described(
        scene, f"Ball dropped from {drop_height} m with Newton restitution 1: every apex "
        "at the drop height, energy must not grow.", contacts=contacts,
        expectations=expectations, horizon=round(3.4 * period, 3))


@register("stiff-many-contacts", tags=(STIFF, "many_contacts"),
          summary="36 boxes on a plane: 144 simultaneous corner contacts")
def many_contacts(count: int = 36) -> Scene:
    scene = box_grid(count=count)
    return scene


@register("stiff-millimetre-parts", tags=(STIFF, "clearance"),
          summary="the clearance pendulum shrunk to a 1 cm, 1 g rod with micrometre clearances, "
          "in SI units")
def millimetre_parts() -> Scene:
    """The clearance pendulum with every length x 1e-2 and every mass x 1e-3 (a 1 cm rod of
    1 g, journal radius 0.1 mm, clearances 1 um), still in metres and kilograms, so that
    tolerances must be relative to work. Built by reading the SI scene's numbers as
    centimetres and grams (gravity set to 981 cm/s^2) and converting back to SI."""
    scene = clearance_pendulum()
    small = dataclasses.replace(scene, units=UnitSystem("cm", "g", "s"),
                                gravity=tuple(100.0 * g for g in scene.gravity))
    shrunk = small.rescaled(UnitSystem())
    return _described(
        shrunk, "The clearance pendulum shrunk to a 1 cm rod of 1 g, journal radius 0.1 mm "
        "and 1 um clearances, in SI units.", horizon=0.5, time_step=1e-4)
