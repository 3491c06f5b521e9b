"""Hypothesis strategies generating valid scenes (shared by the property tests)."""

from __future__ import annotations

import math

from hypothesis import strategies as st

from clearbench.scenarios.bodies import Body, Motion
from clearbench.scenarios.contacts import ContactPair
from clearbench.scenarios.drivers import Driver
from clearbench.scenarios.joints import ClearanceRevoluteJoint, RevoluteJoint, SphericalJoint
from clearbench.scenarios.loads import (
    AngleLawLoad,
    DistanceLawLoad,
    LinearSpringDamper,
    LoadApplication,
    Moment,
    PointForce,
)
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.shapes import (
    Arc,
    Bore,
    Box,
    Capsule,
    Circle,
    Cylinder,
    Disc,
    Plane,
    Rectangle,
    Sphere,
)
from clearbench.scenarios.units import UnitSystem

# Values below 1e-200 are excluded: rescaling to um-mg-us multiplies some by 1e-6, and values
# pushed into the subnormal range lose digits (no scene has such values).
finite = st.floats(min_value=-1e3, max_value=1e3, allow_nan=False, allow_infinity=False,
                   allow_subnormal=False).filter(lambda x: x == 0.0 or abs(x) > 1e-200)
positive = st.floats(min_value=1e-3, max_value=1e3, allow_nan=False, allow_infinity=False)
vector3 = st.tuples(finite, finite, finite)


@st.composite
def unit_quaternions(draw):
    """Random unit quaternion (w, x, y, z), normalised in float64."""
    components = draw(st.tuples(*[st.floats(-1.0, 1.0, allow_nan=False)] * 4))
    norm = math.sqrt(sum(c * c for c in components))
    if norm < 1e-3:
        return (1.0, 0.0, 0.0, 0.0)
    return tuple(c / norm for c in components)


@st.composite
def inertias(draw):
    """Diagonal principal moments satisfying the triangle inequality, rotated by a quaternion."""
    import numpy as np

    a = draw(positive)
    b = draw(st.floats(min_value=a, max_value=4 * a))
    c = draw(st.floats(min_value=b, max_value=a + b))
    q = np.array(draw(unit_quaternions()))
    w, x, y, z = q
    r = np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ])
    matrix = r @ np.diag([a, b, c]) @ r.T
    matrix = 0.5 * (matrix + matrix.T)
    return tuple(tuple(float(v) for v in row) for row in matrix)


def shapes(name: str):
    placement = dict(position=vector3, orientation=unit_quaternions())
    return st.one_of(
        st.builds(Sphere, name=st.just(name), radius=positive, **placement),
        st.builds(Box, name=st.just(name), half_extents=st.tuples(positive, positive, positive),
                  **placement),
        st.builds(Capsule, name=st.just(name), radius=positive, half_length=positive,
                  **placement),
        st.builds(Cylinder, name=st.just(name), radius=positive, half_length=positive,
                  **placement),
        st.builds(Plane, name=st.just(name), **placement),
        st.builds(Circle, name=st.just(name), radius=positive, **placement),
        st.builds(Arc, name=st.just(name), radius=positive, start_angle=st.just(0.25),
                  end_angle=st.floats(0.5, 6.0), **placement),
        st.builds(Rectangle, name=st.just(name), half_extents=st.tuples(positive, positive),
                  **placement),
        st.builds(Disc, name=st.just(name), radius=positive, **placement),
        st.builds(Bore, name=st.just(name), radius=positive, half_length=positive,
                  start_angle=st.just(-1.0), end_angle=st.floats(0.0, 5.0), **placement),
    )


