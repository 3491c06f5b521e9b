"""The report's C-60 section across engines: the labelled schematic, the viewer (c60-trip's
runs side by side), every engine's hook angle, bar angle, C7 gap and FC-1 against time; for
``c60-on`` and ``c60-trip``, one row per engine, preset and step with its status, functional
conditions, latch creep, each trip event against the reference's, largest penetration and
clearance excess per joint, wall time and ratio to the reference; the engines that could not
run it with their reason; the work-precision figure and the error-budget table. Figures come
from :mod:`clearbench.harness.c60.cross_engine` (one implementation for every engine).
Units: mm, ms, N; wall times in s.
"""

from __future__ import annotations

import logging
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
    BUDGETS,
    BudgetStep,
    WorkPrecision,
    error_budget,
    work_precision,
)
from clearbench.harness.measure.headline import format_value
from clearbench.harness.report import c60_motion
from clearbench.harness.report.figures import c60_work_precision_figure
from clearbench.harness.report.html_parts import esc as _esc
from clearbench.harness.report.html_parts import heading, length_text, png_figure, table
from clearbench.harness.report.schematic import schematic_figure
from clearbench.harness.report.viewer.payload import viewer_fragment, viewer_payload

LOG = logging.getLogger(__name__)

FIGURE_TITLE = "C-60 work-precision"
FIGURE_CAPTION = ("Error of FC-1 (c60-on) and of the opening time (c60-trip) against the "
                  "reference at its finest step, over stepping wall time per run; one colour "
                  "and marker per engine, labels are steps [ms], circles the Pareto front of "
                  "the runs that finished (the reference's fine run is the zero of the error, "
                  "not drawn). Look for the points below the dotted 1 % line and how far right "
                  "they sit.")
#: A trip event more than this far (relative, of the reference's time from t = 0) from the
#: reference's is flagged: the events are 0.7-3.7 ms apart and recorded every 0.01 ms, so 5 %
#: of 3-8 ms (0.15-0.4 ms, 15-40 samples) is far beyond the sampling and still well inside
#: the gaps between events.
EVENT_BOUND = 0.05
#: The flag beside an event beyond EVENT_BOUND.
FLAG = "\u2691"


@dataclass
class C60Section:
    runs: list                                   # C60RunFigures
    studies: list                                # WorkPrecision
    budgets: list = field(default_factory=list)  # BudgetStep, every quantity and budget
    cannot_run: dict = field(default_factory=dict)   # label -> reason
    figure: bytes | None = None                  # work-precision
    schematic: bytes | None = None               # the labelled schematic (PNG)
    series: dict = field(default_factory=dict)   # scene name -> time-series PNG
    viewer: dict | None = None                   # the viewer's payload (c60-trip's runs)

    @property
    def empty(self) -> bool:
        return not self.runs and not self.cannot_run


def build_section(store, frame, figures: bool = True, colours=None) -> C60Section:
    """The section's content from a store and its DataFrame (``frame``): empty when the
    store holds no run of c60-on or c60-trip. ``colours``: engine name -> declared colour
    (:func:`.engine_style.engine_colours`). With ``figures``: the work-precision figure, the
    labelled schematic, each scene's time series and the viewer of c60-trip (else c60-on)."""
    runs = collect(store, frame)
    if not runs:   # no C-60 run in the store: no section
        return C60Section([], [])
    studies = work_precision(runs)
    cannot = {f"{a.engine}": f"not available here: {a.detail}" for a in all_availability()
              if not a.available}
    cannot.update(capability_reasons(frame))
    budgets = [step for study in studies if study.points or study.reference_value
               for budget in BUDGETS for step in error_budget(runs, study, budget)]
    section = C60Section(runs, studies, budgets, cannot)
    if figures:
        _draw(section, store, colours)
    return section


