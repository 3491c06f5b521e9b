"""The PyBullet engine: a scene rebuilt in PyBullet (rigid bodies and Featherstone trees),
stepped with guards, read out."""

from clearbench.adapters import installed_package, lazy_engine
from clearbench.adapters.harness_defaults import (
    C60_ON,
    QUICK_SCENES,
    HarnessDefaults,
    both_c60_scenes,
    short_c60,
)

__all__ = ["HARNESS_DEFAULTS", "PybulletEngine", "PRESETS", "availability", "create"]

create, __getattr__ = lazy_engine(__name__, "PybulletEngine", "PRESETS")


#: PyBullet in the harness: checked in the tuned preset; its C-60 runs are chaotic (an
#: ensemble of 8 round-off seeds for their tolerances).
HARNESS_DEFAULTS = HarnessDefaults(
    regress_preset="tuned",
    regress_runs=(*QUICK_SCENES, short_c60(ensemble=8)),
    c60_ladders={"demo": {C60_ON: {"tuned": (2e-3, 4e-3)}},
                 "full": both_c60_scenes({"default": (1e-3,), "tuned": (1e-3, 2e-3, 4e-3)})},
    c60_step_cost=4.3,
    colour="#E69F00",
)


def availability() -> tuple[bool, str]:
    """(True, version) when the ``pybullet`` package is installed, else (False, why); never
    raises, imports nothing."""
    return installed_package("pybullet")
