"""Figures of the report (matplotlib, Agg backend), each returned as PNG bytes.

- :func:`work_precision_figure`: error against stepping time per simulated time unit, one line
  per engine over its ladder of steps, the Pareto front circled;
- :func:`c60_work_precision_figure`: the C-60's FC-1 and opening-time errors against wall
  time per run, one panel each, the same lines and front;
- :func:`time_series_figure`: drift and creep over time (penetration, clearance excess, joint
  gap, slip of bodies that must stick, energy change), one line per engine.
"""

from __future__ import annotations

import dataclasses
import io
import logging
from collections.abc import Mapping

import numpy as np

from clearbench.adapters.trajectory import Trajectory
from clearbench.harness.measure import series as metrics
from clearbench.harness.report.engine_style import engine_style
from clearbench.scenarios.expectation_kinds import body_stays
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


def ladder_line(axes, label: str, x, y, steps, colours: Mapping[str, str] | None = None
                ) -> None:
    """One engine's ladder on log-log axes in its own style, each point annotated with its
    step. ``x``, ``y``, ``steps``: (n,) sequences; ``colours``: as :func:`.engine_style`."""
    style = engine_style(label, colours)
    axes.loglog(x, y, label=label, **style.plot_kwargs())
    for xi, yi, dt in zip(x, y, steps, strict=True):
        axes.annotate(f"{dt:.2g}", (xi, yi), textcoords="offset points", xytext=(4, 3),
                      fontsize=7, color=style.colour)


def pareto_circles(axes, x, y) -> None:
    """Circle the Pareto-front points (x, y: (n,) sequences) in black."""
    if len(x):
        axes.loglog(x, y, "o", markersize=12, markerfacecolor="none",
                    markeredgecolor="black", label="Pareto front")


def work_precision_figure(points, title: str, colours: Mapping[str, str] | None = None
                          ) -> bytes:
    """``points``: DataFrame from :func:`.sweep.work_precision_points`; ``colours``: engine
    name -> declared colour (:func:`.engine_style.engine_colours`)."""
    plt = _pyplot()
    figure, axes = plt.subplots(figsize=(6.4, 4.2))
    exact = points[points["error"] <= 0]
    points = points[points["error"] > 0]  # an exact result has no place on a log scale
    for label, rows in points.groupby("label", sort=True):
        rows = rows.sort_values("stepping_seconds_per_simulated_second")
        x = rows["stepping_seconds_per_simulated_second"].to_numpy(dtype=float)
        y = rows["error"].to_numpy(dtype=float)
        ladder_line(axes, label, x, y, rows["time_step"], colours)
    front = points[points["pareto"].astype(bool)]
    pareto_circles(axes, front["stepping_seconds_per_simulated_second"], front["error"])
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


def c60_work_precision_figure(studies, colours: Mapping[str, str] | None = None
                              ) -> bytes | None:
    """``studies``: :class:`~clearbench.harness.c60.work_precision.WorkPrecision` list, one
    panel each (relative error against stepping wall time per run [s]); None when no study
    has a point with a non-zero error. ``colours``: as :func:`work_precision_figure`."""
    drawn = [s for s in studies if any(p.error > 0 for p in s.points)]
    if not drawn:
        return None
    plt = _pyplot()
    figure, axes_row = plt.subplots(1, len(drawn), figsize=(5.2 * len(drawn), 4.2),
                                    squeeze=False)
    for axes, study in zip(axes_row[0], drawn, strict=True):
        points = [p for p in study.points if p.error > 0]
        for label in sorted({p.label for p in points}):
            mine = sorted((p for p in points if p.label == label), key=lambda p: p.wall_seconds)
            ladder_line(axes, label, [p.wall_seconds for p in mine], [p.error for p in mine],
                        [p.time_step for p in mine], colours)
        front = [p for p in points if p.on_front]
        pareto_circles(axes, [p.wall_seconds for p in front], [p.error for p in front])
        axes.axhline(0.01, color="grey", linewidth=0.8, linestyle=":")
        axes.set_xlabel("stepping wall time per run [s]")
        axes.set_ylabel(f"{study.quantity}: relative error")
        axes.set_title(f"{study.scene_name} ({study.horizon:g} ms): {study.quantity} against "
                       f"the reference at dt {study.reference_step:g} ms", fontsize=9)
        axes.grid(True, which="both", alpha=0.3)
        axes.legend(fontsize=7)
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
        if body_stays(expectation.kind):
            series[f"slip of {expectation.body} [{length}]"] = metrics.displacement(
                scene, trajectory, expectation.body)
            break
    if not scene.features & {"drivers", "point_forces", "moments"}:
        energy = metrics.energy(scene, trajectory)
        total = energy.total
        series["energy change / scale"] = (total - total[0]) / metrics.energy_scale(scene, energy)
    return series


def time_series_figure(scene: Scene, runs: dict[str, Trajectory],
                       colours: Mapping[str, str] | None = None) -> bytes | None:
    """One panel per series, one line per engine label; None when nothing can be drawn.
    ``colours``: as :func:`work_precision_figure`."""
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
            style = engine_style(label, colours)
            axis.plot(t, values, label=label, linewidth=1.0, color=style.colour,
                      linestyle=style.line_style)
        axis.set_ylabel(title, fontsize=8)
        axis.grid(True, alpha=0.3)
        axis.ticklabel_format(axis="y", style="sci", scilimits=(-3, 3))
    axes[0, 0].legend(fontsize=7, loc="best")
    axes[0, 0].set_title(f"{scene.name}: drift and creep over time", fontsize=10)
    axes[-1, 0].set_xlabel(f"time [{scene.units.time}]")
    return _png(figure)
