"""Scenes written for the verdict tests (not in the library): a row of three balls with
elastic impacts (on a floor, and in space), a planar linkage whose driven ends pull a joint
apart, a branched pendulum tree, and a four-bar linkage with a clearance joint.

SI units (m, kg, s).
"""

from __future__ import annotations

import math

from clearbench.scenarios.bodies import Body, Motion
from clearbench.scenarios.contacts import ContactPair
from clearbench.scenarios.drivers import Driver
from clearbench.scenarios.expectations import Expectation
from clearbench.scenarios.inertia import diagonal, solid_box, solid_sphere
from clearbench.scenarios.joints import ClearanceRevoluteJoint, PrismaticJoint, RevoluteJoint
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.shapes import Plane, Sphere

GRAVITY = 9.81  # m/s^2
Z_AXIS = (0.0, 0.0, 1.0)


def elastic_row(speed: float = 1.0, radius: float = 0.05, mass: float = 0.2) -> Scene:
    """Three equal balls resting on a frictionless floor in a row along x; the first, ``2
    radius`` away from the two touching others, moves at ``speed`` [m/s] toward them. The
    ball-ball impacts are elastic (e = 1), the floor holds them (e = 0): the energy is
    conserved, and in the end the first two balls are at rest and the third moves at
    ``speed``. At least one contact (the floor) is closed on every sample."""
    balls = []
    for index, x in enumerate((-4.0 * radius, 0.0, 2.0 * radius)):
        balls.append(Body(f"ball{index}", mass=mass, inertia=solid_sphere(mass, radius),
                          position=(x, 0.0, radius),
                          velocity=(speed if index == 0 else 0.0, 0.0, 0.0),
                          shapes=(Sphere("sphere", radius=radius),)))
    floor = Body("ground", motion=Motion.FIXED, shapes=(Plane("floor"),))
    contacts = [ContactPair(f"floor_{b.name}", body_a="ground", shape_a="floor",
                            body_b=b.name, shape_b="sphere") for b in balls]
    contacts += [ContactPair(f"{a.name}_{b.name}", body_a=a.name, shape_a="sphere",
                             body_b=b.name, shape_b="sphere", restitution=1.0)
                 for a, b in zip(balls, balls[1:], strict=False)]
    return Scene(
        name="elastic-row",
        description="Three balls in a row on a frictionless floor, elastic impacts between "
        "them: the first one's momentum passes to the third.",
        horizon=0.3, time_step=1e-3, bodies=(floor, *balls), contacts=tuple(contacts),
        expectations=(Expectation("energy", kind="energy_non_increasing"),),
    )


def pulled_apart_linkage(pull_speed: float = 0.5, crank_length: float = 0.1,
                         rod_length: float = 0.3) -> Scene:
    """The library's slider-crank at full extension (crank angle 0, slider at crank + rod from
    the pivot), with the slider driven further out along x at ``pull_speed`` [m/s] while the
    crank turns at 10 rad/s: no motion of the rod keeps both its pins, so an ideal joint must
    come apart (0.1 m, a quarter of the linkage, in the 0.2 s horizon)."""
    l1, l2 = crank_length, rod_length
    crank = Body("crank", mass=0.1, inertia=diagonal(1e-5, 1e-4, 1e-4),
                 angular_velocity=(0.0, 0.0, 10.0), motion=Motion.DRIVEN)
    rod = Body("rod", mass=0.2, inertia=diagonal(0.2 * l2**2 / 1200, 0.2 * l2**2 / 12,
                                                 0.2 * l2**2 / 12),
               center_of_mass=(0.5 * l2, 0.0, 0.0), position=(l1, 0.0, 0.0),
               velocity=(0.0, 0.5 * l1 * 10.0, 0.0))
    slider = Body("slider", mass=0.3, inertia=diagonal(1e-4, 1e-4, 1e-4),
                  position=(l1 + l2, 0.0, 0.0), velocity=(pull_speed, 0.0, 0.0),
                  motion=Motion.DRIVEN)
    return Scene(
        name="pulled-apart-linkage",
        description="A slider-crank at full extension whose slider is driven outward: a pin "
        "must come apart.",
        gravity=(0.0, 0.0, -GRAVITY), horizon=0.2, time_step=1e-3,
        bodies=(Body("ground", motion=Motion.FIXED), crank, rod, slider),
        joints=(
            RevoluteJoint("crank_pivot", body_a="ground", body_b="crank", axis=Z_AXIS),
            RevoluteJoint("crank_pin", body_a="crank", body_b="rod", anchor=(l1, 0.0, 0.0),
                          axis=Z_AXIS),
            RevoluteJoint("wrist_pin", body_a="rod", body_b="slider",
                          anchor=(l1 + l2, 0.0, 0.0), axis=Z_AXIS),
            PrismaticJoint("slide", body_a="ground", body_b="slider",
                           anchor=(l1 + l2, 0.0, 0.0), axis=(1.0, 0.0, 0.0)),
        ),
        drivers=(Driver("crank_drive", body="crank", component="rz", times=(0.0,),
                        values=(10.0,)),
                 Driver("pull", body="slider", component="x", times=(0.0,),
                        values=(pull_speed,))),
    )


