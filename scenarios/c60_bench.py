"""The bench experiments of the C-60 study (Section 5) as scenes: a probe moved at constant speed.

* :func:`contact_force_test_scene` (Section 5.2, Fig. 20): the fixed contact C7 is replaced by a
  probe carrying the same plane face, moved along its normal (world x). The probe starts
  ``stroke`` behind the fixed contact's place, the moving contact rests on its stop (C6, on the
  plate) after the mechanism settles; the probe then pushes it forward to the fixed contact's
  place (the reference position), holds while the mechanism reaches equilibrium, and goes back
  to its start. The force on the probe against its displacement is the curve of Fig. 20.
* :func:`trip_force_test_scene` (Section 5.3, Fig. 21, pin side): a spherical probe tip pushes
  the tripping bar's pin in world +y at constant speed until the latch releases; the curve is
  the probe force against its displacement since first contact.

The study's probes move at 0.5 mm/s = 5e-4 mm/ms; the default speeds here are higher (see
``probe_speed``): the validation command reruns at half the speed and reports the difference.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from . import c60_model as model
from .bodies import Body, Motion
from .contacts import ContactPair
from .drivers import Driver
from .expectations import Expectation
from .outputs import ContactForce, PointPosition
from .scene import Scene
from .shapes import Cylinder, Sphere

PROBE = "probe"
#: The fixed-contact face of the frame (C7), reused on the probe.
FIXED_CONTACT_FACE = "Case_as_fixedcontact_movingcontact_stopper_C7"
#: The CAD's stand-in for the tripping-bar pin axis (a rod of radius 0.005 mm).
PIN_FILE = "C60/FC/Tbar_FC_measurement.stp"
PIN_SHAPE = "Tbar_pin"
#: Probe tip radius of the trip test [mm] (the study does not give it; the curve is taken from
#: the first contact, so it only sets the start position).
PROBE_TIP_RADIUS = 0.5
#: Friction of the probes (metal on plastic, as the sheet's metal/plastic pairs).
PROBE_FRICTION = 0.1
#: Time the mechanism is left to settle before a probe moves [ms].
SETTLE_TIME = 2.0
COMPONENTS = ("x", "y", "z", "rx", "ry", "rz")


def _probe_drivers(moving: str, times, values, quantity: str) -> tuple[Driver, ...]:
    """Drivers of a fully prescribed probe: ``moving`` follows the profile, the rest stays."""
    drivers = []
    for component in COMPONENTS:
        if component == moving:
            drivers.append(Driver(f"probe_{component}", body=PROBE, component=component,
                                  quantity=quantity, times=tuple(times), values=tuple(values)))
        else:
            drivers.append(Driver(f"probe_{component}", body=PROBE, component=component,
                                  quantity="velocity", times=(0.0,), values=(0.0,)))
    return tuple(drivers)


def contact_force_test_scene(
    name: str = "c60-contact-force-test",
    *,
    clearances: Mapping[str, float] | None = None,
    probe_speed: float = 0.1,
    stroke: float = 2.8,
    hold: float = 2.0,
    time_step: float = 1e-3,
    handle_spring_arm: str = "design",
    contact_spring_preload: float = model.CONTACT_SPRING_PRELOAD,
) -> Scene:
    """Section 5.2: probe in place of the fixed contact, forward to the reference and back.

    The handle spring acts at its design arm by default here: with the source's arm (27 N mm
    about the handle's pivot instead of 10, see :mod:`.c60_model`) the handle leaves its ON
    stop once the fixed contact no longer loads the moving contact, and the mechanism opens
    before the probe arrives (measured: the handle turns 1.7 rad and the latch lets go at
    3.5 ms), whereas the study's mechanism stays latched for this test.

    Parameters
    ----------
    clearances : mapping, optional
        Joint radial clearances [mm] (default: the prototype's, Table 7).
    probe_speed : float
        Probe speed [mm/ms] (the study: 5e-4).
    stroke : float
        Distance from the probe's start to the reference position [mm]: beyond the moving
        contact's free travel to its stop on the plate (C6), about 2.35 mm at the contact, so
        that the forward stroke starts unloaded (the study's probe is loaded over 2.0 mm).
    hold : float
        Time at the reference position [ms].
    """
    clearances = model.prototype_clearances() if clearances is None else clearances
    frame_face = next(s for s in model.c60_scene().body(model.FRAME).shapes
                      if s.name == FIXED_CONTACT_FACE)
    travel = stroke / probe_speed
    times = (0.0, SETTLE_TIME, SETTLE_TIME + travel, SETTLE_TIME + travel + hold,
             SETTLE_TIME + 2.0 * travel + hold)
    values = (0.0, 0.0, stroke, stroke, 0.0)
    probe = Body(PROBE, mass=1.0, position=(-stroke, 0.0, 0.0), motion=Motion.DRIVEN,
                 shapes=(frame_face,))
    c7 = next(c for c in model.load_model()["contacts"] if c["name"] == model.C7)
    contact = ContactPair("Probe_C7", body_a="moving_contact",
                          shape_a="porte_contact_asm_contact_surface", body_b=PROBE,
                          shape_b=FIXED_CONTACT_FACE, friction=float(c7["friction"]),
                          offset=float(c7["offset"]))
    return model.c60_scene(
        name, clearances=clearances, horizon=times[-1] + 0.2, time_step=time_step,
        handle_spring_arm=handle_spring_arm, contact_spring_preload=contact_spring_preload,
        without_contacts=(model.C7,),
        extra_bodies=(probe,), extra_contacts=(contact,),
        extra_drivers=_probe_drivers("x", times, values, "position"),
        extra_outputs=(ContactForce("probe_force", contact="Probe_C7"),
                       PointPosition("probe_x", body=PROBE, component="x")),
        expectations=(Expectation("no_penetration", kind="no_penetration"),),
        description="C-60 contact-force bench test (Section 5.2): a probe in place of the "
        f"fixed contact, {stroke} mm forward to the reference at {probe_speed} mm/ms, held "
        f"{hold} ms, and back.",
        tags=("c60", "bench"),
    )


def pin_shape() -> Cylinder:
    """The tripping-bar pin (the CAD's rod standing for its axis) as a contact shape."""
    rod = model.primitives()[PIN_FILE].primitives[0]
    axis = np.asarray(rod.axis, dtype=float)
    centre = np.asarray(rod.axis_point) + 0.5 * rod.length * axis
    return Cylinder(PIN_SHAPE, position=tuple(float(c) for c in centre),
                    orientation=model._frame_quaternion(rod.x_axis, axis), radius=rod.radius,
                    half_length=0.5 * rod.length)


def trip_force_test_scene(
    name: str = "c60-trip-force-test",
    *,
    clearances: Mapping[str, float] | None = None,
    probe_speed: float = 0.02,
    start_gap: float = 0.02,
    approach: float = 0.3,
    approach_speed: float = 0.1,
    stroke: float = 0.9,
    time_step: float = 1e-3,
    handle_spring_arm: str = "source",
    contact_spring_preload: float = model.CONTACT_SPRING_PRELOAD,
) -> Scene:
    """Section 5.3, pin side: a spherical probe pushes the tripping bar's pin along world +y.

    The probe starts ``start_gap`` from the pin of the ON pose; while the mechanism settles
    (the joints take up their clearances) the pin moves away from it (0.36 mm with the
    prototype's clearances, 0.14 mm with the sheet's). After ``SETTLE_TIME`` the probe covers
    ``approach`` at ``approach_speed``, then moves at ``probe_speed`` for ``stroke``: the first
    contact must fall in that slow phase (the analysis reports where it fell).

    Parameters
    ----------
    clearances : mapping, optional
        Joint radial clearances [mm] (default: the prototype's, Table 7).
    probe_speed : float
        Probe speed while it pushes [mm/ms] (the study: 5e-4).
    start_gap : float
        Gap between the probe tip and the pin in the ON pose [mm].
    approach, approach_speed : float
        Distance [mm] covered first at ``approach_speed`` [mm/ms].
    stroke : float
        Probe travel at ``probe_speed`` [mm] (beyond the study's 0.44 mm trip distance).
    """
    clearances = model.prototype_clearances() if clearances is None else clearances
    pin = pin_shape()
    bar = model.on_poses()["tripping_bar"]
    pin_world = bar.point(pin.position)
    start = pin_world - np.array([0.0, PROBE_TIP_RADIUS + pin.radius + start_gap, 0.0])
    probe = Body(PROBE, mass=1.0, position=tuple(float(c) for c in start), motion=Motion.DRIVEN,
                 shapes=(Sphere("tip", radius=PROBE_TIP_RADIUS),))
    contact = ContactPair("Probe_pin", body_a="tripping_bar", shape_a=PIN_SHAPE, body_b=PROBE,
                          shape_b="tip", friction=PROBE_FRICTION)
    slow_from = SETTLE_TIME + approach / approach_speed
    horizon = slow_from + stroke / probe_speed
    return model.c60_scene(
        name, clearances=clearances, horizon=horizon, time_step=time_step,
        handle_spring_arm=handle_spring_arm, contact_spring_preload=contact_spring_preload,
        extra_shapes={"tripping_bar": (pin,)},
        extra_bodies=(probe,), extra_contacts=(contact,),
        extra_drivers=_probe_drivers(
            "y", (0.0, SETTLE_TIME, SETTLE_TIME, slow_from, slow_from),
            (0.0, 0.0, approach_speed, approach_speed, probe_speed), "velocity"),
        extra_outputs=(ContactForce("probe_force", contact="Probe_pin"),
                       PointPosition("probe_y", body=PROBE, component="y")),
        expectations=(Expectation("no_penetration", kind="no_penetration"),),
        description="C-60 trip-force bench test (Section 5.3, pin side): a probe pushes the "
        f"tripping-bar pin along +y at {probe_speed} mm/ms until the latch releases.",
        tags=("c60", "bench"),
    )
