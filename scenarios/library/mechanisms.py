"""Library mechanisms: pendulums (ideal and with clearance), a torque-free body, slider-cranks.

SI units (m, kg, s). Joints are declared in world coordinates at the initial configuration.
"""

from __future__ import annotations

import math

from clearbench.scenarios.bodies import Body, Motion
from clearbench.scenarios.contacts import ContactPair
from clearbench.scenarios.drivers import Driver
from clearbench.scenarios.expectations import Expectation
from clearbench.scenarios.inertia import diagonal
from clearbench.scenarios.joints import ClearanceRevoluteJoint, PrismaticJoint, RevoluteJoint
from clearbench.scenarios.outputs import BodyAngle, PointPosition
from clearbench.scenarios.registry import register
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.shapes import Box, Plane
from clearbench.scenarios.tags import ANALYTIC, SMOKE

GRAVITY = 9.81  # m/s^2
Y_AXIS = (0.0, 1.0, 0.0)
Z_AXIS = (0.0, 0.0, 1.0)


def _rotation_about_y(angle: float) -> tuple:
    return (math.cos(0.5 * angle), 0.0, math.sin(0.5 * angle), 0.0)


ROD_RADIUS_RATIO = 0.02  # radius of the pendulum rod per unit length (its small axial moment)


def pendulum_rod_inertia(mass: float, length: float) -> tuple:
    """Inertia about the centre of mass of a uniform rod of length 2 ``length`` hung from one
    end (centre of mass ``length`` below the pivot), axis along body z [kg m^2]."""
    transverse = mass * (2.0 * length) ** 2 / 12.0
    radius = ROD_RADIUS_RATIO * length
    return diagonal(transverse, transverse, 0.5 * mass * radius**2)


def _pendulum_bob(initial_angle: float, length: float, mass: float) -> Body:
    """A uniform rod whose frame origin is the pivot, centre of mass ``length`` below it at
    rest, tilted by ``initial_angle`` about world y.

    A rod rather than a point bob: a point bob has almost no inertia about its centre of mass,
    so in a clearance joint it could spin about its centre while the bore whirls round the
    journal; that mode is not what a pendulum test is about."""
    return Body("bob", mass=mass, inertia=pendulum_rod_inertia(mass, length),
                center_of_mass=(0.0, 0.0, -length), orientation=_rotation_about_y(initial_angle))


PENDULUM_OUTPUTS = (
    BodyAngle("angle", body="bob", axis=Y_AXIS),
    PointPosition("bob_x", body="bob", point=(0.0, 0.0, -1.0), component="x"),
)


@register("pendulum", tags=(SMOKE, ANALYTIC, "joints"),
          summary="pendulum on an ideal revolute joint: energy conserved, elliptic period")
def pendulum(initial_angle: float = 1.0, length: float = 1.0, mass: float = 1.0,
             ) -> Scene:
    bob = _pendulum_bob(initial_angle, length, mass)
    pivot_inertia = pendulum_rod_inertia(mass, length)[0][0] + mass * length**2
    return Scene(
        description=f"Rod pendulum ({mass} kg, centre of mass {length} m below the pivot) on an "
        "ideal revolute joint, "
        f"released from rest at {initial_angle} rad: energy conserved, period from the "
        "complete elliptic integral.",
        horizon=10.0,
        time_step=1e-3,
        bodies=(Body("ground", motion=Motion.FIXED), bob),
        joints=(RevoluteJoint("pivot", body_a="ground", body_b="bob", anchor=(0.0, 0.0, 0.0),
                              axis=Y_AXIS),),
        outputs=PENDULUM_OUTPUTS,
        expectations=(
            Expectation("period", kind="pendulum", body="bob", parameters={
                "mass": mass, "pivot_distance": length, "pivot_inertia": pivot_inertia,
                "gravity": GRAVITY, "initial_angle": initial_angle}),
            Expectation("energy", kind="energy_conserved"),
        ),
    )


@register("clearance-pendulum", tags=(SMOKE, "clearance", "friction"),
          summary="pendulum on a 3D revolute joint with radial and axial clearance")
