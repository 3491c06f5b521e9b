"""Benchmarks of the reference engine: they measure and print, they assert nothing.

- :func:`reference_step_costs`: wall time per step and per contact per solver iteration on the
  clearance pendulum and on a scene with more than 100 active contacts (box grid);
- :func:`clearance_ladder`: the frictionless clearance pendulum against the exact ideal
  pendulum on a ladder of clearances, with a figure;
- :func:`c60_costs`: wall time per run and per step of the full C-60 runs (c60-trip, c60-on)
  with the solver's iteration and residual statistics.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from clearbench.adapters.base import RunSettings
from clearbench.adapters.reference import create
from clearbench.scenarios import analytic
from clearbench.scenarios.registry import get_scene

from . import metrics


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
                solver_seconds=trajectory.metadata["solver_seconds"],
                contact_iterations=trajectory.metadata["contact_sweeps"],
            )
            if best is None or cost.stepping_seconds < best.stepping_seconds:
                best = cost
        out.append(best)
    return out


#: (radial clearance [m], time step [s]) rungs: the step shrinks with the clearance so that the
#: per-step drift of a velocity-level scheme (about h^2 omega^2 L) stays below the clearance.
LADDER = ((1e-3, 1e-3), (1e-4, 3e-4), (1e-5, 1e-4), (1e-6, 3e-5))


@dataclass(frozen=True)
class LadderRung:
    clearance: float
    time_step: float
    angle_error: float       # largest |angle - exact ideal angle| [rad]
    excess: float            # largest eccentricity beyond the clearance [m]
    converged: bool
    stepping_seconds: float
    times: np.ndarray
    error_history: np.ndarray


def clearance_ladder(horizon: float = 0.5, ladder=LADDER) -> list[LadderRung]:
    """Frictionless clearance pendulum against the exact ideal pendulum (elliptic functions)."""
    engine = create()
    ideal = get_scene("pendulum").expectations[0].parameters
    frequency = analytic.physical_pendulum_frequency(
        ideal["mass"], ideal["pivot_distance"], ideal["pivot_inertia"], ideal["gravity"])
    rungs = []
    for clearance, step in ladder:
        scene = get_scene("clearance-pendulum", radial_clearance=clearance,
                          axial_clearance=clearance, friction=0.0)
        trajectory = engine.run(scene, RunSettings(time_step=step, horizon=horizon))
        angle = ideal["initial_angle"] + metrics.output_values(scene, trajectory)["angle"]
        exact = analytic.pendulum_angle(trajectory.times, ideal["initial_angle"], frequency)
        error = np.abs(angle - exact)
        rungs.append(LadderRung(
            clearance, step, float(error.max()),
            float(metrics.clearance_motion(scene, trajectory).excess.max()),
            bool(trajectory.solver_converged.all()), trajectory.stepping_seconds,
            trajectory.times, error))
    return rungs


def plot_clearance_ladder(rungs: list[LadderRung], path) -> None:
    """Angle error against time for each rung, and the largest error against the clearance."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figure, (left, right) = plt.subplots(1, 2, figsize=(10, 4))
    for rung in rungs:
        left.semilogy(rung.times, np.maximum(rung.error_history, 1e-16),
                      label=f"c = {rung.clearance:g} m, h = {rung.time_step:g} s")
    left.set_xlabel("time [s]")
    left.set_ylabel("|angle - ideal| [rad]")
    left.legend(fontsize=8)
    left.set_title("clearance pendulum vs exact ideal pendulum")
    clearances = [r.clearance for r in rungs]
    right.loglog(clearances, [r.angle_error for r in rungs], "o-")
    right.set_xlabel("radial clearance [m]")
    right.set_ylabel("largest angle error [rad]")
    right.set_title("goes to zero with the clearance")
    right.grid(True, which="both", alpha=0.3)
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    plt.close(figure)


@dataclass(frozen=True)
class PhysicsRow:
    """One expectation figure of one run."""

    scene: str
    time_step: float
    expectation: str
    figure: str
    value: float
    converged: bool
    stepping_seconds: float


def engine_physics_table(engine_name: str = "reference", preset: str = "default",
                         time_steps: tuple = (None,), tag: str | None = None) -> list[PhysicsRow]:
    """Every expectation figure of every library scene (optionally with ``tag``) for one engine
    and preset, at each of ``time_steps`` (None: the scene's own step) [scene units]."""
    import importlib

    from clearbench.adapters.availability import ENGINE_MODULES
    from clearbench.scenarios.registry import scene_names

    from .expectations import evaluate

    module = importlib.import_module(f"clearbench.adapters.{ENGINE_MODULES[engine_name]}")
    engine = module.create(preset)
    rows = []
    for name in scene_names(tag):
        scene = get_scene(name)
        for step in time_steps:
            trajectory = engine.run(scene, RunSettings(time_step=step))
            for result in evaluate(scene, trajectory):
                for figure, value in result.figures.items():
                    rows.append(PhysicsRow(name, trajectory.time_step, result.name, figure,
                                           value, bool(trajectory.solver_converged.all()),
                                           trajectory.stepping_seconds))
    return rows


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
                solver_seconds=trajectory.metadata["solver_seconds"],
                mean_active_contacts=float(np.mean(trajectory.active_contacts[1:])),
                mean_iterations=float(np.mean(trajectory.solver_iterations[1:])),
                median_residual=float(np.nanmedian(residual)),
                max_residual=float(np.nanmax(residual)),
                unconverged_steps=len(trajectory.metadata["unconverged_steps"]),
            ))
    return out