def _draw(section: C60Section, store, colours) -> None:
    """The section's figures and viewer (a figure that fails is left out, with a warning:
    a figure must never stop the report)."""
    if section.studies:
        section.figure = c60_work_precision_figure(section.studies, colours)
    for scene_name in (TRIP_SCENE, ON_SCENE):
        shown = c60_motion.shown_runs(store, section.runs, scene_name)
        if not shown:
            continue
        scene = store.scene(store.get(shown[0].figures.key)["scene_hash"])
        try:
            image = c60_motion.time_series_figure(scene, shown, colours)
            if image is not None:
                section.series[scene_name] = image
            if section.schematic is None:
                section.schematic = schematic_figure(scene)
            if section.viewer is None:
                section.viewer = viewer_payload(scene, c60_motion.recorded_runs(shown),
                                                c60_motion.reference_events(shown))
        except Exception as error:  # noqa: BLE001 - reported, the report goes on
            LOG.warning("C-60 motion figures of %s not drawn: %s", scene_name, error)


# ---------------------------------------------------------------------------- cells
def _ms(value: float) -> str:
    return "—" if not math.isfinite(value) else f"{value:.3f}"


def relative(value: float, reference: float) -> float:
    """(value - reference) / |reference|; NaN when either is missing."""
    if not (math.isfinite(value) and math.isfinite(reference) and reference):
        return math.nan
    return (value - reference) / abs(reference)


def _difference(value: float, reference: float) -> str:
    change = relative(value, reference)
    return "" if math.isnan(change) else f" ({100 * change:+.3g} %)"


def reference_run(runs, scene_name: str, horizon: float) -> C60RunFigures | None:
    """The reference's finest finished run of the scene at ``horizon`` (the yardstick)."""
    candidates = [r for r in runs if r.scene_name == scene_name and r.label == REFERENCE_LABEL
                  and r.horizon == horizon and r.status == "ok"]
    return min(candidates, key=lambda r: r.time_step) if candidates else None


@dataclass(frozen=True)
class EventComparison:
    """One trip event of a run against the reference's: times [ms], relative difference of
    the times from t = 0 (NaN when either is missing), and whether it is beyond
    :data:`EVENT_BOUND` (an event the run has and the reference not, or the other way round,
    is flagged too)."""

    event: str
    time: float
    reference: float
    change: float
    flagged: bool

    def text(self) -> str:
        if not math.isfinite(self.time):
            return "none" + (f" {FLAG}" if self.flagged else "")
        change = "" if math.isnan(self.change) else f" ({100 * self.change:+.3g} %)"
        return f"{self.time:.3f}{change}" + (f" {FLAG}" if self.flagged else "")


def compare_events(run: C60RunFigures, reference: C60RunFigures | None
                   ) -> list[EventComparison]:
    """Each trip event (strike, release, opening) of ``run`` against the reference's (not
    compared when ``run`` is the reference's run itself)."""
    if reference is not None and reference.key == run.key:
        reference = None
    out = []
    for event in c60_motion.EVENTS:
        time = getattr(run, event)
        ref = getattr(reference, event) if reference is not None else math.nan
        change = relative(time, ref)
        missing_one = reference is not None and math.isfinite(ref) != math.isfinite(time)
        flagged = (not math.isnan(change) and abs(change) > EVENT_BOUND) or (
            missing_one and run.status == "ok")
        out.append(EventComparison(event, time, ref, change, flagged))
    return out


def _status(run: C60RunFigures) -> str:
    text = run.status
    if run.status != "ok" and math.isfinite(run.simulated_until) \
            and run.simulated_until < run.horizon:
        text += f" at {run.simulated_until:.3g} ms"
    return text


def latch_text(run: C60RunFigures) -> str:
    """``holds, creep 0.0012 µm`` / ``SLIPS, creep 1.64 mm``: the latch's state and the hook's
    creep."""
    if run.latched is None:
        return "—" if math.isnan(run.latch_creep) else length(run.latch_creep)
    return f"{'holds' if run.latched else 'SLIPS'}, creep {length(run.latch_creep)}"


def length(value: float, unit: str = "mm") -> str:
    """A C-60 length (given in mm), as :func:`.html_parts.length_text` writes it."""
    return length_text(value, unit)