def clearance_pendulum(radial_clearance: float = 1e-4, axial_clearance: float = 1e-4,
                       initial_angle: float = 1.0, length: float = 1.0, mass: float = 1.0,
                       journal_radius: float = 0.01,
                       bearing_length: float = 0.02, friction: float = 0.1,
                       restitution: float = 0.0) -> Scene:
    """The pendulum of ``pendulum`` hung on a clearance joint: a journal of radius
    ``journal_radius`` [m] fixed to the ground inside the bob's bore of radius
    journal_radius + radial_clearance, with flanges leaving ``axial_clearance`` of axial play.
    The bore starts concentric with the journal; as the clearance goes to zero the motion must
    approach the ideal pendulum."""
    bob = _pendulum_bob(initial_angle, length, mass)
    joint = ClearanceRevoluteJoint(
        "pivot", journal_body="ground", bearing_body="bob", anchor=(0.0, 0.0, 0.0), axis=Y_AXIS,
        journal_radius=journal_radius, radial_clearance=radial_clearance,
        bearing_length=bearing_length, axial_clearance=axial_clearance,
        thrust_radius=1.5 * (journal_radius + radial_clearance), friction=friction,
        restitution=restitution,
    )
    return Scene(
        description=f"The pendulum on a 3D revolute joint with radial clearance "
        f"{radial_clearance} m and axial clearance {axial_clearance} m (journal radius "
        f"{journal_radius} m, mu {friction}, e {restitution}).",
        horizon=3.0,
        time_step=1e-3,
        bodies=(Body("ground", motion=Motion.FIXED), bob),
        clearance_joints=(joint,),
        outputs=PENDULUM_OUTPUTS,
        expectations=(
            Expectation("ideal_limit", kind="approaches_ideal", body="bob",
                        parameters={"radial_clearance": radial_clearance}),
            Expectation("no_penetration", kind="no_penetration"),
            Expectation("energy", kind="energy_non_increasing"),
        ),
    )


@register("torque-free-flip", tags=(ANALYTIC, "gyroscopic"),
          summary="asymmetric body spun near its intermediate axis: flips, invariants conserved")
def torque_free_flip(moments: tuple = (1.0, 2.0, 2.5), spin: float = 3.0,
                     perturbation: float = 0.01) -> Scene:
    """Free body with principal moments I1 < I2 < I3 [kg m^2] spun at ``spin`` [rad/s] about
    its intermediate axis, perturbed by ``perturbation`` [rad/s] on the other two: the
    Dzhanibekov flip."""
    return Scene(
        description=f"Torque-free body, principal moments {tuple(moments)} kg m^2, spun at "
        f"{spin} rad/s about the intermediate axis: energy and angular momentum conserved, "
        "periodic flips.",
        gravity=(0.0, 0.0, 0.0),
        horizon=10.0,
        time_step=1e-3,
        bodies=(Body("body", mass=1.0, inertia=diagonal(*moments),
                     angular_velocity=(perturbation, spin, perturbation)),),
        expectations=(Expectation("invariants", kind="torque_free", body="body"),
                      Expectation("energy", kind="energy_conserved")),
    )


def _planar_link(name: str, mass: float, length: float, inertia_z: float, pivot: tuple,
                 angular_velocity: float, pivot_velocity: tuple, motion=Motion.FREE) -> Body:
    """A link along +x from ``pivot``, centre of mass at mid-length, rotating about z.

    Out-of-plane moments are chosen to respect the triangle inequality of a slender bar
    (I_xx small, I_yy = I_zz); they do not enter the planar motion.
    """
    velocity = (pivot_velocity[0], pivot_velocity[1] + angular_velocity * 0.5 * length, 0.0)
    return Body(name, mass=mass, inertia=diagonal(0.01 * inertia_z, inertia_z, inertia_z),
                center_of_mass=(0.5 * length, 0.0, 0.0), position=pivot, velocity=velocity,
                angular_velocity=(0.0, 0.0, angular_velocity), motion=motion)


@register("slider-crank", tags=(ANALYTIC, "joints", "closed_loop"),
          summary="slider-crank with ideal joints, crank driven at constant speed")
def slider_crank(crank_length: float = 0.1, rod_length: float = 0.3,
                 crank_speed: float = 10.0) -> Scene:
    """Crank driven at ``crank_speed`` [rad/s] about z from angle 0; the slider moves on the x
    axis through the crank pivot. Closed-form kinematics x = l1 cos(theta) + sqrt(l2^2 -
    l1^2 sin^2(theta))."""
    l1, l2, w = crank_length, rod_length, crank_speed
    rod_rate = -l1 * w / l2  # at theta = 0
    pin = (l1, 0.0, 0.0)
    pin_velocity = (0.0, l1 * w, 0.0)
    crank = Body("crank", mass=0.1, inertia=diagonal(1e-5, 1e-4, 1e-4),
                 angular_velocity=(0.0, 0.0, w), motion=Motion.DRIVEN)
    rod = _planar_link("rod", 0.2, l2, 0.2 * l2**2 / 12.0, pin, rod_rate, pin_velocity)
    slider = Body("slider", mass=0.3, inertia=diagonal(1e-4, 1e-4, 1e-4),
                  position=(l1 + l2, 0.0, 0.0))
    return Scene(
        description=f"Slider-crank (crank {l1} m, rod {l2} m) with ideal joints, crank driven "
        f"at {w} rad/s: closed-form slider kinematics.",
        gravity=(0.0, 0.0, -GRAVITY),
        horizon=1.0,
        time_step=1e-3,
        bodies=(Body("ground", motion=Motion.FIXED), crank, rod, slider),
        joints=(
            RevoluteJoint("crank_pivot", body_a="ground", body_b="crank", axis=Z_AXIS),
            RevoluteJoint("crank_pin", body_a="crank", body_b="rod", anchor=pin, axis=Z_AXIS),
            RevoluteJoint("wrist_pin", body_a="rod", body_b="slider", anchor=(l1 + l2, 0, 0),
                          axis=Z_AXIS),
            _prismatic_x("slide", "ground", "slider", (l1 + l2, 0.0, 0.0)),
        ),
        drivers=(Driver("crank_drive", body="crank", component="rz", quantity="velocity",
                        times=(0.0,), values=(w,)),),
        outputs=(PointPosition("slider_x", body="slider", component="x"),
                 BodyAngle("crank_angle", body="crank", axis=Z_AXIS)),
        expectations=(Expectation("kinematics", kind="slider_crank", body="slider", parameters={
            "crank_length": l1, "rod_length": l2, "crank_speed": w, "offset": 0.0}),),
    )


