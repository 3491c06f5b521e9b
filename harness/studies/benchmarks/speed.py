"""Speed of the reference engine (it measures and reports, it asserts nothing).

- :func:`reference_step_costs` (``clearbench bench reference``): wall time per step and per
  contact per solver iteration on the clearance pendulum and on a scene with more than 100
  active contacts (box grid);
- :func:`c60_costs` (``clearbench bench c60``): wall time per run and per step of the full C-60
  runs (c60-trip, c60-on) with the solver's iteration and residual statistics;
- :func:`newton_first_runs` (``clearbench bench newton-first``): the hybrid one-step solver with
  and without its memory "Newton first after a step that needed it", on the start of c60-on.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from clearbench.adapters.base import RunSettings
from clearbench.adapters.reference import create
from clearbench.ref_solver import stepper
from clearbench.scenarios.library import get_scene


@dataclass(frozen=True)
class StepCost:
    """Measured cost of one reference run."""

    scene: str
    steps: int
    mean_active_contacts: float
    stepping_seconds: float
    solver_seconds: float
    contact_iterations: int

    @property
    def microseconds_per_step(self) -> float:
        return 1e6 * self.stepping_seconds / self.steps

    @property
    def microseconds_per_contact_iteration(self) -> float:
        """Solver time per contact per iteration (sweep or Newton iteration) [us]."""
        return 1e6 * self.solver_seconds / max(self.contact_iterations, 1)


def reference_step_costs(repeat: int = 3) -> list[StepCost]:
    """Best of ``repeat`` runs (after one warm-up run that compiles) of each benchmark scene."""
    engine = create()
    cases = (("clearance-pendulum", RunSettings(horizon=1.0)),
             ("box-grid", RunSettings(horizon=0.2)))
    parameters = {"box-grid": {"count": 30}}  # 120 corner contacts once settled
    out = []
    for name, settings in cases:
        scene = get_scene(name, **parameters.get(name, {}))
        engine.run(scene, RunSettings(horizon=10 * scene.time_step))  # compile, warm caches
        best = None
        for _ in range(repeat):
            trajectory = engine.run(scene, settings)
            cost = StepCost(
                scene=name, steps=trajectory.steps,
                mean_active_contacts=float(np.mean(trajectory.active_contacts[1:])),
                stepping_seconds=trajectory.stepping_seconds,
                solver_seconds=trajectory.solver_seconds,
                contact_iterations=trajectory.metadata["contact_sweeps"],
            )
            if best is None or cost.stepping_seconds < best.stepping_seconds:
                best = cost
        out.append(best)
    return out


@dataclass(frozen=True)
class C60Cost:
    """Measured cost and solver statistics of one C-60 run (one core)."""

    scene: str
    preset: str
    steps: int
    stepping_seconds: float
    solver_seconds: float
    mean_active_contacts: float
    mean_iterations: float      # solver iterations per step (summed over activation rounds)
    median_residual: float      # of the recorded steps' largest residual
    max_residual: float
    unconverged_steps: int

    @property
    def milliseconds_per_step(self) -> float:
        return 1e3 * self.stepping_seconds / self.steps


def c60_costs(presets: tuple[str, ...] = ("default", "newton"),
              scenes: tuple[tuple[str, dict], ...] = (("c60-trip", {}), ("c60-on", {}))
              ) -> list[C60Cost]:
    """Wall time of full C-60 runs (c60-trip: 20 ms at the source's step 1e-3 ms; c60-on:
    7 ms) with each preset, after a 20-step warm-up run that compiles the kernels."""
    out = []
    for preset in presets:
        engine = create(preset)
        for name, parameters in scenes:
            scene = get_scene(name, **parameters)
            engine.run(scene, RunSettings(horizon=20 * scene.time_step))
            trajectory = engine.run(scene, RunSettings())
            residual = trajectory.solver_residual[1:]
            out.append(C60Cost(
                scene=name, preset=preset, steps=trajectory.steps,
                stepping_seconds=trajectory.stepping_seconds,
                solver_seconds=trajectory.solver_seconds,
                mean_active_contacts=float(np.mean(trajectory.active_contacts[1:])),
                mean_iterations=trajectory.iterations_per_step,
                median_residual=float(np.nanmedian(residual)),
                max_residual=float(np.nanmax(residual)),
                unconverged_steps=trajectory.unconverged_count,
            ))
    return out


@dataclass(frozen=True)
class NewtonFirstRun:
    """One run of the start of c60-on with the hybrid solver's Newton-first memory on or off."""

    newton_first: bool
    stepping_seconds: float
    solver_seconds: float
    mean_iterations: float      # solver iterations per step
    p90_iterations: float
    unconverged_steps: int


def newton_first_runs(horizon: float = 1.5) -> list[NewtonFirstRun]:
    """The first ``horizon`` [ms] of c60-on with the reference engine, with the stepper's
    memory of the last solve disabled (every step starts with NSGS) and as shipped, each after
    a warm-up run that compiles. Times depend on the machine's load."""
    return [_newton_first_run(horizon, newton_first) for newton_first in (False, True)]


def _newton_first_run(horizon: float, newton_first: bool) -> NewtonFirstRun:
    # The memory is private to the stepper: the benchmark switches it off by wrapping _solve.
    original = stepper.MoreauJeanStepper._solve

    def nsgs_first(self, problem, r0):
        self._newton_first = False  # forget that the last step needed Newton
        return original(self, problem, r0)

    if not newton_first:
        stepper.MoreauJeanStepper._solve = nsgs_first
    try:
        engine = create()
        scene = get_scene("c60-on")
        engine.run(scene, RunSettings(horizon=0.01))  # compile
        trajectory = engine.run(scene, RunSettings(horizon=horizon))
    finally:
        stepper.MoreauJeanStepper._solve = original
    iterations = trajectory.solver_iterations[1:]
    return NewtonFirstRun(newton_first, trajectory.stepping_seconds,
                          trajectory.solver_seconds, float(iterations.mean()),
                          float(np.percentile(iterations, 90)),
                          trajectory.unconverged_count)