def _joints(run: C60RunFigures) -> tuple[str, str]:
    """(worst joint text, every joint's excess)."""
    name, worst = run.worst_joint
    if not name:
        return "—", ""
    detail = ", ".join(f"{j} {length(v)}" for j, v in run.clearance_excess.items())
    return f"{name} {length(worst)}", detail


def _head_cells(run: C60RunFigures) -> list[str]:
    """engine, dt [ms], horizon [ms], status."""
    return [run.label, f"{run.time_step:g}", f"{run.horizon:g}", _status(run)]


def _instrument(run: C60RunFigures) -> str:
    """The independent instrument's largest penetration, and its unseen excess."""
    text = length(run.instrument_penetration)
    if run.unseen_penetration > 0:
        text += (f" UNSEEN {length(run.unseen_penetration)} more than the kernel's at "
                 f"{run.unseen_time:.4g} ms")
    return text


def _tail_cells(run: C60RunFigures) -> list[str]:
    """Largest penetration, the instrument's, the same beyond the rebuild's overlap, worst
    joint, wall per step [ms] and per run [s], x reference."""
    if run.status == "unsupported":
        return ["—"] * 7
    return [f"{length(run.penetration_max)} {run.penetration_pair}".strip(),
            _instrument(run), length(run.penetration_beyond_rebuild), _joints(run)[0],
            format_value(1e3 * run.stepping_seconds_per_step), format_value(run.stepping_seconds),
            format_value(run.ratio_to_reference)]


def table_runs(runs, scene_name: str) -> list[C60RunFigures]:
    """The runs of one scene in the order of its table: the reference first, then by engine
    label and step."""
    return sorted((r for r in runs if r.scene_name == scene_name),
                  key=lambda r: (r.label != REFERENCE_LABEL, r.label, r.time_step))


def on_rows(runs) -> list[list[str]]:
    """Cells of the c60-on table (plain text)."""
    rows = []
    for run in table_runs(runs, ON_SCENE):
        reference = reference_run(runs, ON_SCENE, run.horizon)
        fc1_ref = reference.fc1 if reference is not None and reference.key != run.key \
            else math.nan
        others = ", ".join(f"{k} {format_value(v)}" for k, v in run.functional_conditions.items()
                           if k != "FC-1")
        rows.append(_head_cells(run) + [format_value(run.fc1) + _difference(run.fc1, fc1_ref),
                                        others or "—", latch_text(run)] + _tail_cells(run))
    return rows


def trip_rows(runs) -> list[list[str]]:
    """Cells of the c60-trip table (plain text): each event against the reference's."""
    rows = []
    for run in table_runs(runs, TRIP_SCENE):
        reference = reference_run(runs, TRIP_SCENE, run.horizon)
        events = [c.text() for c in compare_events(run, reference)]
        rows.append(_head_cells(run) + events + _tail_cells(run))
    return rows


ON_HEAD = ["engine", "dt [ms]", "horizon [ms]", "status", "FC-1 [N] (vs reference)",
           "FC-2..FC-6 [mm]", "latch (hook creep after 3 ms)", "largest penetration",
           "independent instrument", "beyond the rebuild's overlap",
           "worst joint: clearance excess", "wall / step [ms]", "wall / run [s]", "x reference"]
TRIP_HEAD = ["engine", "dt [ms]", "horizon [ms]", "status", "strike [ms] (vs reference)",
             "latch release [ms] (vs reference)", "contacts open [ms] (vs reference)",
             "largest penetration", "independent instrument", "beyond the rebuild's overlap",
             "worst joint: clearance excess", "wall / step [ms]", "wall / run [s]",
             "x reference"]


def run_summary(section: C60Section, run: C60RunFigures) -> str:
    """What a finished C-60 run comes to, against the reference's finest run (none for that
    run itself): c60-on's FC-1 and the latch, c60-trip's events."""
    reference = reference_run(section.runs, run.scene_name, run.horizon)
    if reference is not None and reference.key == run.key:
        reference = None     # the yardstick itself: nothing to compare with
    if run.scene_name == ON_SCENE:
        change = relative(run.fc1, reference.fc1) if reference else math.nan
        versus = "" if math.isnan(change) else f" ({100 * change:+.2g} %)"
        return f"FC-1 {format_value(run.fc1, 'N')}{versus}, latch {latch_text(run)}"
    return ", ".join(f"{c.event} {c.text()}" for c in compare_events(run, reference))


