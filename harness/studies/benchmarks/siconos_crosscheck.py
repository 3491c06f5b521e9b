"""The reference solver against Siconos 4.4 at equal time steps
(``clearbench bench siconos-crosscheck``): the analytic scenes, the clearance pendulum and the
Flores-Leine-Glocker slider-crank, each at its own step and horizon."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from clearbench.adapters import siconos
from clearbench.adapters.base import RunSettings
from clearbench.adapters.reference import create
from clearbench.harness.measure import series
from clearbench.kernels.quaternion import quat_angular_distance_batch
from clearbench.scenarios.library import get_scene, scene_names
from clearbench.scenarios.scales import feature_lengths


def crosscheck_scenes() -> tuple[str, ...]:
    """Scenes of the cross-check: every analytic scene, the clearance pendulum and the
    Flores-Leine-Glocker slider-crank."""
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
    reference = create()
    rows = []
    for name in scenes or crosscheck_scenes():
        scene = get_scene(name)
        settings = RunSettings(horizon=horizon)
        reference.run(scene, RunSettings(horizon=10 * scene.time_step))  # compile
        ours = reference.run(scene, settings)
        for preset in presets:
            theirs = siconos.create(preset).run(scene, settings)
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
                  reference_unconverged=ours.unconverged_count
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
    com_ours = series.centre_of_mass_positions(scene, ours)[:, moving]
    com_theirs = series.centre_of_mass_positions(scene, theirs)[:, moving]
    com_distance = np.max(np.linalg.norm(com_theirs - com_ours, axis=-1), axis=1)
    # A body at rest has no range: compare with a millionth of the scene's largest feature.
    floor = 1e-6 * max(feature_lengths(scene), default=1.0)
    com_range = max(float(np.max(np.ptp(com_ours, axis=0))) if len(moving) else 0.0, floor)
    rotation = quat_angular_distance_batch(theirs.orientations[:, moving],
                                           ours.orientations[:, moving])
    ours_out = series.output_values(scene, ours)
    theirs_out = series.output_values(scene, theirs)
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
        siconos_unconverged=theirs.unconverged_count,
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
