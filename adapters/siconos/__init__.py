"""The Siconos engine: Debian's python3-siconos, run as a worker process fed with JSON."""

from clearbench.adapters import lazy_engine
from clearbench.adapters.harness_defaults import (
    C60_ON,
    QUICK_SCENES,
    HarnessDefaults,
    both_c60_scenes,
    short_c60,
)

__all__ = ["HARNESS_DEFAULTS", "SiconosEngine", "availability", "create"]

create, __getattr__ = lazy_engine(__name__, "SiconosEngine")


#: Siconos in the harness: rigid contacts; its C-60 steps 10 us in the quick suite and the
#: demo (36 ms of wall time per step).
HARNESS_DEFAULTS = HarnessDefaults(
    regress_runs=(*QUICK_SCENES, short_c60(time_step=1e-2)),
    rigid_contacts=True,
    c60_ladders={"demo": {C60_ON: {"default": (1e-2,), "projection": (1e-2,)}},
                 "full": both_c60_scenes({"default": (1e-3, 2e-3, 1e-2), "nsn-ac": (1e-3,),
                                          "projection": (1e-3,)})},
    c60_step_cost=53.0,
    colour="#CC79A7",
)


def availability() -> tuple[bool, str]:
    """Whether Debian's interpreter imports Siconos (:func:`.run.siconos_availability`:
    a probe in that interpreter, its answer cached); never raises."""
    from clearbench.adapters.siconos.run import siconos_availability

    return siconos_availability()