def c60_cell_texts(section: C60Section) -> dict[str, str]:
    """Run key -> what the overview's cell shows for a finished C-60 run
    (:func:`run_summary`)."""
    return {run.key: run_summary(section, run) for run in section.runs if run.status == "ok"}


def _budget_cell(step: BudgetStep | None) -> str:
    if step is None:
        return "not run"
    if step.time_step is None:
        return f"not met: {step.reason}"
    return (f"dt {step.time_step:g} ms: {100 * step.error:.2g} %, "
            f"{format_value(step.wall_seconds)} s per run")


def budget_table(section: C60Section) -> tuple[list[str], list[list[str]]]:
    """(head, rows) of the error-budget table: one row per engine label, one column per
    quantity and budget."""
    columns = [(study.quantity, budget) for study in section.studies for budget in BUDGETS]
    labels = sorted({s.label for s in section.budgets}, key=lambda x: (x != REFERENCE_LABEL, x))
    by_key = {(s.label, s.quantity, s.budget): s for s in section.budgets}
    head = ["engine"] + [f"{q} within {100 * b:g} %" for q, b in columns]
    rows = [[label] + [_budget_cell(by_key.get((label, q, b))) for q, b in columns]
            for label in labels]
    return head, rows


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
TRIP_NOTE = ("Each event's time against the reference's finest run, relative to the "
             "reference's time from t = 0; " + FLAG + f" beyond {100 * EVENT_BOUND:g} % (or an "
             "event one run has and the other not); 'none': did not happen within the run. "
             "Strike: the plunger first pushes the tripping bar; release: the latch contacts "
             "C4 and C5 first carry no force; opening: C7's gap first exceeds 0.1 mm.")
BUDGET_NOTE = ("For each error budget, the cheapest step of the engine's ladder whose error "
               "and the error of every finer step of the ladder stay within it (a finer step "
               "that diverged or drifts beyond it disqualifies the coarser ones), with that "
               "step's error and the run's stepping wall time. The reference's finest step is "
               "the yardstick (error 0).")
MOTION_CAPTION = ("Each engine's finest run of c60-trip played side by side: drag to turn "
                  "the view (every view follows), the slider or play to move in time, the "
                  "event buttons for the pose at the reference's strike, release and opening. "
                  "Bodies are drawn from the scene's contact primitives (rings, faces, "
                  "cylinders: the C-60's CAD surfaces, not its whole parts); black dots are "
                  "contacts that carry force and red lines their forces on the second body of "
                  "each pair, to one scale in every view.")
SCHEMATIC_CAPTION = ("The C-60 in its ON pose seen along z: each part in its colour (the "
                     "viewer's), the revolute joints J1..J7 (and the needle's bearing S3) at "
                     "their rings, the contacts C1..C7 at their contact points.")
SERIES_CAPTION = ("Every engine's finest run against time: the hook's and the tripping bar's "
                  "rotation about z since t = 0, C7's gap (moving on fixed contact; c60-trip) "
                  "and FC-1, C7's normal force. Markers: strike (triangle), release (circle), "
                  "opening (square). The y range holds the runs that finished; a run that "
                  "diverged leaves it ('off scale' in the legend).")


