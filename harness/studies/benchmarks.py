"""Benchmarks of the reference engine: they measure and print, they assert nothing.

- :func:`reference_step_costs`: wall time per step and per contact per solver iteration on the
  clearance pendulum and on a scene with more than 100 active contacts (box grid);
- :func:`clearance_ladder`: the frictionless clearance pendulum against the exact ideal
  pendulum on a ladder of clearances, with a figure;
- :func:`c60_costs`: wall time per run and per step of the full C-60 runs (c60-trip, c60-on)
  with the solver's iteration and residual statistics.
- :func:`siconos_crosscheck`: the reference solver against Siconos 4.4 at equal time steps on
  the analytic scenes, the clearance pendulum and the Flores slider-crank.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from clearbench.adapters import ENGINES
from clearbench.adapters.base import RunSettings
from clearbench.adapters.reference.engine import create
from clearbench.harness.measure import series as metrics
from clearbench.kernels.quaternion import quat_angular_distance_batch
from clearbench.scenarios import analytic
from clearbench.scenarios.library import get_scene
from clearbench.scenarios.scales import feature_lengths


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


# ---------------------------------------------------------------------------- Siconos
#: Scenes of the Siconos cross-check: every analytic scene, the clearance pendulum and the
#: Flores-Leine-Glocker slider-crank.
def crosscheck_scenes() -> tuple[str, ...]:
    from clearbench.scenarios.library import scene_names

    return tuple(scene_names("analytic")) + ("clearance-pendulum", "flores-slider-crank")


@dataclass(frozen=True)
class CrossCheckRow:
    """Reference solver against one Siconos preset on one scene, at the scene's time step.

    Differences are maxima over the recorded samples: ``output_difference`` over the scene's
    named outputs (the largest relative to its range, ``output_name``, in that output's unit),
    ``position_difference`` the distance between the centres of mass of the same body [L],
    ``rotation_difference`` the angle between the orientations of the same body [rad].
    ``divergence_time`` is the first time at which the compared quantity (the worst output, or
    the centre of mass when the scene has no outputs) differs by more than 1 % of its range in
    the reference run [T] (nan: never). Residuals are each engine's own normalised one-step
    residual (largest over the run), with the count of steps that did not converge (ours:
    contact problem or projection; Siconos: one-step problem). Times are stepping wall time per
    step [us]."""

    scene: str
    preset: str
    time_step: float
    steps: int
    status: str
    output_name: str
    output_difference: float
    position_difference: float
    rotation_difference: float
    divergence_time: float
    reference_residual: float
    siconos_residual: float
    reference_unconverged: int
    siconos_unconverged: int
    reference_us_per_step: float
    siconos_us_per_step: float
    siconos_python_seconds: float
    siconos_stepping_seconds: float
    message: str

    @property
    def time_ratio(self) -> float:
        """Our time per step over Siconos's (< 1: ours is faster)."""
        return self.reference_us_per_step / self.siconos_us_per_step

    @property
    def python_share(self) -> float:
        """Fraction of Siconos's stepping time spent in our Python contact relations."""
        return self.siconos_python_seconds / max(self.siconos_stepping_seconds, 1e-300)


def siconos_crosscheck(scenes=None, presets=("projection", "default"),
                       horizon: float | None = None) -> list[CrossCheckRow]:
    """Run the reference engine and Siconos (each preset) on each scene at the scene's time
    step over its horizon (or ``horizon``), and compare them."""
    from clearbench.adapters.siconos import engine as siconos_engine

    reference = create()
    rows = []
    for name in scenes or crosscheck_scenes():
        scene = get_scene(name)
        settings = RunSettings(horizon=horizon)
        reference.run(scene, RunSettings(horizon=10 * scene.time_step))  # compile
        ours = reference.run(scene, settings)
        for preset in presets:
            theirs = siconos_engine.create(preset).run(scene, settings)
            rows.append(_crosscheck_row(scene, preset, ours, theirs))
    return rows


def _first_time(times, difference, scale) -> float:
    over = np.nonzero(difference > 0.01 * scale)[0]
    return float(times[over[0]]) if len(over) else float("nan")


def _crosscheck_row(scene, preset, ours, theirs) -> CrossCheckRow:
    nan = float("nan")
    common = dict(scene=scene.name, preset=preset, time_step=ours.time_step, steps=ours.steps,
                  status=theirs.status.value,
                  reference_residual=float(np.nanmax(ours.solver_residual, initial=0.0)),
                  reference_unconverged=len(ours.metadata.get("unconverged_steps", []))
                  + len(ours.metadata.get("unconverged_projections", [])),
                  reference_us_per_step=1e6 * ours.stepping_seconds / max(ours.steps, 1),
                  message=theirs.message)
    if len(theirs.times) != len(ours.times):
        return CrossCheckRow(**common, output_name="", output_difference=nan,
                             position_difference=nan, rotation_difference=nan,
                             divergence_time=nan, siconos_residual=nan,
                             siconos_unconverged=0, siconos_us_per_step=nan,
                             siconos_python_seconds=nan, siconos_stepping_seconds=nan)
    times = ours.times
    moving = [i for i, b in enumerate(scene.bodies) if b.motion.value != "fixed"]
    com_ours = metrics.centre_of_mass_positions(scene, ours)[:, moving]
    com_theirs = metrics.centre_of_mass_positions(scene, theirs)[:, moving]
    com_distance = np.max(np.linalg.norm(com_theirs - com_ours, axis=-1), axis=1)
    # A body at rest has no range: compare with a millionth of the scene's largest feature.
    floor = 1e-6 * max(feature_lengths(scene), default=1.0)
    com_range = max(float(np.max(np.ptp(com_ours, axis=0))) if len(moving) else 0.0, floor)
    rotation = quat_angular_distance_batch(theirs.orientations[:, moving],
                                           ours.orientations[:, moving])
    ours_out = metrics.output_values(scene, ours)
    theirs_out = metrics.output_values(scene, theirs)
    output_name, output_difference, worst = "", nan, -1.0
    divergence = _first_time(times, com_distance, com_range)
    for key in ours_out:
        difference = np.abs(theirs_out[key] - ours_out[key])
        # An output that does not move (the Flores slider's angle, ~1e-11 rad) is compared
        # with a floor of 1e-6 in its unit, not with its round-off range.
        scale = max(float(np.ptp(ours_out[key])), 1e-6)
        if float(np.max(difference)) / scale > worst:
            worst = float(np.max(difference)) / scale
            output_name, output_difference = key, float(np.max(difference))
            divergence = _first_time(times, difference, scale)
    return CrossCheckRow(
        **common, output_name=output_name, output_difference=output_difference,
        position_difference=float(np.max(com_distance)) if len(moving) else 0.0,
        rotation_difference=float(np.max(rotation)) if len(moving) else 0.0,
        divergence_time=divergence,
        siconos_residual=float(np.nanmax(theirs.solver_residual, initial=0.0)),
        siconos_unconverged=int(theirs.metadata.get("unconverged_count", 0)),
        siconos_us_per_step=1e6 * theirs.stepping_seconds / max(theirs.steps, 1),
        siconos_python_seconds=float(theirs.metadata.get("python_relation_seconds", 0.0)),
        siconos_stepping_seconds=theirs.stepping_seconds)


def crosscheck_markdown(rows: list[CrossCheckRow]) -> str:
    """The cross-check as a Markdown table."""
    lines = [
        "| scene | Siconos preset | h [s] | steps | max \\|Δ output\\| (output) | "
        "max \\|Δ COM\\| [m] | max Δ rotation [rad] | Δ > 1 % from t [s] | "
        "residual ours / Siconos | unconverged ours / Siconos | us/step ours / Siconos | "
        "time ours / Siconos | Python share of Siconos time |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        if r.status not in ("ok", "diverged"):
            lines.append(f"| {r.scene} | {r.preset} | {r.time_step:g} | {r.steps} | "
                         f"{r.status}: {r.message[:60]} |" + " |" * 8)
            continue
        output = f"{r.output_difference:.2e} ({r.output_name})" if r.output_name else "-"
        divergence = "never" if math.isnan(r.divergence_time) else f"{r.divergence_time:.4g}"
        lines.append(
            f"| {r.scene} | {r.preset} | {r.time_step:g} | {r.steps} | {output} | "
            f"{r.position_difference:.2e} | {r.rotation_difference:.2e} | {divergence} | "
            f"{r.reference_residual:.0e} / {r.siconos_residual:.0e} | "
            f"{r.reference_unconverged} / {r.siconos_unconverged} | "
            f"{r.reference_us_per_step:.0f} / {r.siconos_us_per_step:.0f} | "
            f"{r.time_ratio:.2f} | {100 * r.python_share:.0f} % |")
    return "\n".join(lines)


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

    from clearbench.harness.measure.expectation_figures import evaluate
    from clearbench.scenarios.library import scene_names

    module = importlib.import_module(ENGINES[engine_name])
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
