"""The report's C-60 section across engines: for ``c60-on`` and ``c60-trip``, one row per
engine, preset and step with its status, functional conditions, latch creep, trip times,
largest penetration and clearance excess per joint, wall time and ratio to the reference; the
engines that could not run it with their reason; the work-precision figure and the step each
engine needs for 1 % on FC-1. Figures come from :mod:`clearbench.harness.c60.cross_engine`
(one implementation for every engine). Units: mm, ms, N; wall times in s.
"""

from __future__ import annotations

import base64
import html
import math
from dataclasses import dataclass, field

from clearbench.adapters import all_availability
from clearbench.harness.c60.cross_engine import (
    ON_SCENE,
    REFERENCE_LABEL,
    TRIP_SCENE,
    C60RunFigures,
    capability_reasons,
    collect,
)
from clearbench.harness.c60.work_precision import (
    FC1_TARGET,
    StepForTarget,
    WorkPrecision,
    steps_for_target,
    work_precision,
)
from clearbench.harness.measure.headline import format_value
from clearbench.harness.report.figures import c60_work_precision_figure

FIGURE_TITLE = "C-60 work-precision"
FIGURE_CAPTION = ("Error of FC-1 (c60-on) and of the opening time (c60-trip) against the "
                  "reference at its finest step, over stepping wall time per run; one colour "
                  "and marker per engine, labels are steps [ms], circles the Pareto front (the "
                  "reference's fine run is the zero of the error, not drawn). Look for the "
                  "points below the dotted 1 % line and how far right they sit.")


@dataclass
class C60Section:
    runs: list                                   # C60RunFigures
    studies: list                                # WorkPrecision
    targets: dict = field(default_factory=dict)  # quantity -> [StepForTarget]
    cannot_run: dict = field(default_factory=dict)   # label -> reason
    figure: bytes | None = None

    @property
    def empty(self) -> bool:
        return not self.runs and not self.cannot_run


def build_section(store, frame, figures: bool = True, colours=None) -> C60Section:
    """The section's content from a store and its DataFrame (``frame``): empty when the
    store holds no run of c60-on or c60-trip. ``colours``: engine name -> declared colour
    (:func:`.engine_style.engine_colours`)."""
    runs = collect(store, frame)
    if not runs:   # no C-60 run in the store: no section
        return C60Section([], [])
    studies = work_precision(runs)
    cannot = {f"{a.engine}": f"not available here: {a.detail}" for a in all_availability()
              if not a.available}
    cannot.update(capability_reasons(frame))
    section = C60Section(runs, studies,
                         {s.quantity: steps_for_target(s) for s in studies if s.points},
                         cannot)
    if figures and studies:
        section.figure = c60_work_precision_figure(studies, colours)
    return section


# ---------------------------------------------------------------------------- cells
def _esc(value) -> str:
    return html.escape(str(value))


def _ms(value: float) -> str:
    return "—" if not math.isfinite(value) else f"{value:.3f}"


def _difference(value: float, reference: float) -> str:
    if not (math.isfinite(value) and math.isfinite(reference) and reference):
        return ""
    return f" ({100 * (value - reference) / abs(reference):+.3g} %)"


def _reference_value(runs, scene_name: str, horizon: float, attribute: str) -> float:
    candidates = [r for r in runs if r.scene_name == scene_name and r.label == REFERENCE_LABEL
                  and r.horizon == horizon and r.status == "ok"]
    if not candidates:
        return math.nan
    return getattr(min(candidates, key=lambda r: r.time_step), attribute)


def _status(run: C60RunFigures) -> str:
    text = run.status
    if run.status != "ok" and math.isfinite(run.simulated_until) \
            and run.simulated_until < run.horizon:
        text += f" at {run.simulated_until:.3g} ms"
    return text


def _latch(run: C60RunFigures) -> str:
    if run.latched is None:
        return "—" if math.isnan(run.latch_creep) else format_value(run.latch_creep)
    return f"{'holds' if run.latched else 'SLIPS'}, {format_value(run.latch_creep)}"


def _joints(run: C60RunFigures) -> tuple[str, str]:
    """(worst joint text, every joint's excess) [mm]."""
    name, worst = run.worst_joint
    if not name:
        return "—", ""
    detail = ", ".join(f"{j} {format_value(v)}" for j, v in run.clearance_excess.items())
    return f"{name} {format_value(worst)}", detail


def _head_cells(run: C60RunFigures) -> list[str]:
    """engine, dt [ms], horizon [ms], status."""
    return [run.label, f"{run.time_step:g}", f"{run.horizon:g}", _status(run)]


def _instrument(run: C60RunFigures) -> str:
    """The independent instrument's largest penetration [mm], and its unseen excess."""
    text = format_value(run.instrument_penetration)
    if run.unseen_penetration > 0:
        text += (f" UNSEEN {format_value(run.unseen_penetration)} more than the kernel's at "
                 f"{run.unseen_time:.4g} ms")
    return text


