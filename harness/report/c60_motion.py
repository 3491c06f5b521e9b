"""The C-60 seen moving: which runs the report shows (per engine and preset its finest step
on the comparison's horizon), the hook angle, tripping-bar angle, C7 gap and FC-1 of each
against time on one plot per quantity (events marked), and the viewer's data for them.

Units: the scenes' mm-g-ms (angles in degrees, the C7 gap in mm, FC-1 in N, times in ms).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from clearbench.adapters.trajectory import Trajectory
from clearbench.harness.c60.cross_engine import (
    LATCH_BODY,
    REFERENCE_LABEL,
    TRIP_SCENE,
    C60RunFigures,
)
from clearbench.harness.measure import series as metrics
from clearbench.harness.report.engine_style import engine_style
from clearbench.harness.report.figures import _png, _pyplot
from clearbench.harness.report.viewer.frames import RecordedRun
from clearbench.harness.report.viewer.payload import Event
from clearbench.scenarios.c60 import model
from clearbench.scenarios.geometry import smallest_gaps
from clearbench.scenarios.scene import Scene

#: The bar the hook latches on, whose angle shows the trip.
BAR_BODY = "tripping_bar"
#: The trip's events, in order (attributes of C60RunFigures).
EVENTS = ("strike", "release", "opening")
#: Marker of each event on the time series.
EVENT_MARKERS = {"strike": "v", "release": "o", "opening": "s"}
#: Statuses whose recording is shown (a diverged run up to where it stopped).
SHOWN_STATUSES = ("ok", "diverged")


@dataclass(frozen=True)
class ShownRun:
    """A run the report plays and plots: its figures (events, status) and its trajectory."""

    figures: C60RunFigures
    trajectory: Trajectory

    @property
    def title(self) -> str:
        return f"{self.figures.label} dt {self.figures.time_step:g} ms"

    @property
    def events(self) -> dict[str, float]:
        return {name: getattr(self.figures, name) for name in EVENTS}


def comparison_horizon(runs: Sequence[C60RunFigures], scene_name: str) -> float:
    """The horizon most runs of the scene share (the plan's; NaN when none) [ms]."""
    horizons = [r.horizon for r in runs if r.scene_name == scene_name]
    if not horizons:
        return math.nan
    values, counts = np.unique(horizons, return_counts=True)
    return float(values[np.argmax(counts)])


def shown_runs(store, runs: Sequence[C60RunFigures], scene_name: str) -> list[ShownRun]:
    """Per engine and preset, its finest-step run of ``scene_name`` on the comparison's
    horizon that has a recording (ok or diverged), the reference first."""
    horizon = comparison_horizon(runs, scene_name)
    best: dict[str, C60RunFigures] = {}
    for run in runs:
        if run.scene_name != scene_name or run.horizon != horizon \
                or run.status not in SHOWN_STATUSES:
            continue
        if run.label not in best or run.time_step < best[run.label].time_step:
            best[run.label] = run
    order = sorted(best, key=lambda label: (label != REFERENCE_LABEL, label))
    out = []
    for label in order:
        trajectory = store.load_trajectory(best[label].key)
        if trajectory is not None and len(trajectory.times) >= 2:
            out.append(ShownRun(best[label], trajectory))
    return out


def c7_gap(scene: Scene, trajectory: Trajectory) -> np.ndarray:
    """C7's gap (moving on fixed contact) less its offset at each sample, (T,) [mm]: the
    scene's own pair geometry (as :func:`clearbench.harness.measure.series.contact_gaps`)."""
    contact = next(c for c in scene.contacts if c.name == model.C7)
    a, b = scene.body(contact.body_a), scene.body(contact.body_b)
    ia, ib = scene.body_index(contact.body_a), scene.body_index(contact.body_b)
    return smallest_gaps(
        a.shape(contact.shape_a), (trajectory.positions[:, ia], trajectory.orientations[:, ia]),
        b.shape(contact.shape_b), (trajectory.positions[:, ib], trajectory.orientations[:, ib])
    ) - contact.offset


def motion_series(scene: Scene, trajectory: Trajectory) -> dict[str, np.ndarray]:
    """Panel title -> (T,) series of one run: the hook's and the tripping bar's rotation about
    z since t = 0 [deg], C7's gap [mm] and FC-1, C7's normal force [N]."""
    z = (0.0, 0.0, 1.0)
    return {
        "hook angle [deg]": np.degrees(metrics.body_angle(
            trajectory, scene.body_index(LATCH_BODY), z)),
        "tripping-bar angle [deg]": np.degrees(metrics.body_angle(
            trajectory, scene.body_index(BAR_BODY), z)),
        "C7 gap [mm]": c7_gap(scene, trajectory),
        "FC-1: C7 force [N]": trajectory.contact_normal_force[
            :, trajectory.contact_index(model.C7)],
    }


def readable_limits(curves: Sequence[tuple[np.ndarray, bool]], margin: float = 0.08
                    ) -> tuple[float, float] | None:
    """y limits that hold every finished run's curve (``(values, finished)`` pairs; every
    curve when none finished), ``margin`` of the span added each side: a run that diverged
    leaves the plot rather than squashing the others. None when nothing is finite."""
    chosen = [v for v, finished in curves if finished] or [v for v, _ in curves]
    values = np.concatenate([v[np.isfinite(v)] for v in chosen]) if chosen else np.zeros(0)
    if not values.size:
        return None
    low, high = float(values.min()), float(values.max())
    span = high - low or max(abs(high), 1e-9)
    return low - margin * span, high + margin * span


def time_series_figure(scene: Scene, shown: Sequence[ShownRun],
                       colours: Mapping[str, str] | None = None) -> bytes | None:
    """Every shown run on one plot per quantity of :func:`motion_series` against time, its
    trip events marked on each curve (c60-trip), y limits from the finished runs
    (:func:`readable_limits`; a curve that leaves them says 'off scale' in the legend)."""
    if not shown:
        return None
    plt = _pyplot()
    data = [(run, motion_series(scene, run.trajectory)) for run in shown]
    panels = list(data[0][1])
    if scene.name != TRIP_SCENE:
        panels = [p for p in panels if not p.startswith("C7 gap")]
    figure, axes = plt.subplots(len(panels), 1, figsize=(9.0, 1.9 * len(panels) + 0.8),
                                sharex=True, squeeze=False)
    for axis, panel in zip(axes[:, 0], panels, strict=True):
        limits = readable_limits([(values[panel], run.figures.status == "ok")
                                  for run, values in data])
        for run, values in data:
            y = values[panel]
            style = engine_style(run.figures.label, colours)
            off = limits is not None and bool(np.any((y < limits[0]) | (y > limits[1])))
            label = run.title + (f" ({run.figures.status})" if run.figures.status != "ok"
                                 else "") + (", off scale" if off else "")
            axis.plot(run.trajectory.times, y, color=style.colour, linestyle=style.line_style,
                      linewidth=1.0, label=label)
            if scene.name == TRIP_SCENE:
                for event, time in run.events.items():
                    if math.isfinite(time):
                        k = min(int(np.searchsorted(run.trajectory.times, time)), len(y) - 1)
                        axis.plot([time], [y[k]], EVENT_MARKERS[event], color=style.colour,
                                  markersize=6, markerfacecolor="white")
        if limits is not None:
            axis.set_ylim(*limits)
        axis.set_ylabel(panel, fontsize=8)
        axis.grid(True, alpha=0.3)
    handles, labels = axes[0, 0].get_legend_handles_labels()
    if scene.name == TRIP_SCENE:
        for event, marker in EVENT_MARKERS.items():
            handles.append(axes[0, 0].plot([], [], marker, color="black",
                                           markerfacecolor="white")[0])
            labels.append(event)
    axes[0, 0].legend(handles, labels, fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    axes[0, 0].set_title(f"{scene.name}: every engine against time"
                         + (" (markers: the trip's events)" if scene.name == TRIP_SCENE else ""),
                         fontsize=10)
    axes[-1, 0].set_xlabel("time [ms]")
    return _png(figure)


def recorded_runs(shown: Sequence[ShownRun]) -> list[RecordedRun]:
    """The viewer's runs: each shown run with its title, status, message and events."""
    return [RecordedRun(run.title, run.trajectory, run.figures.status, run.figures.message,
                        run.events if run.figures.scene_name == TRIP_SCENE else {})
            for run in shown]


def reference_events(shown: Sequence[ShownRun]) -> list[Event]:
    """The snapshots' instants: the first shown run's (the reference's when it ran) trip
    events that happened."""
    if not shown or shown[0].figures.scene_name != TRIP_SCENE:
        return []
    first = shown[0]
    return [Event(name, time, first.figures.label) for name, time in first.events.items()
            if math.isfinite(time)]
