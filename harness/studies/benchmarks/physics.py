"""The reference engine against physics (it measures and reports, it asserts nothing).

Every figure comes from the shared evaluator
:func:`clearbench.harness.measure.expectation_figures.evaluate`.

- :func:`engine_physics_table` (``clearbench bench reference-physics``): every expectation figure
  of every library scene, for one engine and preset;
- :func:`impact_localisation` (``clearbench bench impact-localisation``): bouncing-ball apex
  errors with impact localisation off (classic Moreau-Jean) and on;
- :func:`flores_reference` (``clearbench bench flores-reference``): the reference trajectory of
  the Flores-Leine-Glocker slider-crank at h = 1e-5 s, with its expectation figures;
- :func:`scale_invariance` (``clearbench bench scale-invariance``): the clearance pendulum in SI
  against mm-g-ms, and against SI with the bob moved by 1e-15 m.
"""

from __future__ import annotations

import dataclasses
import importlib
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from clearbench.adapters.base import RunSettings
from clearbench.adapters.reference import create
from clearbench.adapters.trajectory import Trajectory
from clearbench.harness.measure.expectation_figures import ExpectationResult, evaluate
from clearbench.harness.run.engine_choice import engine_module_path
from clearbench.scenarios.library import get_scene, scene_names
from clearbench.scenarios.units import MM_G_MS


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
                         time_steps: tuple = (None,), tag: str | None = None,
                         options: Mapping | None = None) -> list[PhysicsRow]:
    """Every expectation figure of every library scene (optionally with ``tag``) for one engine
    and preset (with the engine ``options``), at each of ``time_steps`` (None: the scene's own
    step) [scene units]."""
    engine = importlib.import_module(engine_module_path(engine_name)).create(preset)
    rows = []
    for name in scene_names(tag):
        scene = get_scene(name)
        for step in time_steps:
            trajectory = engine.run(scene, RunSettings(time_step=step,
                                                       options=dict(options or {})))
            for result in evaluate(scene, trajectory):
                for figure, value in result.figures.items():
                    rows.append(PhysicsRow(name, trajectory.time_step, result.name, figure,
                                           value, bool(trajectory.solver_converged.all()),
                                           trajectory.stepping_seconds))
    return rows


@dataclass(frozen=True)
class ImpactRow:
    """Apex figures of one bouncing-ball run (scene units)."""

    scene: str
    time_step: float
    localised: bool
    apex_relative_errors: tuple     # apexes 1-4 (nan where not reached)
    height_after_rest: float
    penetration_max: float
    split_steps: int


def impact_localisation(scenes=("bouncing-ball-e0.5", "bouncing-ball-e0.9"),
                        time_steps=(1e-3, 1e-4)) -> list[ImpactRow]:
    """Each bouncing-ball scene at each step with impact localisation off and on (the engine
    option ``localise_impacts``): the relative error of apexes 1-4, the height after t_inf,
    the penetration and the number of localised (split) steps."""
    engine = create()
    rows = []
    for name in scenes:
        scene = get_scene(name)
        for h in time_steps:
            for localise in (False, True):
                trajectory = engine.run(scene, RunSettings(
                    time_step=h, options={"localise_impacts": localise}))
                figures = {r.name: r.figures for r in evaluate(scene, trajectory)}
                apexes = figures["apex_heights"]
                rows.append(ImpactRow(
                    name, h, localise,
                    tuple(apexes.get(f"apex_{k}_relative_error", float("nan"))
                          for k in range(1, 5)),
                    apexes["height_after_rest"], figures["no_penetration"]["penetration_max"],
                    trajectory.metadata["split_steps"]))
    return rows


def flores_reference(time_step: float = 1e-5,
                     record_every: int = 10) -> tuple[Trajectory, list[ExpectationResult]]:
    """The Flores-Leine-Glocker slider-crank by the reference engine at ``time_step`` [s]
    (samples every ``record_every`` steps), and its expectation figures."""
    scene = get_scene("flores-slider-crank")
    trajectory = create().run(scene, RunSettings(time_step=time_step, record_every=record_every))
    return trajectory, evaluate(scene, trajectory)


#: Horizon of the scale-invariance runs [s] and the times at which they are compared [s].
SCALE_HORIZON = 0.5
SCALE_TIMES = (0.05, 0.1, 0.15, 0.2, 0.3, 0.4, 0.5)


def scale_invariance(times=SCALE_TIMES) -> list[tuple[float, float, float]]:
    """(t [s], largest body-position difference SI vs mm-g-ms [m], the same SI vs SI with the
    bob 1e-15 m away [m]) of the clearance pendulum at each of ``times``. Both differences grow
    at the same rate: the rattling in the clearance is chaotic."""
    engine = create()
    scene = get_scene("clearance-pendulum")
    bob = scene.body_index("bob")
    body = scene.bodies[bob]
    bodies = list(scene.bodies)
    bodies[bob] = dataclasses.replace(
        body, position=(body.position[0] + 1e-15,) + tuple(body.position[1:]))
    si = engine.run(scene, RunSettings(horizon=SCALE_HORIZON))
    mm = engine.run(scene.rescaled(MM_G_MS), RunSettings(horizon=1e3 * SCALE_HORIZON))
    moved = engine.run(dataclasses.replace(scene, bodies=tuple(bodies)),
                       RunSettings(horizon=SCALE_HORIZON))
    rows = []
    for t in times:
        k = int(np.searchsorted(si.times, t))
        units = float(np.abs(1e-3 * mm.positions[k] - si.positions[k]).max())
        perturbed = float(np.abs(moved.positions[k] - si.positions[k]).max())
        rows.append((t, units, perturbed))
    return rows
