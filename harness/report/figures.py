"""Figures of the report (matplotlib, Agg backend), each returned as PNG bytes.

- :func:`work_precision_figure`: error against stepping time per simulated time unit, one line
  per engine over its ladder of steps, the Pareto front circled;
- :func:`time_series_figure`: drift and creep over time (penetration, clearance excess, joint
  gap, slip of bodies that must stick, energy change), one line per engine.
"""

from __future__ import annotations

import dataclasses
import io
import logging

import numpy as np

from clearbench.adapters.trajectory import Trajectory
from clearbench.harness.measure import series as metrics
from clearbench.harness.measure.figures import STICK_KINDS
from clearbench.scenarios.scene import Scene

LOG = logging.getLogger(__name__)

#: Samples per trajectory used for time-series figures (the tables hold exact maxima).
PLOT_SAMPLES = 1200


def _pyplot():
    import matplotlib  # lazy: matplotlib is loaded only when a figure is drawn

    matplotlib.use("Agg", force=True)
    import matplotlib.pyplot as plt

    return plt


def _png(figure) -> bytes:
    plt = _pyplot()
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=110, bbox_inches="tight")
    plt.close(figure)
    return buffer.getvalue()


def work_precision_figure(points, title: str) -> bytes:
    """``points``: DataFrame from :func:`.sweep.work_precision_points`."""
    plt = _pyplot()
    figure, axes = plt.subplots(figsize=(6.4, 4.2))
    exact = points[points["error"] <= 0]
    points = points[points["error"] > 0]  # an exact result has no place on a log scale
    for label, rows in points.groupby("label", sort=True):
        rows = rows.sort_values("stepping_seconds_per_simulated_second")
        x = rows["stepping_seconds_per_simulated_second"].to_numpy(dtype=float)
        y = rows["error"].to_numpy(dtype=float)
        (line,) = axes.loglog(x, y, "o-", label=label)
        for xi, yi, dt in zip(x, y, rows["time_step"], strict=True):
            axes.annotate(f"{dt:.2g}", (xi, yi), textcoords="offset points", xytext=(4, 3),
                          fontsize=7, color=line.get_color())
    front = points[points["pareto"].astype(bool)]
    if len(front):
        axes.loglog(front["stepping_seconds_per_simulated_second"], front["error"], "o",
                    markersize=12, markerfacecolor="none", markeredgecolor="black",
                    label="Pareto front")
    if len(exact):
        axes.text(0.02, 0.02, "error 0 (not drawn): " + ", ".join(
            f"{label} dt={dt:.2g}" for label, dt in zip(exact["label"], exact["time_step"],
                                                        strict=True)),
            transform=axes.transAxes, fontsize=7)
    axes.set_xlabel("stepping wall time per simulated time unit [s]")
    axes.set_ylabel("error (relative)")
    axes.set_title(title, fontsize=10)
    axes.grid(True, which="both", alpha=0.3)
    axes.legend(fontsize=8)
    return _png(figure)


def subsample(trajectory: Trajectory, samples: int = PLOT_SAMPLES) -> Trajectory:
    """The trajectory at ``samples`` evenly spaced recorded samples (first and last kept)."""
    count = len(trajectory.times)
    if count <= samples:
        return trajectory
    index = np.unique(np.linspace(0, count - 1, samples).round().astype(int))
    return dataclasses.replace(trajectory, **{name: getattr(trajectory, name)[index]
                                              for name in Trajectory.ARRAYS})


def time_series(scene: Scene, trajectory: Trajectory) -> dict[str, np.ndarray]:
    """Drift and creep series of one run, (T,) each, keyed by panel title (scene units)."""
    series: dict[str, np.ndarray] = {}
    length = scene.units.length
    if scene.expanded.contacts:
        depth = metrics.penetration(scene, trajectory)
        series[f"penetration [{length}]"] = np.max(depth, axis=1) if depth.size else \
            np.zeros(len(trajectory.times))
    if scene.clearance_joints:
        motion = metrics.clearance_motion(scene, trajectory)
        series[f"clearance excess [{length}]"] = np.max(motion.excess, axis=1)
    if scene.joints:
        series[f"ideal-joint gap [{length}]"] = np.max(
            metrics.joint_violation(scene, trajectory).distance, axis=1)
    for expectation in scene.expectations:
        if expectation.kind in STICK_KINDS:
            series[f"slip of {expectation.body} [{length}]"] = metrics.displacement(
                scene, trajectory, expectation.body)
            break
    if not scene.features & {"drivers", "point_forces", "moments"}:
        energy = metrics.energy(scene, trajectory)
        total = energy.total
        series["energy change / scale"] = (total - total[0]) / metrics.energy_scale(scene, energy)
    return series


def time_series_figure(scene: Scene, runs: dict[str, Trajectory]) -> bytes | None:
    """One panel per series, one line per engine label; None when nothing can be drawn."""
    plt = _pyplot()
    data: dict[str, dict[str, tuple]] = {}
    for label, trajectory in runs.items():
        if len(trajectory.times) < 2:
            continue
        short = subsample(trajectory)
        for title, values in time_series(scene, short).items():
            data.setdefault(title, {})[label] = (short.times, values)
    if not data:
        return None
    panels = list(data)
    figure, axes = plt.subplots(len(panels), 1, figsize=(6.4, 1.9 * len(panels) + 0.6),
                                sharex=True, squeeze=False)
    for axis, title in zip(axes[:, 0], panels, strict=True):
        for label, (t, values) in data[title].items():
            axis.plot(t, values, label=label, linewidth=1.0)
        axis.set_ylabel(title, fontsize=8)
        axis.grid(True, alpha=0.3)
        axis.ticklabel_format(axis="y", style="sci", scilimits=(-3, 3))
    axes[0, 0].legend(fontsize=7, loc="best")
    axes[0, 0].set_title(f"{scene.name}: drift and creep over time", fontsize=10)
    axes[-1, 0].set_xlabel(f"time [{scene.units.time}]")
    return _png(figure)
