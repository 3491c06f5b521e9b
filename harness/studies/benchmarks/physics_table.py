"""Error of an engine against the physics expectations of the analytic scenes, as Markdown
tables (``clearbench bench physics-table --engine NAME[PRESET]``; ``mujoco-table`` is its MuJoCo
case).

Every figure comes from :func:`clearbench.harness.measure.expectation_figures.evaluate`, the
evaluator every engine is judged by, so the columns of every engine and of the reference solver
are computed by the same code. This module only chooses which figures to show and in which
display unit: the columns of each expectation kind (its ``table``,
:class:`~clearbench.harness.measure.kinds.TableColumn`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from clearbench.adapters.base import Engine, RunSettings
from clearbench.adapters.trajectory import RunStatus
from clearbench.harness.measure.expectation_figures import evaluate
from clearbench.harness.measure.kinds import measured_kind
from clearbench.scenarios.library import get_scene, scene_names
from clearbench.scenarios.scene import Scene

#: Scenes of the tables: the analytic library plus the clearance pendulum.
DEFAULT_SCENES = tuple(scene_names("analytic")) + ("clearance-pendulum",)


@dataclass(frozen=True)
class Cell:
    """One run: status, message, the figures of each expectation, and stepping wall time."""

    status: RunStatus
    message: str
    figures: dict
    stepping_seconds: float
    steps: int


def run_cell(engine: Engine, scene: Scene, time_step: float,
             horizon: float | None = None, options: dict | None = None) -> Cell:
    """Run ``scene`` at ``time_step`` (with the engine ``options`` over its preset) and
    evaluate its expectations.

    Samples are kept every ``scene.time_step`` (or every step when finer), so that the
    evaluator costs the same at every time step.
    """
    record_every = max(1, round(scene.time_step / time_step))
    trajectory = engine.run(scene, RunSettings(time_step=time_step, horizon=horizon,
                                               record_every=record_every,
                                               options=dict(options or {})))
    figures = {}
    if len(trajectory.times) >= 2:
        for result in evaluate(scene, trajectory):
            figures[result.name] = (result.kind, dict(result.figures))
    return Cell(trajectory.status, trajectory.message, figures, trajectory.stepping_seconds,
                trajectory.steps)


def table_rows(scene: Scene, cells: list[Cell]) -> list[tuple[str, list[str]]]:
    """(label, one formatted value per cell) for every shown figure of ``scene``."""
    rows = []
    for expectation in scene.expectations:
        for figure in measured_kind(expectation.kind).table:
            if not figure.shown(expectation.parameters):
                continue
            values = []
            for cell in cells:
                kind_figures = cell.figures.get(expectation.name)
                value = math.nan if kind_figures is None else \
                    kind_figures[1].get(figure.key, math.nan)
                values.append(format_value(value * figure.factor, cell))
            unit = f" [{figure.unit}]" if figure.unit else ""
            rows.append((f"{figure.label}{unit}", values))
    return rows


def format_value(value: float, cell: Cell) -> str:
    """Three significant digits; the status when the run did not end OK."""
    text = "n/a" if not math.isfinite(value) else f"{value + 0.0:.3g}"  # no "-0"
    if cell.status is RunStatus.OK:
        return text
    return f"{text} ({cell.status.value})"


def measure(engines: dict[str, Engine], time_steps: tuple[float, ...],
            scenes: tuple[str, ...] = DEFAULT_SCENES, horizon: float | None = None,
            progress=None, options: dict | None = None) -> list[dict]:
    """Run every (scene, engine, time step), with the engine ``options`` over each preset; per
    scene a dict with its name, column labels, rows and the cells. ``progress(text)`` is called
    before each run."""
    out = []
    for name in scenes:
        scene = get_scene(name)
        labels, cells = [], []
        for label, engine in engines.items():
            for time_step in time_steps:
                if progress:
                    progress(f"{name} {label} dt={time_step:g}")
                cells.append(run_cell(engine, scene, time_step, horizon, options))
                labels.append(f"{label} dt={time_step:g}")
        out.append({"scene": name, "labels": labels, "rows": table_rows(scene, cells),
                    "cells": cells})
    return out


def markdown(measured: list[dict]) -> str:
    """The measurements as Markdown tables, one per scene."""
    lines = []
    for block in measured:
        lines.append(f"**{block['scene']}**")
        lines.append("")
        lines.append("| figure | " + " | ".join(block["labels"]) + " |")
        lines.append("|---|" + "---:|" * len(block["labels"]))
        for label, values in block["rows"]:
            lines.append(f"| {label} | " + " | ".join(values) + " |")
        seconds = [f"{c.stepping_seconds / max(c.steps, 1) * 1e6:.3g}" for c in block["cells"]]
        lines.append("| stepping time per step [us] | " + " | ".join(seconds) + " |")
        notes = [f"{label}: {cell.message}" for label, cell in zip(block["labels"],
                                                                   block["cells"], strict=True)
                 if cell.message]
        lines.append("")
        for note in notes:
            lines.append(f"- {note}")
        if notes:
            lines.append("")
    return "\n".join(lines)


def markdown_compact(measured: list[dict]) -> str:
    """The measurements as one Markdown table: a row per (scene, figure), a column per
    (engine, time step); runs that did not end OK carry their status."""
    if not measured:
        return ""
    labels = measured[0]["labels"]
    lines = ["| scene | figure | " + " | ".join(labels) + " |",
             "|---|---|" + "---:|" * len(labels)]
    for block in measured:
        for label, values in block["rows"]:
            lines.append(f"| {block['scene']} | {label} | " + " | ".join(values) + " |")
    return "\n".join(lines)
