"""Cost per step of an engine as simultaneous contacts grow (``clearbench bench contact-cost``).

The scene is the library's ``box_grid(count)``: ``count`` boxes dropped 1 mm onto a plane, four
corner contacts each, run for a short horizon (the drop and the settling). Per run: wall time of
stepping per nominal step, the engine's solver iterations per nominal step (Newton iterations
in Exudyn, sweeps in the reference solver, as the engine records them), and, where the engine
reports them, its own steps (Exudyn's reduced steps included).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from clearbench.adapters.base import Engine, RunSettings
from clearbench.scenarios.library.basic import box_grid

#: Box counts of the default table.
DEFAULT_BOXES = (1, 4, 9, 16, 26)
#: Default simulated duration [s]: the 1 mm drop takes 14 ms, the rest is settling.
DEFAULT_HORIZON = 0.05


@dataclass(frozen=True)
class ContactCost:
    """One run of ``box_grid(boxes)``: status, wall time [us] and iterations per nominal step,
    and the engine's own step count (None when it does not report one)."""

    engine: str
    boxes: int
    time_step: float
    status: str
    message: str
    microseconds_per_step: float
    iterations_per_step: float
    engine_steps: int | None
    nominal_steps: int

    @property
    def contacts(self) -> int:
        """Corner contacts when every box rests flat."""
        return 4 * self.boxes


def contact_costs(engines: dict[str, Engine], boxes=DEFAULT_BOXES, time_steps=(1e-3, 1e-4),
                  horizon: float = DEFAULT_HORIZON, progress=None,
                  options: dict | None = None) -> list[ContactCost]:
    """Run every (engine label, box count, time step [s]), with the engine ``options`` over
    each preset; ``progress(text)`` before each."""
    rows = []
    for label, engine in engines.items():
        for count in boxes:
            scene = box_grid(count=count)
            for time_step in time_steps:
                if progress:
                    progress(f"box_grid({count}) {label} dt={time_step:g}")
                trajectory = engine.run(scene, RunSettings(time_step=time_step, horizon=horizon,
                                                           options=dict(options or {})))
                steps = max(trajectory.steps, 1)
                iterations = trajectory.iterations_per_step if trajectory.steps else math.nan
                engine_steps = trajectory.metadata.get("solver_steps")
                rows.append(ContactCost(label, count, time_step, trajectory.status.value,
                                        trajectory.message,
                                        trajectory.stepping_seconds / steps * 1e6, iterations,
                                        None if engine_steps is None else int(engine_steps),
                                        trajectory.steps))
    return rows


def markdown(rows: list[ContactCost]) -> str:
    """One Markdown table: a row per (engine, box count), a column per time step."""
    steps = sorted({r.time_step for r in rows}, reverse=True)
    lines = ["| engine | boxes (contacts) | " + " | ".join(f"dt {dt:g} s" for dt in steps) + " |",
             "|---|---|" + "---|" * len(steps)]
    keys = list(dict.fromkeys((r.engine, r.boxes) for r in rows))
    for engine, count in keys:
        cells = []
        for dt in steps:
            found = [r for r in rows if (r.engine, r.boxes, r.time_step) == (engine, count, dt)]
            cells.append(_cell(found[0]) if found else "")
        lines.append(f"| {engine} | {count} ({4 * count}) | " + " | ".join(cells) + " |")
    notes = [f"- {r.engine} {r.boxes} boxes dt {r.time_step:g}: {r.message}" for r in rows
             if r.message]
    return "\n".join(lines + ([""] + notes if notes else []))


def _cell(row: ContactCost) -> str:
    text = f"{row.microseconds_per_step:.0f} us, {row.iterations_per_step:.1f} it"
    if row.engine_steps is not None:
        text += f", {row.engine_steps} engine steps / {row.nominal_steps}"
    return text if row.status == "ok" else f"{text} ({row.status})"