def branched_tree(arm: float = 0.2) -> Scene:
    """A branched pendulum tree hung from the ground, its bodies listed so that the tree is
    not depth-first: ``hub`` (revolute to the ground about y), ``left`` and ``right`` (each
    revolute to the hub), and ``tip`` (revolute to ``left``), listed hub, left, right, tip. A
    breadth-first plan makes links hub, left, right, tip; a depth-first numbering hub, left,
    tip, right. Every body has its own mass (0.1 to 0.4 kg), so bodies in the wrong rows show
    in every figure. Starts at rest, tilted by the arms' layout, swings in gravity (no contact).
    Lengths in m."""
    def rod(name: str, mass: float, position: tuple) -> Body:
        # A slender rod along x of length ``arm``, its frame at its centre of mass.
        return Body(name, mass=mass, inertia=diagonal(1e-6, mass * arm**2 / 12,
                                                      mass * arm**2 / 12),
                    position=position)

    y_axis = (0.0, 1.0, 0.0)
    hub = rod("hub", 0.4, (0.5 * arm, 0.0, 0.0))
    left = rod("left", 0.1, (1.5 * arm, 0.0, 0.0))
    right = rod("right", 0.3, (arm, 0.0, -0.5 * arm))
    tip = rod("tip", 0.2, (2.5 * arm, 0.0, 0.0))
    return Scene(
        name="branched-tree",
        description="A branched pendulum tree listed breadth-first (hub, left, right, tip).",
        gravity=(0.0, 0.0, -GRAVITY), horizon=0.2, time_step=1e-3,
        bodies=(Body("ground", motion=Motion.FIXED), hub, left, right, tip),
        joints=(
            RevoluteJoint("pivot", body_a="ground", body_b="hub", axis=y_axis),
            RevoluteJoint("hub_left", body_a="hub", body_b="left", anchor=(arm, 0.0, 0.0),
                          axis=y_axis),
            RevoluteJoint("hub_right", body_a="hub", body_b="right", anchor=(arm, 0.0, 0.0),
                          axis=y_axis),
            RevoluteJoint("left_tip", body_a="left", body_b="tip",
                          anchor=(2.0 * arm, 0.0, 0.0), axis=y_axis),
        ),
    )


def elastic_row_in_space(speed: float = 1.0, radius: float = 0.05, mass: float = 0.2) -> Scene:
    """The three-ball row without floor or gravity: every contact elastic (e = 1) and
    frictionless, nothing else acting, so the scene conserves energy by its content alone.
    Rigid impacts hand the first ball's momentum to the third (0, 0, ``speed``); a scheme
    that ends the impacts plastic leaves the three together at ``speed`` / 3, a third of the
    kinetic energy."""
    balls = tuple(Body(f"ball{index}", mass=mass, inertia=solid_sphere(mass, radius),
                       position=(x, 0.0, 0.0),
                       velocity=(speed if index == 0 else 0.0, 0.0, 0.0),
                       shapes=(Sphere("sphere", radius=radius),))
                  for index, x in enumerate((-4.0 * radius, 0.0, 2.0 * radius)))
    contacts = tuple(ContactPair(f"{a.name}_{b.name}", body_a=a.name, shape_a="sphere",
                                 body_b=b.name, shape_b="sphere", restitution=1.0)
                     for a, b in zip(balls, balls[1:], strict=False))
    return Scene(
        name="elastic-row-in-space",
        description="Three balls in a row without gravity, elastic frictionless impacts: the "
        "first one's momentum passes to the third, the energy is conserved.",
        gravity=(0.0, 0.0, 0.0), horizon=0.3, time_step=1e-3, bodies=balls,
        contacts=contacts,
        expectations=(Expectation("no_penetration", kind="no_penetration"),),
    )


def clearance_four_bar(radial_clearance: float = 1e-4) -> Scene:
    """A four-bar linkage in the xz-plane released at rest under gravity: ground pivots A
    (0, 0, 0) and D (0.4, 0, 0) m, crank A-B (0.2 m at 60 degrees), coupler B-C, rocker D-C,
    revolute axes along y. A, B and D are ideal joints; C (coupler to rocker) is a clearance
    joint (journal radius 10 mm, ``radial_clearance`` [m]): its journal and bearing are on two
    moving bodies of one kinematic tree."""
    a, b, c, d = (0.0, 0.0, 0.0), (0.1, 0.0, 0.1732), (0.45, 0.0, 0.28), (0.4, 0.0, 0.0)
    y_axis = (0.0, 1.0, 0.0)

    def link(name: str, start: tuple, end: tuple, mass: float = 1.0) -> Body:
        # A bar of square section 40 mm from start to end, its frame at its middle, x along it.
        dx, dz = end[0] - start[0], end[2] - start[2]
        length, angle = (dx * dx + dz * dz) ** 0.5, -math.atan2(dz, dx)
        return Body(name, mass=mass, inertia=solid_box(mass, (0.5 * length, 0.02, 0.02)),
                    position=tuple(0.5 * (p + q) for p, q in zip(start, end, strict=True)),
                    orientation=(math.cos(0.5 * angle), 0.0, math.sin(0.5 * angle), 0.0))

    return Scene(
        name="clearance-four-bar",
        description="A four-bar linkage falling under gravity from rest, its coupler-rocker "
        "pin a clearance joint.",
        horizon=0.5, time_step=1e-3,
        bodies=(Body("ground", motion=Motion.FIXED), link("crank", a, b),
                link("coupler", b, c), link("rocker", d, c)),
        joints=(RevoluteJoint("A", body_a="ground", body_b="crank", anchor=a, axis=y_axis),
                RevoluteJoint("B", body_a="crank", body_b="coupler", anchor=b, axis=y_axis),
                RevoluteJoint("D", body_a="ground", body_b="rocker", anchor=d, axis=y_axis)),
        clearance_joints=(ClearanceRevoluteJoint(
            "C", journal_body="coupler", bearing_body="rocker", anchor=c, axis=y_axis,
            journal_radius=0.01, radial_clearance=radial_clearance, bearing_length=0.02,
            axial_clearance=1e-4, thrust_radius=0.015, friction=0.1, restitution=0.0),),
        expectations=(Expectation("no_penetration", kind="no_penetration"),),
    )
