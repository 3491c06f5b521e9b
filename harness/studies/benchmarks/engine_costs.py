"""Stepping cost per step of engines side by side (``clearbench bench engines``).

Every contender (an ``engine[preset]``, with run options) runs every scene in one process,
one scene at a time and the contenders in turn within a scene, so that a change of the
machine's load weighs on all of them alike. A contender's first run of a scene is a short
warm-up (it compiles, loads caches), untimed; the measured run's cost per step is its
``stepping_seconds / steps``, as the run store's ``stepping_seconds_per_step``. The figures
are printed; nothing is asserted about time.
"""

from __future__ import annotations

import importlib
import math
from dataclasses import dataclass, field

from clearbench.adapters import ENGINES, engine_availability
from clearbench.adapters.base import RunSettings
from clearbench.scenarios.library import get_scene

#: Steps of the untimed warm-up run of each contender and scene.
WARM_UP_STEPS = 5


@dataclass(frozen=True)
class Contender:
    """An engine[preset] with its run options; ``label`` names it in the table."""

    engine: str
    preset: str
    options: dict = field(default_factory=dict)

    @property
    def label(self) -> str:
        extra = ",".join(f"{k}={v}" for k, v in sorted(self.options.items()))
        return f"{self.engine}[{self.preset}]" + (f" {extra}" if extra else "")


@dataclass(frozen=True)
class EngineCost:
    """One measured run: ``seconds_per_step`` [s] (NaN when it did not run: ``status``,
    ``message`` say why)."""

    scene: str
    contender: str
    steps: int
    seconds_per_step: float
    status: str
    message: str = ""


def available_contenders(engines: list[str] | None = None) -> list[Contender]:
    """Every preset of every available engine (of ``engines``, default all), in the order of
    the engine registry."""
    out = []
    for name in engines or list(ENGINES):
        if not engine_availability(name).available:
            continue
        engine = importlib.import_module(ENGINES[name]).create("default")
        out.extend(Contender(name, preset) for preset in engine.PRESETS)
    return out


def measure(scenes: list[str], contenders: list[Contender], steps: int,
            report=None) -> list[EngineCost]:
    """Cost per step of each contender on each scene over ``steps`` steps of the scene's time
    step (at most the scene's horizon). ``report(cost)``, when given, is called as each
    figure comes."""
    costs = []
    for name in scenes:
        scene = get_scene(name)
        dt = scene.time_step
        horizon = min(scene.horizon, steps * dt)
        for contender in contenders:
            engine = importlib.import_module(ENGINES[contender.engine]).create(contender.preset)
            try:
                engine.run(scene, RunSettings(horizon=min(horizon, WARM_UP_STEPS * dt),
                                              options=contender.options))
                run = engine.run(scene, RunSettings(horizon=horizon, options=contender.options,
                                                    record_every=max(1, steps // 10)))
            except Exception as error:  # a contender that fails is a figure, not a crash
                cost = EngineCost(name, contender.label, 0, math.nan, "error",
                                  f"{type(error).__name__}: {error}")
            else:
                per_step = run.stepping_seconds / run.steps if run.steps > 0 else math.nan
                cost = EngineCost(name, contender.label, run.steps, per_step,
                                  run.status.value, run.message if run.steps == 0 else "")
            costs.append(cost)
            if report is not None:
                report(cost)
    return costs


def ratios_to(costs: list[EngineCost], reference: str) -> dict[tuple[str, str], float]:
    """(scene, contender) -> cost per step over that of the contender ``reference`` on the
    same scene (NaN where either did not run)."""
    base = {c.scene: c.seconds_per_step for c in costs if c.contender == reference}
    return {(c.scene, c.contender): c.seconds_per_step / base.get(c.scene, math.nan)
            for c in costs}