# ---------------------------------------------------------------------------- HTML
def _table_html(head: list[str], rows: list[list[str]], runs, scene_name: str,
                caption: str) -> str:
    """The table with the status's message as its tooltip and each joint's excess folded."""
    mine = table_runs(runs, scene_name)
    status_column, joint_column = head.index("status"), len(head) - 4
    body = []
    for cells, run in zip(rows, mine, strict=True):
        tds = []
        for index, cell in enumerate(cells):
            if index == status_column:
                tds.append(f"<span title='{_esc(run.message)}'>{_esc(cell)}</span>")
            elif index == joint_column and _joints(run)[1]:
                tds.append(f"<details><summary>{_esc(cell)}</summary><span "
                           f"class='small'>{_esc(_joints(run)[1])}</span></details>")
            else:
                tds.append(_esc(cell))
        body.append(tds)
    numeric = (1, 2, len(head) - 3, len(head) - 2, len(head) - 1)
    return table(head, body, caption, raw=True, css_class="wide", numeric=numeric)


def motion_html(section: C60Section) -> str:
    """The schematic, the viewer and the time series (the C-60 seen moving)."""
    parts = []
    if section.schematic is not None:
        parts.append(png_figure(section.schematic, SCHEMATIC_CAPTION,
                                "C-60 schematic: parts, joints J1..J7, contacts C1..C7"))
    if section.viewer is not None:
        parts.append(viewer_fragment(section.viewer, "c60-viewer", MOTION_CAPTION))
    for scene_name, png in section.series.items():
        parts.append(png_figure(png, f"{scene_name}: {SERIES_CAPTION}"))
    if not parts:
        return ""
    return heading(3, "The C-60 seen moving", "c60-motion") + "".join(parts)


def section_html(section: C60Section) -> str:
    if section.empty:
        return ""
    parts = [heading(2, "C-60 across engines", "c60-engines"),
             f"<p class='small'>{_esc(INTRO)} Runs: {_esc(_horizons(section.runs))}.</p>",
             motion_html(section)]
    if any(r.scene_name == ON_SCENE for r in section.runs):
        parts += [heading(3, "c60-on: settled ON pose", "c60-on-table"),
                  "<p class='small'>Look for: FC-1 near the reference's, the latch holding, "
                  "penetration and clearance excess far below the 6-40 µm clearances.</p>",
                  _table_html(ON_HEAD, on_rows(section.runs), section.runs, ON_SCENE,
                              "c60-on: one row per engine, preset and step")]
    if any(r.scene_name == TRIP_SCENE for r in section.runs):
        parts += [heading(3, "c60-trip: magnetic trip", "c60-trip-table"),
                  f"<p class='small'>{_esc(TRIP_NOTE)}</p>",
                  _table_html(TRIP_HEAD, trip_rows(section.runs), section.runs, TRIP_SCENE,
                              "c60-trip: each event against the reference's")]
    if section.budgets:
        head, rows = budget_table(section)
        parts += [heading(3, "Error budget: the step each engine needs", "c60-error-budget"),
                  f"<p class='small'>{_esc(BUDGET_NOTE)}</p>",
                  table(head, rows, "The cheapest step within 1 % and 5 %, per engine")]
    if section.figure is not None:
        parts.append(png_figure(section.figure, FIGURE_CAPTION, FIGURE_TITLE))
    if section.cannot_run:
        items = "".join(f"<li><b>{_esc(k)}</b>: {_esc(condense(v))}</li>"
                        for k, v in sorted(section.cannot_run.items()))
        parts += [heading(3, "Engines that cannot run the C-60 here", "c60-cannot-run"),
                  f"<ul class='small'>{items}</ul>"]
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
        lines += ["### c60-trip", "", TRIP_NOTE, ""] + _table_markdown(
            TRIP_HEAD, trip_rows(section.runs))
    if section.budgets:
        head, rows = budget_table(section)
        lines += ["### Error budget", "", BUDGET_NOTE, ""] + _table_markdown(head, rows)
    if section.cannot_run:
        lines += ["Engines that cannot run the C-60 here:", ""]
        lines += [f"- {k}: {_md(condense(v))}"
                  for k, v in sorted(section.cannot_run.items())] + [""]
    if figure_file:
        lines += [f"![{FIGURE_TITLE}]({figure_file})", "", f"*{FIGURE_CAPTION}*", ""]
    return lines


__all__ = ["C60Section", "BudgetStep", "WorkPrecision", "build_section", "section_html",
           "section_markdown"]