@st.composite
def scenes(draw):
    """A valid scene with 2-4 bodies, contacts, joints, loads and possibly a driver."""
    count = draw(st.integers(2, 4))
    bodies = [Body("ground", motion=Motion.FIXED, shapes=(draw(shapes("s0")),))]
    for index in range(1, count):
        bodies.append(Body(
            f"body{index}", mass=draw(positive), inertia=draw(inertias()),
            center_of_mass=draw(vector3), position=draw(vector3),
            orientation=draw(unit_quaternions()), velocity=draw(vector3),
            angular_velocity=draw(vector3), shapes=(draw(shapes("s0")), draw(shapes("s1"))),
        ))
    contacts = [
        ContactPair(f"c{i}", body_a=bodies[0].name, shape_a="s0", body_b=bodies[i].name,
                    shape_b=draw(st.sampled_from(["s0", "s1"])),
                    friction=draw(st.floats(0.0, 2.0)), restitution=draw(st.floats(0.0, 1.0)),
                    offset=draw(st.floats(-1e-3, 1e-3)))
        for i in range(1, count)
    ]
    joints = []
    if count >= 3:
        kind = draw(st.sampled_from([RevoluteJoint, SphericalJoint]))
        extra = {"axis": (0.0, 0.0, 1.0)} if kind is RevoluteJoint else {}
        joints.append(kind("j", body_a="body1", body_b="body2", anchor=draw(vector3), **extra))
    clearance = []
    if draw(st.booleans()):
        radius = draw(positive)
        gap = draw(positive)
        clearance.append(ClearanceRevoluteJoint(
            "cj", journal_body="ground", bearing_body="body1", anchor=draw(vector3),
            axis=(0.0, 1.0, 0.0), journal_radius=radius, radial_clearance=gap,
            bearing_length=draw(positive), axial_clearance=draw(positive),
            thrust_radius=2.0 * (radius + gap), friction=draw(st.floats(0.0, 1.0)),
        ))
    loads = [
        LinearSpringDamper("spring", body_a="ground", body_b="body1", point_b=draw(vector3),
                           stiffness=draw(positive), damping=draw(positive),
                           rest_length=draw(positive), preload=draw(finite)),
        PointForce("push", body="body1", force=draw(vector3), frame="body", start_time=0.0,
                   end_time=draw(st.one_of(st.none(), positive))),
        Moment("twist", body="body1", moment=draw(vector3), start_time=draw(positive)),
        AngleLawLoad("angle_law", axis=(0.0, 0.0, 1.0), stiffness=draw(positive),
                     offset=draw(finite), angle_bodies=("body1",),
                     angle_coefficients=(draw(finite),),
                     applications=(
                         LoadApplication("body1", "force", (1.0, 2.0, 0.5), "body",
                                         draw(vector3), draw(finite), draw(positive)),
                         LoadApplication("ground", "moment", (0.0, 0.0, 1.0), "world",
                                         coefficient=draw(finite)))),
        DistanceLawLoad("distance_law", body_a="ground", point_a=draw(vector3), body_b="body1",
                        point_b=draw(vector3), stiffness=draw(positive),
                        rest_length=draw(positive),
                        applications=(LoadApplication("body1", "moment", (0.0, 1.0, 0.0),
                                                      "body", lever=draw(positive)),)),
    ]
    drivers = []
    if draw(st.booleans()):
        bodies[-1] = Body(bodies[-1].name, mass=1.0, motion=Motion.DRIVEN,
                          shapes=bodies[-1].shapes)
        drivers.append(Driver("drive", body=bodies[-1].name, component="x", quantity="velocity",
                              times=(0.0, 0.7, 0.7), values=(0.0, 0.0, draw(finite))))
    units = draw(st.sampled_from([UnitSystem(), UnitSystem("mm", "g", "ms")]))
    horizon = draw(positive)
    return Scene(
        name="generated", description="hypothesis scene", units=units, gravity=draw(vector3),
        horizon=horizon, time_step=horizon * draw(st.floats(1e-6, 1.0)), bodies=tuple(bodies),
        joints=tuple(joints), clearance_joints=tuple(clearance), contacts=tuple(contacts),
        loads=tuple(loads), drivers=tuple(drivers),
    )