def _prismatic_x(name: str, body_a: str, body_b: str, anchor: tuple):
    return PrismaticJoint(name, body_a=body_a, body_b=body_b, anchor=anchor, axis=(1.0, 0, 0))


@register("flores-slider-crank", tags=("clearance", "impact", "friction"),
          summary="slider-crank with a translational clearance (Flores, Leine, Glocker 2010)")
def flores_slider_crank(clearance: float = 0.001, friction: float = 0.01,
                        restitution: float = 0.4) -> Scene:
    """The slider-crank of Flores, Leine and Glocker (Multibody System Dynamics 23, 2010) with
    a translational clearance joint: the slider (half-length 0.05 m, half-height 0.025 m) moves
    in a guide ``clearance`` [m] taller than itself; crank and rod on ideal revolute joints.

    Initial conditions as published: all angles 0, omega1 = 150 rad/s, omega2 = -75 rad/s
    (the slider at rest), gravity -9.81 m/s^2 along y; the crank is not driven. The slider is
    a box of depth 0.05 m in this 3D rebuild, so each 2D corner is two contact points.
    """
    l1, l2 = 0.153, 0.306
    w1, w2 = 150.0, -75.0
    half = (0.05, 0.025, 0.025)
    crank = _planar_link("crank", 0.038, l1, 7.4e-5, (0.0, 0.0, 0.0), w1, (0.0, 0.0, 0.0))
    pin = (l1, 0.0, 0.0)
    rod = _planar_link("rod", 0.038, l2, 5.9e-4, pin, w2, (0.0, l1 * w1, 0.0))
    wrist = (l1 + l2, 0.0, 0.0)
    slider = Body("slider", mass=0.076, inertia=diagonal(1.35e-6, 2.16e-6, 2.7e-6),
                  position=wrist, shapes=(Box("block", half_extents=half),))
    gap = half[1] + 0.5 * clearance
    s = math.sqrt(0.5)
    guide = Body("guide", motion=Motion.FIXED, shapes=(
        Plane("lower", position=(0.0, -gap, 0.0), orientation=(s, -s, 0.0, 0.0)),
        Plane("upper", position=(0.0, gap, 0.0), orientation=(s, s, 0.0, 0.0)),
    ))
    contact = dict(friction=friction, restitution=restitution)
    return Scene(
        description=f"Slider-crank with a translational clearance of {clearance} m (Flores, "
        f"Leine, Glocker 2010): e_N {restitution}, mu {friction}, omega1 = 150 rad/s.",
        gravity=(0.0, -GRAVITY, 0.0),
        horizon=0.2,
        time_step=1e-5,
        bodies=(guide, crank, rod, slider),
        joints=(
            RevoluteJoint("crank_pivot", body_a="guide", body_b="crank", axis=Z_AXIS),
            RevoluteJoint("crank_pin", body_a="crank", body_b="rod", anchor=pin, axis=Z_AXIS),
            RevoluteJoint("wrist_pin", body_a="rod", body_b="slider", anchor=wrist, axis=Z_AXIS),
        ),
        contacts=(
            ContactPair("guide_lower", body_a="guide", shape_a="lower", body_b="slider",
                        shape_b="block", **contact),
            ContactPair("guide_upper", body_a="guide", shape_a="upper", body_b="slider",
                        shape_b="block", **contact),
        ),
        outputs=(PointPosition("slider_x", body="slider", component="x"),
                 PointPosition("slider_y", body="slider", component="y"),
                 BodyAngle("slider_angle", body="slider", axis=Z_AXIS),
                 BodyAngle("crank_angle", body="crank", axis=Z_AXIS)),
        expectations=(Expectation("no_penetration", kind="no_penetration"),
                      Expectation("energy", kind="energy_non_increasing")),
    )
