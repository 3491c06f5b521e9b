"""Library scenes of the Schneider Electric C-60 mechanism (tag ``c60``), mm-g-ms.

* ``c60-on``: the ON pose, no trip: the mechanism settles and stays latched; FC-1 (the C7
  contact force) and the measurement pairs (FC-2..FC-6) at equilibrium.
* ``c60-trip``: the source's magnetic trip: the plunger moves at 0.2 mm/ms from 0.7 ms, strikes
  the tripping bar, the latch releases and the contacts open (20 ms, as the source).
* ``c60-contact-force-test`` and ``c60-trip-force-test``: the bench experiments of Section 5
  with the prototype's clearances (Table 7), see :mod:`clearbench.scenarios.c60.bench`.

Every factory takes ``clearances`` (joint -> radial clearance [mm]), ``time_step`` and
``horizon`` [ms] where it applies, a named model ``variant`` (``source`` by default; the
source's documented alternatives, ``paper-table-4`` friction and combinations, see
:data:`clearbench.scenarios.c60.variants.VARIANTS`) and, as keyword overrides of the
variant, the fields of :class:`~clearbench.scenarios.c60.variants.ModelParameters`:
``contact_spring_preload`` [rad], ``contact_spring_angle_offset`` [deg],
``moving_contact_force_lever`` and ``plate_force_lever`` [mm], ``handle_spring_arm``
(``source``/``design``; the contact-force test takes ``design`` unless told, see
:mod:`clearbench.scenarios.c60.bench`), ``friction_set`` (``source``/``paper-table-4``) and
``friction`` (contact class -> coefficient, e.g. ``friction={"C4": 0.1}``). A bad value is
refused naming the field before the scene is built.
"""

from __future__ import annotations

from collections.abc import Mapping

from clearbench.scenarios.c60.bench import contact_force_test_scene, trip_force_test_scene
from clearbench.scenarios.c60.model import c60_scene
from clearbench.scenarios.c60.variants import model_parameters
from clearbench.scenarios.expectations import Expectation
from clearbench.scenarios.registry import register
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.tags import BENCH, C60

#: Time after which the ON mechanism is settled (the source's settling moment on the bar ends at
#: 1 ms; the joints have taken up their clearances by 2 ms) [ms].
SETTLED_AFTER = 3.0


@register("c60-on", tags=(C60,),
          summary="C-60 breaker in its ON pose: settles, stays latched; FC-1..FC-6")
def c60_on(clearances: Mapping[str, float] | None = None, horizon: float = 7.0,
           time_step: float = 1e-3, variant: str = "source", **model) -> Scene:
    return c60_scene(
        clearances=clearances, horizon=horizon, time_step=time_step,
        parameters=model_parameters(variant, **model), plunger_speed=0.0,
        expectations=(Expectation("no_penetration", kind="no_penetration"),) + ((
            Expectation("stays_latched", kind="sticks", body="hook",
                        parameters={"start_time": SETTLED_AFTER, "end_time": horizon}),)
            # A run that ends before the mechanism settles cannot judge the latch.
            if horizon > SETTLED_AFTER else ()),
        description="Schneider Electric C-60 mechanism in its ON pose (mm, g, ms): the joints "
        "take up their clearances, the hook stays latched on the tripping bar and the moving "
        "contact rests on the fixed contact (FC-1).",
    )


@register("c60-trip", tags=(C60,),
          summary="C-60 magnetic trip: the plunger strikes the bar, the latch releases, C7 opens")
def c60_trip(clearances: Mapping[str, float] | None = None, horizon: float = 20.0,
             time_step: float = 1e-3, plunger_speed: float = 0.2, plunger_start: float = 0.7,
             variant: str = "source", **model) -> Scene:
    return c60_scene(
        clearances=clearances, horizon=horizon, time_step=time_step,
        parameters=model_parameters(variant, **model), plunger_speed=plunger_speed,
        plunger_start=plunger_start,
        description="Schneider Electric C-60 magnetic trip (the source's 20 ms run): the "
        f"plunger moves at {plunger_speed} mm/ms from {plunger_start} ms, pushes the tripping "
        "bar, the hook releases and the springs open the moving contact.",
    )


@register("c60-contact-force-test", tags=(C60, BENCH),
          summary="C-60 bench test: probe in place of the fixed contact, force vs displacement")
def c60_contact_force_test(clearances: Mapping[str, float] | None = None,
                           probe_speed: float = 0.1, time_step: float = 1e-3,
                           variant: str = "source", **model) -> Scene:
    model.setdefault("handle_spring_arm", "design")
    return contact_force_test_scene(
        clearances=clearances, probe_speed=probe_speed, time_step=time_step,
        parameters=model_parameters(variant, **model))


@register("c60-trip-force-test", tags=(C60, BENCH),
          summary="C-60 bench test: probe pushes the tripping-bar pin until the latch releases")
def c60_trip_force_test(clearances: Mapping[str, float] | None = None,
                        probe_speed: float = 0.02, time_step: float = 1e-3,
                        variant: str = "source", **model) -> Scene:
    return trip_force_test_scene(
        clearances=clearances, probe_speed=probe_speed, time_step=time_step,
        parameters=model_parameters(variant, **model))
