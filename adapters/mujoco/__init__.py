"""The MuJoCo engine: a scene rebuilt in MuJoCo, stepped with guards, read out."""

from clearbench.adapters import installed_package, lazy_engine
from clearbench.adapters.harness_defaults import (
    C60_ON,
    C60_TRIP,
    QUICK_SCENES,
    HarnessDefaults,
    both_c60_scenes,
    short_c60,
)

__all__ = ["HARNESS_DEFAULTS", "MujocoEngine", "availability", "create"]

create, __getattr__ = lazy_engine(__name__, "MujocoEngine")


#: MuJoCo in the harness: checked in the tuned preset (the one the docs measure the C-60
#: with); its C-60 runs are chaotic (impacts amplify round-off into figures drawn from a
#: distribution), so their tolerances come from an ensemble of 8 round-off seeds.
HARNESS_DEFAULTS = HarnessDefaults(
    regress_preset="tuned",
    regress_runs=(*QUICK_SCENES, short_c60(ensemble=8)),
    c60_ladders={"demo": {C60_ON: {"default": (1e-3,), "tuned": (1e-3, 2e-3, 4e-3, 8e-3)},
                          C60_TRIP: {"tuned": (1e-3, 4e-3)}},
                 "full": both_c60_scenes({"default": (1e-3, 4e-3),
                                          "tuned": (1e-3, 2e-3, 4e-3, 8e-3)})},
    c60_step_cost=0.32,
    colour="#0072B2",
)


def availability() -> tuple[bool, str]:
    """(True, version) when the ``mujoco`` package is installed, else (False, why); never
    raises, imports nothing."""
    return installed_package("mujoco")
