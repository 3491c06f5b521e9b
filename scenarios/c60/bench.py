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

from clearbench.scenarios.bodies import Body, Motion
from clearbench.scenarios.c60 import model
from clearbench.scenarios.c60.variants import ModelParameters
from clearbench.scenarios.contacts import ContactPair
from clearbench.scenarios.drivers import Driver
from clearbench.scenarios.expectations import Expectation
from clearbench.scenarios.outputs import ContactForce, PointPosition
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.shapes import Cylinder, Sphere

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
    stroke: float = 2.2,
    retreat_speed: float = 0.5,
    hold: float = 2.0,
    time_step: float = 1e-3,
    parameters: ModelParameters | None = None,
) -> Scene:
    """Section 5.2: probe in place of the fixed contact, forward to the reference and back.

    The breaker is in its ON pose with the probe at the fixed contact's place (the reference):
    the mechanism settles latched as in ``c60-on``. The probe then retreats ``stroke`` at
    ``retreat_speed`` to the initial position (the set-up of the bench, not part of the curve),
    moves forward at ``probe_speed`` to the reference, holds ``hold`` and goes back to the
    initial position: the forward and backward strokes are the curve of Fig. 20.

    Why the probe starts at the reference. Once nothing loads the moving contact (it rests on
    its stop C6, on the plate, and the contact spring's load stays inside the plate), little
    holds the handle in its ON pose against its spring. An earlier revision started the probe
    2.8 mm back from an unsettled mechanism: the handle turned from -0.33 to +1.37 rad by
    9 ms and the latch let go before the probe arrived. Settled at the reference first, the
    moving contact follows the retreating probe for about 2.0 mm (the study's probe is loaded
    over 2.0 mm) and then rests on C6; ``stroke`` (2.2 mm) only just exceeds that, so that the
    curve reaches zero load while the unloaded time stays short (2.4 ms at the default speeds).

    The library scene ``c60-contact-force-test`` puts the handle spring at its design arm
    unless told otherwise (10 N mm about the handle's pivot
    instead of the source's 27, see :mod:`.model`). Measured with the reference engine
    over the first 10 ms (``clearbench c60 angles`` on the trajectory): with the
    source's arm the handle leaves its ON pose within 1 ms of the moving contact landing on
    C6 (-0.34 rad at 6 ms, +0.68 rad at 10 ms, stroke 2.2 mm) and the mechanism opens; with
    the design arm it stays at -0.343 rad through 4.8 ms unloaded (stroke 2.4 mm).

    Parameters
    ----------
    clearances : mapping, optional
        Joint radial clearances [mm] (default: the prototype's, Table 7).
    probe_speed : float
        Probe speed on the forward and backward strokes [mm/ms] (the study: 5e-4).
    stroke : float
        Distance from the reference to the initial position [mm].
    retreat_speed : float
        Probe speed of the set-up retreat [mm/ms].
    hold : float
        Time at the reference position [ms].
    parameters : ModelParameters, optional
        The model's documented alternatives (:mod:`.variants`); the source's by default.
    """
    clearances = model.prototype_clearances() if clearances is None else clearances
    frame_face = next(s for s in model.c60_scene().body(model.FRAME).shapes
                      if s.name == FIXED_CONTACT_FACE)
    retreat_end = SETTLE_TIME + stroke / retreat_speed
    travel = stroke / probe_speed
    times = (0.0, SETTLE_TIME, retreat_end, retreat_end + travel, retreat_end + travel + hold,
             retreat_end + 2.0 * travel + hold)
    values = (0.0, 0.0, -stroke, 0.0, 0.0, -stroke)
    probe = Body(PROBE, mass=1.0, position=(0.0, 0.0, 0.0), motion=Motion.DRIVEN,
                 shapes=(frame_face,))
    c7 = next(c for c in model.load_model()["contacts"] if c["name"] == model.C7)
    contact = ContactPair("Probe_C7", body_a="moving_contact",
                          shape_a="porte_contact_asm_contact_surface", body_b=PROBE,
                          shape_b=FIXED_CONTACT_FACE, friction=float(c7["friction"]),
                          offset=float(c7["offset"]))
    return model.c60_scene(
        name, clearances=clearances, horizon=times[-1] + 0.2, time_step=time_step,
        parameters=parameters,
        without_contacts=(model.C7,),
        extra_bodies=(probe,), extra_contacts=(contact,),
        extra_drivers=_probe_drivers("x", times, values, "position"),
        extra_outputs=(ContactForce("probe_force", contact="Probe_C7"),
                       PointPosition("probe_x", body=PROBE, component="x")),
        expectations=(Expectation("no_penetration", kind="no_penetration"),),
        description="C-60 contact-force bench test (Section 5.2): a probe in place of the "
        f"fixed contact, settled at the reference, back {stroke} mm, forward to the reference "
        f"at {probe_speed} mm/ms, held {hold} ms, and back.",
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
    stroke: float = 0.65,
    time_step: float = 1e-3,
    parameters: ModelParameters | None = None,
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
        Probe travel at ``probe_speed`` [mm]: beyond the release (measured 0.56 mm into the
        slow phase with the prototype's clearances: first contact 0.08 mm in, trip distance
        0.48 mm) by 0.09 mm, which the curve's release test needs (0.02 mm) with margin, and
        no further: the source has no OFF stop, and long after the release the free linkage
        turns into poses its contact set does not cover (measured with a 0.9 mm stroke at half
        the probe speed: projections failing from 11.6 ms after the release, a 0.8 mm
        penetration, the bodies tumbling).
    parameters : ModelParameters, optional
        The model's documented alternatives (:mod:`.variants`); the source's by default.
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
        parameters=parameters,
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
