"""A toy engine kept outside the package, plugged in with ``--engine-module toy=tests.toy_engine``
(tests/test_toy_engine.py): free rigid bodies in gravity and sphere-plane contacts with a
penalty spring-damper and regularised friction, stepped by semi-implicit Euler. It is the
template of a new engine (docs/engines/adding.md), file for file: ``settings.py`` (presets,
options, the settings object), ``capabilities.py`` (each scene feature: native, approximated
or unsupported), ``build.py`` (the scene as the engine's model), ``run.py`` (its runner: one
step, a state and a contact read-out; the shared loop does the rest) and ``engine.py`` (the
:class:`~clearbench.adapters.base.SteppingEngine` tying them together). It follows the adapter
contract (``availability``, ``create``) and declares its harness defaults here, so the harness
runs it in ``compare``, ``regress``, ``stability``, ``c60 compare`` and ``report`` without a
line of harness code naming it."""

from clearbench.adapters import lazy_engine
from clearbench.adapters.harness_defaults import C60_ON, HarnessDefaults, QuickRun

__all__ = ["HARNESS_DEFAULTS", "ToyEngine", "availability", "create"]

create, __getattr__ = lazy_engine(__name__, "ToyEngine")

#: The toy in the harness: one quick run (the bounce, 0.5 s: the first impact at 0.45 s and
#: the rebound), compliant contacts, no numba, one C-60 step in the demo plan (it cannot build
#: the C-60: the run is recorded unsupported, with the features it lacks), its own colour.
HARNESS_DEFAULTS = HarnessDefaults(
    regress_runs=(QuickRun("bouncing-ball-e0.5", 0.5),),
    c60_ladders={"demo": {C60_ON: {"default": (1e-3,)}}},
    colour="#8C564B",
)


def availability() -> tuple[bool, str]:
    """Always available: numpy only."""
    return True, "toy engine 1.0 (tests/toy_engine)"