def _tail_cells(run: C60RunFigures) -> list[str]:
    """Largest penetration, the instrument's, the same beyond the rebuild's overlap, worst
    joint, wall per step [ms] and per run [s], x reference."""
    if run.status == "unsupported":
        return ["—"] * 7
    return [f"{format_value(run.penetration_max)} {run.penetration_pair}".strip(),
            _instrument(run), format_value(run.penetration_beyond_rebuild), _joints(run)[0],
            format_value(1e3 * run.stepping_seconds_per_step), format_value(run.stepping_seconds),
            format_value(run.ratio_to_reference)]


def on_rows(runs) -> list[list[str]]:
    """Cells of the c60-on table (plain text)."""
    rows = []
    for run in (r for r in runs if r.scene_name == ON_SCENE):
        fc1_ref = _reference_value(runs, ON_SCENE, run.horizon, "fc1")
        others = ", ".join(f"{k} {format_value(v)}" for k, v in run.functional_conditions.items()
                           if k != "FC-1")
        rows.append(_head_cells(run) + [format_value(run.fc1) + _difference(run.fc1, fc1_ref),
                                        others or "—", _latch(run)] + _tail_cells(run))
    return rows


def trip_rows(runs) -> list[list[str]]:
    """Cells of the c60-trip table (plain text)."""
    rows = []
    for run in (r for r in runs if r.scene_name == TRIP_SCENE):
        opening_ref = _reference_value(runs, TRIP_SCENE, run.horizon, "opening")
        rows.append(_head_cells(run) + [
            _ms(run.strike), _ms(run.release),
            _ms(run.opening) + _difference(run.opening, opening_ref)] + _tail_cells(run))
    return rows


ON_HEAD = ["engine", "dt [ms]", "horizon [ms]", "status", "FC-1 [N] (vs reference)",
           "FC-2..FC-6 [mm]", "latch (hook creep after 3 ms) [mm]", "largest penetration [mm]",
           "independent instrument [mm]", "beyond the rebuild's overlap [mm]",
           "worst joint: clearance excess [mm]",
           "wall / step [ms]", "wall / run [s]", "x reference"]
TRIP_HEAD = ["engine", "dt [ms]", "horizon [ms]", "status", "strike [ms]", "latch release [ms]",
             "contacts open [ms] (vs reference)", "largest penetration [mm]",
             "independent instrument [mm]", "beyond the rebuild's overlap [mm]",
           "worst joint: clearance excess [mm]",
             "wall / step [ms]", "wall / run [s]", "x reference"]


def target_lines(section: C60Section) -> list[str]:
    lines = []
    for quantity, entries in section.targets.items():
        for entry in entries:
            lines.append(f"{entry.label}, {quantity}: {entry.describe()}")
    return lines


def condense(reason: str) -> str:
    """A capability message ``feature: why; feature: why; ...`` with each distinct reason
    once, after the features that share it."""
    by_reason: dict[str, list[str]] = {}
    for part in str(reason).split("; "):
        feature, sep, why = part.partition(": ")
        if not sep:
            feature, why = "", part
        by_reason.setdefault(why, []).append(feature)
    return "; ".join(f"{', '.join(f for f in features if f)}: {why}".lstrip(": ")
                     for why, features in by_reason.items())


def _problems(runs) -> list[str]:
    out = []
    for run in runs:
        if run.status != "ok" and run.message:
            out.append(f"{run.label} {run.scene_name} dt {run.time_step:g}: {run.status}: "
                       f"{run.message}")
        if run.problem:
            out.append(f"{run.label} {run.scene_name} dt {run.time_step:g}: {run.problem}")
        if run.unseen_reason:
            out.append(f"{run.label} {run.scene_name} dt {run.time_step:g}: "
                       f"{run.unseen_reason}")
    return out


def _horizons(runs) -> str:
    pairs = sorted({(r.scene_name, r.horizon) for r in runs})
    return ", ".join(f"{name} to {horizon:g} ms" for name, horizon in pairs)


INTRO = ("Each engine and preset on the C-60 scenes, measured by the same code "
         "(harness/c60/cross_engine.py). FC-1 is the C7 contact force and FC-2..FC-6 the "
         "measurement pairs, each the mean over the last 1 ms (left out when a run ended "
         "before 3 ms); the latch holds when the hook moves less than the scene's "
         "stays_latched bound (1e-4 of the hook's size) after 3 ms; a joint's clearance excess "
         "is the largest penetration of its rings. 'Beyond the rebuild's overlap' is the "
         "largest penetration less what the engine's rebuilt shapes let the exact ones overlap "
         "while they only touch (the sag of a ring of spheres, of a bore's polygon lining): "
         "the part of the penetration the approximation cannot explain. 'Independent "
         "instrument' is the largest penetration read a second way, by code that shares "
         "nothing with the gap kernel (docs/harness.md); UNSEEN marks a run where it "
         "witnesses more than the kernel's figure (a blind spot of the kernel). Wall times are "
         "stepping alone on a shared machine; 'x reference' is the ratio of wall time per "
         "simulated ms to the reference engine's fine run (its finest step), the run every "
         "error is measured against.")


