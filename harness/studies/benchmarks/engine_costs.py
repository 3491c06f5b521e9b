"""Stepping cost per step of engines side by side (``clearbench bench engines``).

Every contender (an ``engine[preset]``, with run options) runs every scene, one scene at a
time and the contenders in turn within a scene, so that a change of the machine's load weighs
on all of them alike. The runs go through the harness's isolated worker
(:class:`~clearbench.harness.run.runner.Runner`, one worker process kept warm from run to run)
with a wall-clock limit per run: an engine that hangs, crashes or diverges is a row with its
status, and the benchmark goes on with a fresh worker. A contender's first run of a scene is
a short warm-up (it compiles, loads caches), untimed; the measured run's cost per step is its
``stepping_seconds / steps``, as the run store's ``stepping_seconds_per_step``, and its
contact solver's iterations per step the run's total (every engine adds up its steps'
iterations into the next recorded sample, so the samples' sum is the run's total) over its
steps. The figures are printed; nothing is asserted about time.
"""

from __future__ import annotations

import importlib
import math
import tempfile
from collections.abc import Mapping
from dataclasses import dataclass, field

from clearbench.adapters import ENGINES, engine_availability
from clearbench.adapters.trajectory import RunStatus
from clearbench.harness.run.runner import Runner
from clearbench.harness.run.spec import DEFAULT_TIMEOUT, make_run_spec
from clearbench.harness.run.store import ResultsStore
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
    """One measured run: ``seconds_per_step`` [s] and ``iterations_per_step`` (the contact
    solver's, mean over the run's steps; NaN when the run reports none, as Drake's, or did not
    run: ``status``, ``message`` say why)."""

    scene: str
    contender: str
    steps: int
    seconds_per_step: float
    status: str
    message: str = ""
    iterations_per_step: float = math.nan


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


def measure(scenes: list[str], contenders: list[Contender], steps: int, report=None,
            timeout: float = DEFAULT_TIMEOUT,
            extra_engine_modules: Mapping[str, str] | None = None) -> list[EngineCost]:
    """Cost per step of each contender on each scene over ``steps`` steps of the scene's time
    step (at most the scene's horizon). ``timeout`` [s] is the wall-clock limit of each run
    (the warm-up and the measured one); a contender whose warm-up crashed or timed out is not
    run again on that scene. ``report(cost)``, when given, is called as each figure comes."""
    costs = []
    with tempfile.TemporaryDirectory(prefix="clearbench-bench-") as folder:
        runner = Runner(ResultsStore(folder), jobs=1, runs_per_worker=1_000_000,
                        keep_workers=True)
        try:
            for name in scenes:
                scene = get_scene(name)
                dt = scene.time_step
                horizon = min(scene.horizon, steps * dt)
                for contender in contenders:
                    cost = _measure_one(runner, name, contender, dt, horizon, steps, timeout,
                                        extra_engine_modules)
                    costs.append(cost)
                    if report is not None:
                        report(cost)
        finally:
            runner.close()
    return costs


def _measure_one(runner: Runner, scene: str, contender: Contender, dt: float, horizon: float,
                 steps: int, timeout: float,
                 extra_engine_modules: Mapping[str, str] | None) -> EngineCost:
    """The warm-up run, then the measured one, of one contender on one scene."""
    def spec(end: float, record_every: int):
        return make_run_spec(scene, f"{contender.engine}[{contender.preset}]", horizon=end,
                             record_every=record_every, options=contender.options,
                             timeout=timeout, extra_engine_modules=extra_engine_modules)

    warm_up = spec(min(horizon, WARM_UP_STEPS * dt), 1)
    record = _run(runner, warm_up)
    if record["status"] in (RunStatus.CRASHED.value, RunStatus.TIMED_OUT.value):
        return EngineCost(scene, contender.label, 0, math.nan, record["status"],
                          f"warm-up: {record['message']}")
    measured = spec(horizon, max(1, steps // 10))
    record = _run(runner, measured)
    ran = int(record["steps"] or 0)
    per_step = record["stepping_seconds"] / ran if ran > 0 else math.nan
    message = record["message"] if record["status"] != RunStatus.OK.value else ""
    return EngineCost(scene, contender.label, ran, per_step, record["status"], message,
                      _iterations_per_step(runner.store.load_trajectory(measured.key)))


def _iterations_per_step(trajectory) -> float:
    """The run's contact-solver iterations per step (``Trajectory.iterations_per_step``). NaN
    without a trajectory, a step or an iteration (an engine that reports none, or a run with
    no contact solve)."""
    if trajectory is None:
        return math.nan
    per_step = trajectory.iterations_per_step
    return per_step if per_step > 0 else math.nan


def _run(runner: Runner, spec) -> dict:
    """Run ``spec`` in the runner's worker (again if its store has it) and return its row."""
    runner.run_all([spec], rerun=True)
    return runner.store.get(spec.key)


def ratios_to(costs: list[EngineCost], reference: str) -> dict[tuple[str, str], float]:
    """(scene, contender) -> cost per step over that of the contender ``reference`` on the
    same scene (NaN where either did not run)."""
    base = {c.scene: c.seconds_per_step for c in costs if c.contender == reference}
    return {(c.scene, c.contender): c.seconds_per_step / base.get(c.scene, math.nan)
            for c in costs}
