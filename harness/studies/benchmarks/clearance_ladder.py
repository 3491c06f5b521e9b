"""The clearance pendulum against the exact ideal pendulum on a ladder of shrinking clearances
(``clearbench bench clearance-ladder``): the reference engine's clearance joint must approach the
ideal revolute joint as the clearance goes to zero."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from clearbench.adapters.base import RunSettings
from clearbench.adapters.reference import create
from clearbench.harness.measure import series
from clearbench.scenarios import analytic
from clearbench.scenarios.library import get_scene

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
        angle = ideal["initial_angle"] + series.output_values(scene, trajectory)["angle"]
        exact = analytic.pendulum_angle(trajectory.times, ideal["initial_angle"], frequency)
        error = np.abs(angle - exact)
        rungs.append(LadderRung(
            clearance, step, float(error.max()),
            float(series.clearance_motion(scene, trajectory).excess.max()),
            bool(trajectory.solver_converged.all()), trajectory.stepping_seconds,
            trajectory.times, error))
    return rungs


def plot_clearance_ladder(rungs: list[LadderRung], path) -> None:
    """Angle error against time for each rung, and the largest error against the clearance."""
    import matplotlib  # lazy: matplotlib is loaded only when a figure is drawn

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