# ---------------------------------------------------------------------------- HTML
def _table_html(head: list[str], rows: list[list[str]], runs, scene_name: str) -> str:
    """The table with the status's message as its tooltip and each joint's excess folded."""
    mine = [r for r in runs if r.scene_name == scene_name]
    status_column, joint_column = head.index("status"), len(head) - 4
    body = []
    for cells, run in zip(rows, mine, strict=True):
        tds = []
        for index, cell in enumerate(cells):
            if index == status_column:
                tds.append(f"<td title='{_esc(run.message)}'>{_esc(cell)}</td>")
            elif index == joint_column and _joints(run)[1]:
                tds.append(f"<td><details><summary>{_esc(cell)}</summary><span "
                           f"class='small'>{_esc(_joints(run)[1])}</span></details></td>")
            else:
                tds.append(f"<td>{_esc(cell)}</td>")
        body.append(f"<tr>{''.join(tds)}</tr>")
    header = "".join(f"<th>{_esc(h)}</th>" for h in head)
    return f"<table><tr>{header}</tr>{''.join(body)}</table>"


def section_html(section: C60Section) -> str:
    if section.empty:
        return ""
    parts = ["<h2 id='c60-engines'>C-60 across engines</h2>",
             f"<p class='small'>{_esc(INTRO)} Runs: {_esc(_horizons(section.runs))}.</p>"]
    if any(r.scene_name == ON_SCENE for r in section.runs):
        parts += ["<h3>c60-on: settled ON pose</h3>",
                  "<p class='small'>Look for: FC-1 near the reference's, the latch holding, "
                  "penetration and clearance excess far below the 0.006-0.04 mm clearances."
                  "</p>", _table_html(ON_HEAD, on_rows(section.runs), section.runs, ON_SCENE)]
    if any(r.scene_name == TRIP_SCENE for r in section.runs):
        parts += ["<h3>c60-trip: magnetic trip</h3>",
                  "<p class='small'>Look for: the three events in order and near the "
                  "reference's times ('—': did not happen within the run).</p>",
                  _table_html(TRIP_HEAD, trip_rows(section.runs), section.runs, TRIP_SCENE)]
    if section.cannot_run:
        items = "".join(f"<li><b>{_esc(k)}</b>: {_esc(condense(v))}</li>"
                        for k, v in sorted(section.cannot_run.items()))
        parts.append(f"<h3>Engines that cannot run the C-60 here</h3><ul>{items}</ul>")
    if section.targets:
        items = "".join(f"<li>{_esc(line)}</li>" for line in target_lines(section))
        parts.append(f"<h3>Step needed for {100 * FC1_TARGET:g} %</h3><ul>{items}</ul>")
    if section.figure is not None:
        parts.append(f"<figure><img alt='{FIGURE_TITLE}' src='data:image/png;base64,"
                     f"{base64.b64encode(section.figure).decode()}'>"
                     f"<figcaption class='small'>{_esc(FIGURE_CAPTION)}</figcaption></figure>")
    problems = _problems(section.runs)
    if problems:
        items = "".join(f"<li>{_esc(p)}</li>" for p in problems)
        parts.append(f"<details><summary>Run messages ({len(problems)})</summary>"
                     f"<ul class='small'>{items}</ul></details>")
    return "".join(parts)


# ---------------------------------------------------------------------------- Markdown
def _md(text) -> str:
    return str(text).replace("|", "\\|").replace("\n", " ")


def _table_markdown(head: list[str], rows: list[list[str]]) -> list[str]:
    return (["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
            + ["| " + " | ".join(_md(c) for c in row) + " |" for row in rows] + [""])


def section_markdown(section: C60Section, figure_file: str | None = None) -> list[str]:
    if section.empty:
        return []
    lines = ["## C-60 across engines", "", INTRO + f" Runs: {_horizons(section.runs)}.", ""]
    if any(r.scene_name == ON_SCENE for r in section.runs):
        lines += ["### c60-on", ""] + _table_markdown(ON_HEAD, on_rows(section.runs))
    if any(r.scene_name == TRIP_SCENE for r in section.runs):
        lines += ["### c60-trip", ""] + _table_markdown(TRIP_HEAD, trip_rows(section.runs))
    if section.cannot_run:
        lines += ["Engines that cannot run the C-60 here:", ""]
        lines += [f"- {k}: {_md(condense(v))}"
                  for k, v in sorted(section.cannot_run.items())] + [""]
    if section.targets:
        lines += [f"Step needed for {100 * FC1_TARGET:g} %:", ""]
        lines += [f"- {_md(line)}" for line in target_lines(section)] + [""]
    if figure_file:
        lines += [f"![{FIGURE_TITLE}]({figure_file})", "", f"*{FIGURE_CAPTION}*", ""]
    return lines


__all__ = ["C60Section", "StepForTarget", "WorkPrecision", "build_section", "section_html",
           "section_markdown"]
