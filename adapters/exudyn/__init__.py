"""The Exudyn engine: a scene rebuilt in Exudyn's multibody code (index-3 joints, penalty
contact connectors), stepped with guards, read out."""

from clearbench.adapters import installed_package, lazy_engine
from clearbench.adapters.harness_defaults import (
    C60_ON,
    QUICK_SCENES,
    HarnessDefaults,
    OptionPerturbation,
    both_c60_scenes,
    short_c60,
)

__all__ = ["HARNESS_DEFAULTS", "ExudynEngine", "availability", "create"]

create, __getattr__ = lazy_engine(__name__, "ExudynEngine")


#: Exudyn in the harness: checked in the tuned preset, the C-60 in 'mechanism' (the preset the
#: C-60 plans use, docs/engines/exudyn.md) and only to 0.03 ms (before the first clearance
#: closes), its chaotic C-60 run from an ensemble of 8 round-off seeds; its sparse LU as a
#: perturbation of its arithmetic.
HARNESS_DEFAULTS = HarnessDefaults(
    regress_preset="tuned",
    regress_runs=(*QUICK_SCENES, short_c60(0.03, preset="mechanism", ensemble=8)),
    perturbations=(OptionPerturbation(
        "exudyn-sparse", {"linear_solver": "EigenSparse"},
        "Exudyn's sparse LU instead of its dense one: another factorisation order"),),
    c60_ladders={"demo": {C60_ON: {"mechanism": (1e-3,)}},
                 "full": both_c60_scenes({"default": (1e-3,), "tuned": (1e-3,),
                                          "mechanism": (1e-3,)})},
    c60_step_cost=5.8,
    colour="#009E73",
)


def availability() -> tuple[bool, str]:
    """(True, version) when the ``exudyn`` package is installed, else (False, why); never
    raises, imports nothing."""
    return installed_package("exudyn")
