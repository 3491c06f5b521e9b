"""The toy engine: a :class:`~clearbench.adapters.base.SteppingEngine` whose hooks are the
modules beside it (see the package docstring): settings resolved from the preset and the
options, capabilities per feature, the model built, the runner of a run, the notes of a run."""

from __future__ import annotations

from clearbench.adapters.base import SteppingEngine
from clearbench.scenarios.scene import Scene

from . import capabilities
from .build import build_model
from .run import Runner
from .settings import OPTIONS, PRESETS, ToySettings, resolve_settings

__all__ = ["OPTIONS", "PRESETS", "ToyEngine", "create"]


def create(preset: str = "default") -> ToyEngine:
    """A :class:`ToyEngine` with ``preset`` (ValueError for an unknown one)."""
    return ToyEngine(preset)


class ToyEngine(SteppingEngine):
    """Free bodies, spheres and planes (see :mod:`.build`)."""

    name = "toy"
    TITLE = "Toy"
    PRESETS = PRESETS
    OPTIONS = OPTIONS
    CAPABILITIES = capabilities
    RESOLVE_SETTINGS = staticmethod(resolve_settings)

    def build(self, internal: Scene, config: ToySettings, dt: float):
        return build_model(internal, config, dt)

    def runner(self, internal: Scene, built, config: ToySettings, steps: int,
               record_every: int) -> Runner:
        return Runner(internal, built, config, steps, record_every)

    def metadata(self, scene: Scene, internal: Scene, config: ToySettings, built,
                 runner: Runner) -> dict:
        return {"settings": config.as_dict(), "guards": runner.monitor.guard.notes}
