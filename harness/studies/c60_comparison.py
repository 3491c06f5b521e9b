"""The C-60 across engines: which runs of ``c60-on`` and ``c60-trip`` each engine and preset
makes (a ladder of time steps per engine, for the work-precision study, as each engine
declares it: ``HARNESS_DEFAULTS.c60_ladders``, :mod:`clearbench.adapters.harness_defaults`), in
two plans:

- ``demo``: what ``clearbench demo`` runs, budgeted to a few minutes of CPU on a 2-core
  machine: horizons shortened to 4 ms (c60-on: the mechanism is settled from 3 ms and FC-1 is
  the mean over the last 1 ms) and 8.5 ms (c60-trip: the reference's contacts open at 7.6 ms),
  short ladders, the expensive engines at one step;
- ``full``: the scenes' own horizons (7 ms, 20 ms) and longer ladders for every preset (hours
  of CPU; ``clearbench c60 compare --plan full``).

Steps and horizons in ms (the scenes' mm-g-ms units). Timeouts are wall-clock limits against
hangs, generous because the machine may be shared (a c60-trip of the reference that takes
58 s of CPU timed out at 600 s under a load of 15 on 2 cores). An engine not available here
is left out of the runs (the report lists it with the reason); a preset that cannot build the
C-60 records an ``unsupported`` run with its reason.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from clearbench.harness.c60.cross_engine import ON_SCENE, TRIP_SCENE
from clearbench.harness.run.engine_choice import (
    EngineChoice,
    RunInputError,
    engine_defaults,
    engine_names,
    resolve_engine,
)
from clearbench.harness.run.spec import RunSpec, make_run_spec

#: Samples are recorded about every SAMPLE_SPACING ms whatever the step: trip events are
#: resolved to 0.01 ms (the events are 0.8-4 ms apart) and FC-1's 1 ms window averages 100
#: samples.
SAMPLE_SPACING = 0.01


@dataclass(frozen=True)
class C60Plan:
    """``horizons``: scene -> horizon [ms]; ``ladders``: scene -> engine label -> steps [ms]."""

    name: str
    description: str
    horizons: Mapping[str, float]
    ladders: Mapping[str, Mapping[str, tuple[float, ...]]]
    timeout: float

    def labels(self) -> list[str]:
        return list(dict.fromkeys(label for ladder in self.ladders.values() for label in ladder))


#: The plans, each as (description, scene -> horizon [ms], timeout [s]); their ladders are
#: what each engine declares for them (``HARNESS_DEFAULTS.c60_ladders``, :func:`c60_plan`).
PLAN_SETTINGS = {
    "demo": ("c60-on to 4 ms and c60-trip to 8.5 ms (shortened for the demo); the reference at "
             "1 us is the fine run every error is measured against",
             {ON_SCENE: 4.0, TRIP_SCENE: 8.5}, 1800.0),
    "full": ("c60-on (7 ms) and c60-trip (20 ms) at the scenes' own horizons; the reference at "
             "0.5 us is the fine run every error is measured against",
             {ON_SCENE: 7.0, TRIP_SCENE: 20.0}, 7200.0),
}
PLAN_NAMES = tuple(PLAN_SETTINGS)


def c60_plan(name: str, extra_modules: Mapping[str, str] | None = None) -> C60Plan:
    """Plan ``name`` (:data:`PLAN_NAMES`) with the ladders every engine of the registry and
    of ``extra_modules`` declares for it, in that order of engines and each engine's order of
    presets.

    Raises
    ------
    RunInputError
        An engine module that fails to load, or a ladder declared for a plan or a scene the
        harness does not have.
    """
    description, horizons, timeout = PLAN_SETTINGS[name]
    ladders: dict[str, dict[str, tuple[float, ...]]] = {scene: {} for scene in horizons}
    for engine in engine_names(extra_modules):
        declared = engine_defaults(engine, extra_modules).c60_ladders
        for plan_name, scenes in declared.items():
            for scene, ladder in scenes.items():
                if plan_name not in PLAN_SETTINGS or scene not in horizons:
                    raise RunInputError(f"{engine} HARNESS_DEFAULTS.c60_ladders",
                                        f"{plan_name}/{scene}",
                                        f"plans: {', '.join(PLAN_NAMES)}; scenes: "
                                        f"{', '.join(horizons)}")
                if plan_name == name:
                    ladders[scene].update({f"{engine}[{preset}]": tuple(map(float, steps))
                                           for preset, steps in ladder.items()})
    return C60Plan(name, description, horizons, ladders, timeout)


def record_every(time_step: float) -> int:
    """Steps between recorded samples for about :data:`SAMPLE_SPACING` ms."""
    return max(1, round(SAMPLE_SPACING / time_step))


def plan_runs(plan: C60Plan, engines: Sequence[EngineChoice],
              campaign: str = "c60-compare") -> list[RunSpec]:
    """The plan's runs for the engines given (EngineChoice of each available label); labels
    of the plan whose engine is not among them are left out. The runs of largest expected cost
    come first (steps x the engine's ``HARNESS_DEFAULTS.c60_step_cost``): on parallel workers
    the plan then takes about its longest run's wall time, not that run's after all others."""
    chosen = {engine.label: engine for engine in engines}
    specs = []
    for scene_name, ladder in plan.ladders.items():
        for label, steps in ladder.items():
            engine = chosen.get(label)
            if engine is None:
                continue
            for dt in steps:
                specs.append(make_run_spec(
                    scene_name, label, scene_parameters={"horizon": plan.horizons[scene_name]},
                    time_step=dt, record_every=record_every(dt), timeout=plan.timeout,
                    engine_choice=engine, campaign=f"{campaign}:{plan.name}"))
    specs.sort(key=lambda s: -expected_cost(s))
    return specs


def expected_cost(spec: RunSpec) -> float:
    """Steps of ``spec`` times its engine's declared C-60 cost per step relative to the
    reference's (dimensionless: reference steps)."""
    steps = spec.horizon / spec.time_step
    declared = engine_defaults(spec.engine.name, {spec.engine.name: spec.engine.module})
    return steps * declared.c60_step_cost


def plan_engines(plan: C60Plan, labels: Sequence[str] | None = None,
                 extra_modules: Mapping[str, str] | None = None
                 ) -> tuple[list[EngineChoice], dict[str, str]]:
    """The plan's engine labels (or those of ``labels`` it has a ladder for) resolved, and
    label -> why not, for those that cannot run here (engine not available, preset refused,
    no ladder declared in the plan)."""
    chosen, left_out = [], {}
    planned = plan.labels()
    for label in labels if labels is not None else planned:
        try:
            choice = resolve_engine(label, extra_modules)
        except RunInputError as error:
            left_out[label] = error.reason
            continue
        if choice.label in planned:
            chosen.append(choice)
        else:
            left_out[label] = (f"no ladder in the {plan.name} plan (the engine declares its "
                               "C-60 ladders: HARNESS_DEFAULTS.c60_ladders)")
    return chosen, left_out
