"""The reference engine: our nonsmooth Moreau--Jean solver behind the Engine contract."""

import clearbench
from clearbench.adapters import lazy_engine
from clearbench.adapters.harness_defaults import (
    C60_ON,
    C60_TRIP,
    HarnessDefaults,
    QuickRun,
    both_c60_scenes,
    short_c60,
)

__all__ = ["HARNESS_DEFAULTS", "ReferenceEngine", "availability", "create"]

create, __getattr__ = lazy_engine(__name__, "ReferenceEngine")


#: The reference in the harness: the smoke scenes of the quick suite, each carrying the
#: deliberate physics changes it must catch (tests/test_regress_catches.py: the bounce apexes
#: and rest time move with the restitution, the sliding box's stop with the friction, 0.8 s
#: covering its stop at v0 / (mu g) = 0.68 s, the clearance pendulum's eccentricity with the
#: clearance); rigid contacts; numba kernels; the fine runs of the C-60 plans (1 us in the
#: demo, 0.5 us in the full plan, against which every error is measured); black.
HARNESS_DEFAULTS = HarnessDefaults(
    regress_runs=(
        QuickRun("bouncing-ball-e0.5", 1.0, ident="bouncing-ball-e0.5"),
        QuickRun("incline-stick", 0.3, ident="incline-stick"),
        QuickRun("sliding-box", 0.8, ident="sliding-box"),
        QuickRun("pendulum", 1.0, ident="pendulum"),
        # 0.1 s: the first impacts in the clearance, before the rattling motion amplifies
        # round-off into a spread of a whole clearance (1e-4 m on long runs).
        QuickRun("clearance-pendulum", 0.1, ident="clearance-pendulum"),
        short_c60(),
    ),
    rigid_contacts=True,
    numba=True,
    c60_ladders={"demo": {C60_ON: {"default": (1e-3, 4e-3, 8e-3, 16e-3)},
                          C60_TRIP: {"default": (1e-3,)}},
                 "full": both_c60_scenes({"default": (5e-4, 1e-3, 2e-3, 4e-3, 8e-3, 16e-3)})},
    colour="#000000",
)


def availability() -> tuple[bool, str]:
    """Always available: the solver is part of clearbench."""
    return True, f"built in (clearbench {clearbench.__version__})"
