"""The comparison report: a self-contained HTML page and a Markdown summary from a results store.

Contents, in the order a mechanism engineer reads them: a table of contents; the conclusions
(:mod:`.conclusions`: one line per engine and preset, and the C-60 model's standing against the
paper); the overview matrix (:mod:`.overview`: scene x engine, each preset a line in its
engine's cell) and the stiff and extreme suite in the same form; the C-60 across engines
(:mod:`.c60_section`: the labelled schematic, the viewer playing c60-trip in every engine, the
time series, the c60-on and c60-trip tables, the error budget, work-precision) and, when
``clearbench c60 validate`` has written its JSON, the C-60 against the paper; then the detail:
per scene a table of every run with its metrics and its figures (work-precision with its Pareto
front, drift and creep over time) folded two per row; the tolerance campaigns
(:mod:`.campaign_sections`) as tables; per engine the features it approximates or does not
support; a glossary of every abbreviation the page uses. Figures are embedded as base64 PNG in
the HTML and written as PNG files beside the Markdown; three.js is inlined for the viewer.
"""

from __future__ import annotations

import html
import json
import logging
import math
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path

import numpy as np

from clearbench.harness.measure.headline import (
    METRIC_LABELS,
    format_value,
    scene_metric_names,
)
from clearbench.harness.measure.units import unit_text
from clearbench.harness.measure.verdicts import VERDICTS, verdict_text
from clearbench.harness.report.c60_section import (
    EVENT_BOUND,
    FLAG,
    C60Section,
    build_section,
    c60_cell_texts,
)
from clearbench.harness.report.c60_section import section_html as c60_engines_html
from clearbench.harness.report.c60_section import section_markdown as c60_engines_markdown
from clearbench.harness.report.campaign_sections import campaign_html
from clearbench.harness.report.conclusions import HEAD, conclusions, standing
from clearbench.harness.report.engine_style import engine_colours
from clearbench.harness.report.figures import time_series_figure, work_precision_figure
from clearbench.harness.report.glossary import glossary_html
from clearbench.harness.report.html_parts import figure_grid, heading, table
from clearbench.harness.report.overview import (
    NOT_RUN,
    cell_lines,
    engine_columns,
    matrix_html,
    matrix_markdown,
    row_verdict,
)
from clearbench.harness.report.readme_table import results_document, write_results
from clearbench.harness.report.viewer.payload import CSS as VIEWER_CSS
from clearbench.harness.report.viewer.payload import viewer_scripts
from clearbench.harness.run.store import ResultsStore
from clearbench.harness.studies.campaign.report import load_written_sections
from clearbench.harness.studies.campaign.report import render_markdown as campaign_section_markdown
from clearbench.harness.studies.sweep import work_precision_points
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.tags import STIFF

LOG = logging.getLogger(__name__)

FINE_SUFFIX = ":fine-reference"


@dataclass
class SceneSection:
    """What the report says about one scene."""

    name: str
    scene: Scene | None
    runs: object                         # DataFrame of every run of the scene
    representative: dict                 # engine label -> row (dict) at the scene's step
    figures: dict = field(default_factory=dict)   # title -> PNG bytes
    notes: list = field(default_factory=list)


@dataclass
class ReportData:
    frame: object
    sections: list
    engines: list
    approximations: dict                 # label -> {feature: (support, detail)}
    store: str
    generated: str
    c60_validation: dict | None = None   # clearbench c60 validate's JSON (see load_c60_validation)
    #: tolerance campaigns written by ``clearbench campaign report`` (summary, figures)
    campaigns: list = field(default_factory=list)
    #: the C-60 across engines (c60-on and c60-trip runs of the store)
    c60_engines: C60Section | None = None


def _representative(rows, scene: Scene | None) -> dict:
    """Per engine label, the run at the scene's comfortable step (else the closest step)."""
    chosen = {}
    regular = rows[~rows["campaign"].fillna("").str.endswith(FINE_SUFFIX)]
    if not len(regular):
        regular = rows
    for label, group in regular.groupby("label", sort=True):
        target = scene.time_step if scene is not None else group["time_step"].max()
        distance = np.abs(np.log(group["time_step"].astype(float) / target))
        chosen[label] = group.loc[distance.idxmin()].to_dict()
    return chosen


def collect(store: ResultsStore, figures: bool = True,
            colours: Mapping[str, str] | None = None) -> ReportData:
    """Gather the report's content from ``store`` (figures computed when ``figures``, each
    engine in its colour: ``colours``, engine name -> declared colour, default the
    registry's: :func:`.engine_style.engine_colours`)."""
    frame = store.dataframe()
    sections = []
    approximations: dict[str, dict] = {}
    for _, row in frame.iterrows():
        support = json.loads(row["capabilities"] or "{}")
        for feature, (kind, detail) in support.items():
            if kind != "native":
                approximations.setdefault(row["label"], {})[feature] = (kind, detail)
    for name in dict.fromkeys(frame["scene_name"]):
        rows = frame[frame["scene_name"] == name]
        latest_hash = rows.iloc[-1]["scene_hash"]
        scene = store.scene(latest_hash)
        section = SceneSection(name, scene, rows, _representative(rows, scene))
        if rows["scene_hash"].nunique() > 1:
            section.notes.append(f"{rows['scene_hash'].nunique()} scene variants share this "
                                 "name (different parameters); they are listed together.")
        if figures:
            _figures(store, section, colours)
        sections.append(section)
    sections.sort(key=lambda s: (s.scene is not None and STIFF in s.scene.tags, s.name))
    return ReportData(frame, sections, sorted(frame["label"].unique()) if len(frame) else [],
                      approximations, str(store.directory),
                      datetime.now(UTC).isoformat(timespec="seconds"),
                      c60_engines=(build_section(store, frame, figures, colours)
                                   if len(frame) else None))


def _figures(store: ResultsStore, section: SceneSection,
             colours: Mapping[str, str] | None) -> None:
    points = work_precision_points(section.runs, section.name)
    if np.count_nonzero(points["error"] > 0) >= 2:
        section.figures["Work–precision"] = work_precision_figure(
            points, f"{section.name}: error against stepping time", colours)
    if section.scene is None:
        section.notes.append("scene not in the store: no time-series figure")
        return
    trajectories = {}
    for label, row in section.representative.items():
        if row["status"] in ("ok", "diverged") and row["trajectory"]:
            trajectory = store.load_trajectory(row["key"])
            if trajectory is not None and trajectory.scene_hash == section.scene.content_hash:
                trajectories[f"{label} dt={row['time_step']:.3g}"] = trajectory
    if not trajectories:
        return
    try:
        image = time_series_figure(section.scene, trajectories, colours)
    except Exception as error:  # a figure must never stop the report
        LOG.warning("no time-series figure for %s: %s", section.name, error)
        section.notes.append(f"drift figure not drawn: {type(error).__name__}: {error}")
        return
    if image is not None:
        section.figures["Drift and creep over time"] = image


# ---------------------------------------------------------------------------- content helpers
def _run_title(row) -> str:
    """The run's message and its failed expectations (a verdict cell's title)."""
    failed = [r["name"] for r in json.loads(row.get("expectations") or "[]")
              if r.get("passed") is False]
    unseen = (row.get("verdict_reason") or "") if row.get("status") == "ok" else ""
    return "; ".join(filter(None, [row.get("message") or "", unseen,
                                   f"failed: {', '.join(failed)}" if failed else ""]))


def _column_head(name: str, scene: Scene | None) -> str:
    """A metric column's header: its label and its unit (``penetration [mm]``)."""
    unit = unit_text(name, scene, short=True)
    label = METRIC_LABELS.get(name, (name,))[0]
    return f"{label} [{unit}]" if unit else label


def _metric_columns(section: SceneSection) -> list[str]:
    present = set()
    for text in section.runs["metrics"]:
        present.update(json.loads(text or "{}"))
    names = scene_metric_names(section.scene) if section.scene is not None else sorted(present)
    return [n for n in names if n in present]


def _engine_notes(data: ReportData) -> list[tuple[str, str, str, str]]:
    """(engines, feature, support, how): each approximation once per engine and feature, the
    presets that state it in the same words listed together (``mujoco[default, tuned]``)."""
    grouped: dict[tuple[str, str, str, str], list[str]] = {}
    for label in data.engines:
        name, _, preset = label.partition("[")
        for feature, (kind, detail) in sorted(data.approximations.get(label, {}).items()):
            grouped.setdefault((name, feature, kind, detail), []).append(preset.rstrip("]"))
    return [(f"{name}[{', '.join(presets)}]", feature, kind, detail)
            for (name, feature, kind, detail), presets in sorted(grouped.items())]


#: The first this many characters of an approximation's detail are shown, the rest folded.
DETAIL_SUMMARY = 160


def _folded(detail: str) -> str:
    """HTML of a long detail: its first sentence (at most DETAIL_SUMMARY characters) shown,
    the whole text folded in a <details>."""
    text = str(detail)
    first = text.split(". ", 1)[0]
    if len(first) > DETAIL_SUMMARY:
        first = first[:DETAIL_SUMMARY].rsplit(" ", 1)[0] + " ..."
    if first == text:
        return _esc(text)
    return f"<details><summary>{_esc(first)}</summary>{_esc(text)}</details>"


# ---------------------------------------------------------------------------- HTML
CSS = """
body{font-family:system-ui,-apple-system,Segoe UI,Helvetica,Arial,sans-serif;margin:2em auto;
max-width:1100px;color:#222;line-height:1.4;padding:0 1em;overflow-wrap:anywhere}
h1{font-size:1.6em}h2{border-bottom:1px solid #ccc;padding-bottom:.2em;margin-top:2em}
table{border-collapse:collapse;margin:.6em 0;font-size:.86em}
caption{caption-side:top;text-align:left;font-weight:600;padding:.2em 0}
th,td{border:1px solid #ccc;padding:.25em .5em;text-align:left;vertical-align:top}
th{background:#f3f3f3}td.num{text-align:right;font-variant-numeric:tabular-nums;
overflow-wrap:normal;white-space:nowrap}
.scroll{max-width:100%;overflow-x:auto}
.status{font-weight:600}.small{color:#555;font-size:.85em}img{max-width:100%}
.figs{display:grid;grid-template-columns:repeat(2,minmax(0,1fr));gap:1em}
.figs figure{margin:0}figure{margin:.6em 0}
table.matrix{width:100%;table-layout:fixed;font-size:.8em}table.matrix th.scene{width:12%}
table.matrix .line{padding:.15em .3em;margin:1px 0;border-radius:2px}
td.notrun{color:#777;background:#fafafa}
table.conclusions{font-size:.82em}table.conclusions td:first-child{white-space:nowrap}
.toc{font-size:.9em;margin:.5em 0 1em}
dl.glossary{display:grid;grid-template-columns:max-content 1fr;gap:.2em 1em;font-size:.9em}
dl.glossary dt{font-weight:600}dl.glossary dd{margin:0}
details>summary{cursor:pointer}
@media print{details{display:block}.cb-viewer{break-inside:avoid}}
"""



def _esc(value) -> str:
    return html.escape(str(value))


def _verdict_body(verdict: str, text: str) -> tuple[str, str]:
    """(background colour, cell content) of a verdict cell: symbol and name, ``text`` under
    it."""
    style = VERDICTS.get(verdict)
    colour = style.colour if style else "#ffffff"
    body = f"<span class='status'>{_esc(verdict_text(verdict))}</span>" if style else ""
    if text:
        body += f"<br><span class='small'>{_esc(text)}</span>"
    return colour, body


def _run_verdict_td(run) -> str:
    """A per-scene table's verdict cell: the run's verdict (status and expectations together,
    as in the overview), its colour, and the message and failed expectations as its title."""
    colour, body = _verdict_body(row_verdict(run), "")
    return f"<td style='background:{colour}' title='{_esc(_run_title(run))}'>{body}</td>"


def overview_rows(data: ReportData, stiff: bool, engines: list[str]) -> list:
    """(scene, step text, engine -> cell lines) of the overview (``stiff``: of the stiff
    suite's matrix)."""
    texts = c60_cell_texts(data.c60_engines) if data.c60_engines else {}
    rows = []
    for section in data.sections:
        if (section.scene is not None and STIFF in section.scene.tags) != stiff:
            continue
        by_label = {label: texts.get(row["key"], "")
                    for label, row in section.representative.items()}
        step = (f"dt {section.scene.time_step:g} {section.scene.units.time}"
                if section.scene is not None else "")
        rows.append((section.name, step, {
            engine: cell_lines(section.representative, engine, section.scene, by_label)
            for engine in engines}))
    return rows


def _overview_html(data: ReportData, stiff: bool) -> str:
    engines = engine_columns(data.engines)
    title = "Stiff and extreme suite" if stiff else "Overview"
    note = ("Each engine at the case's own (hard) step" if stiff else
            "Each engine at the scene's comfortable step") + (
        ": one column per engine (the reference first), one line per preset it ran the "
        "scene with, its verdict from the run's status and the scene's expectations together, "
        "and under it the failing expectation's value against its limit, the message of a run "
        "that stopped, or the scene's headline figure. Hover a line for the whole text.")
    return matrix_html(overview_rows(data, stiff, engines), engines, title,
                       "stiff-matrix" if stiff else "overview-matrix", note, legend=not stiff)


def _runs_table_html(section: SceneSection) -> str:
    columns = _metric_columns(section)
    head = "".join(f"<th>{_esc(_column_head(c, section.scene))}</th>" for c in columns)
    rows = []
    for _, run in section.runs.sort_values(["label", "time_step"]).iterrows():
        figures = json.loads(run["metrics"] or "{}")
        role = " (fine reference)" if str(run["campaign"]).endswith(FINE_SUFFIX) else ""
        cells = "".join(f"<td class='num'>{_esc(format_value(figures.get(c)))}</td>"
                        for c in columns)
        passed = run["expectations_passed"]
        mark = "—" if passed is None or (isinstance(passed, float) and math.isnan(passed)) \
            else ("all passed" if int(passed) else "one failed")
        rows.append(
            f"<tr><td>{_esc(run['label'] + role)}</td><td class='num'>{run['time_step']:.3g}"
            f"</td>{_run_verdict_td(run)}<td>{mark}</td>{cells}"
            f"<td class='num'>{_esc(format_value(run['stepping_seconds_per_step'], 's'))}</td>"
            f"<td class='num'>"
            f"{_esc(format_value(run['stepping_seconds_per_simulated_second'], 's'))}</td></tr>")
    unit = section.scene.units.time if section.scene is not None else ""
    return (f"<div class='scroll'><table><caption>{_esc(section.name)}: every run"
            f"</caption><thead><tr><th>engine</th><th>dt [{_esc(unit)}]</th><th>verdict</th>"
            f"<th>expectations</th>{head}<th>stepping / step</th><th>stepping / "
            f"{_esc(unit or 'time unit')} simulated</th></tr></thead><tbody>{''.join(rows)}"
            "</tbody></table></div>")


def _messages_html(section: SceneSection) -> str:
    items = []
    for label, row in section.representative.items():
        if row["status"] != "ok" and row.get("message"):
            items.append(f"<li><b>{_esc(label)}</b> {_esc(row['status'])}: "
                         f"{_esc(row['message'])}</li>")
        for result in json.loads(row["expectations"] or "[]"):
            if result.get("passed") is False:
                items.append(f"<li><b>{_esc(label)}</b> fails {_esc(result.get('name'))}: "
                             f"{_esc(result.get('detail', ''))}</li>")
        if row.get("metrics_error"):
            items.append(f"<li><b>{_esc(label)}</b> metrics not computed: "
                         f"{_esc(row['metrics_error'])}</li>")
    return f"<ul>{''.join(items)}</ul>" if items else ""


#: One line under each per-scene figure: what it shows and what to look for.
FIGURE_CAPTIONS = {
    "Work–precision": "Error against stepping time per simulated unit over each engine's "
                      "ladder of steps (labels: steps), circles the Pareto front: look for the "
                      "lowest line furthest left.",
    "Drift and creep over time": "Penetration, clearance excess, joint gap, slip of a body "
                                 "that must stick and energy change along each engine's run "
                                 "at the scene's step: look for growth and jumps.",
}


def _section_html(section: SceneSection) -> str:
    scene = section.scene
    intro = _esc(scene.description) if scene is not None else ""
    units = (f" Units: length {scene.units.length}, mass {scene.units.mass}, time "
             f"{scene.units.time}." if scene is not None else "")
    figures = figure_grid([(png, f"{title}: {FIGURE_CAPTIONS.get(title, '')}")
                           for title, png in section.figures.items()],
                          f"Figures of {section.name}")
    notes = "".join(f"<p class='small'>{_esc(n)}</p>" for n in section.notes)
    return (heading(3, section.name, f"scene-{section.name}") + f"<p>{intro}{units}</p>"
            f"{_runs_table_html(section)}{_messages_html(section)}{figures}{notes}")


def _engines_html(data: ReportData) -> str:
    notes = [[a, b, c, _folded(d)] for a, b, c, d in _engine_notes(data)]
    versions = data.frame.groupby("label")["engine_version"].last() if len(data.frame) else {}
    version_table = table(["engine", "version"], [[k, v] for k, v in dict(versions).items()],
                          "The engines' versions")
    notes_table = (table(["engine", "feature", "support", "how"],
                         [[_esc(a), _esc(b), _esc(c), d] for a, b, c, d in notes],
                         "Features an engine approximates or does not support", raw=True)
                   if notes else "<p>Every feature used was native.</p>")
    return (heading(2, "Engines and their approximations", "engines") + version_table
            + "<p class='small'>Features of the scenes run that an engine only approximates or "
            "does not support, as the engine states it (Engine.capabilities):</p>"
            + notes_table)


def load_c60_validation(path: str | Path | None) -> dict | None:
    """The JSON written by ``clearbench c60 validate`` (table, findings, runs, figures), with
    the figures read in as PNG bytes under ``"figure_png"``; None when ``path`` is None or
    does not exist (the C-60 section is then left out)."""
    if path is None or not Path(path).is_file():
        return None
    document = json.loads(Path(path).read_text())
    base = Path(path).parent
    document["figure_png"] = {}
    for title, relative in document.get("figures", {}).items():
        figure = base / relative
        if figure.is_file():
            document["figure_png"][title] = figure.read_bytes()
        else:
            LOG.warning("C-60 validation figure %s is missing", figure)
    return document


def _c60_number(value, digits: int = 3) -> str:
    return "-" if value is None else f"{value:.{digits}f}"


def _c60_difference(value) -> str:
    return "-" if value is None else f"{100 * value:+.1f} %"


def _c60_causes(validation: dict) -> list[tuple[list[str], str]]:
    """Each distinct believed cause once, with the quantities (and differences) it
    explains."""
    grouped: dict[str, list[str]] = {}
    for r in validation["rows"]:
        if r.get("believed_cause"):
            note = f" ({r['note']})" if r.get("note") else ""
            grouped.setdefault(r["believed_cause"], []).append(
                f"{r['quantity']}{note}: {_c60_difference(r['difference'])}")
    return [(quantities, cause) for cause, quantities in grouped.items()]


def _c60_html(validation: dict) -> str:
    rows = [[r["quantity"] + (f" ({r['note']})" if r["note"] else ""), r["unit"],
             _c60_number(r["ours"]), _c60_number(r["paper_simulated"]),
             _c60_number(r["paper_measured"]), _c60_difference(r["difference"])]
            for r in validation["rows"]]
    causes = "".join(f"<li>{'; '.join(_esc(q) for q in quantities)}. What we believe causes "
                     f"it: {_esc(cause)}</li>" for quantities, cause in _c60_causes(validation))
    findings = "".join(f"<li>{_esc(f)}</li>" for f in validation.get("findings", []))
    figures = figure_grid([(png, title) for title, png in
                           validation.get("figure_png", {}).items()],
                          "Force-displacement figures against the paper's", open_=True)
    return (heading(2, validation["title"], "c60-paper")
            + f"<p class='small'>From <code>{_esc(validation['source'])}</code> (reference "
            f"engine, preset {_esc(validation['preset'])}); paper: {_esc(validation['paper'])}."
            " Differences are relative to the measured value where there is one, else to the "
            "paper's simulated value; nothing is tuned to them.</p>"
            + table(["quantity", "unit", "ours", "paper, simulated", "paper, measured",
                     "difference"], rows, "The reference engine's C-60 against the paper",
                    numeric=(2, 3, 4, 5))
            + heading(3, "Differences above 10 %", "c60-paper-differences")
            + f"<ul class='small'>{causes}</ul>" + heading(3, "Findings", "c60-paper-findings")
            + f"<ul class='small'>{findings}</ul>{figures}")


def _c60_markdown(validation: dict, figure_files: dict) -> list[str]:
    lines = [f"## {validation['title']}", "",
             f"From `{validation['source']}` (reference engine, preset {validation['preset']});"
             f" paper: {validation['paper']}.", "",
             "| quantity | unit | ours | paper, simulated | paper, measured | difference |",
             "|---|---|---|---|---|---|"]
    for r in validation["rows"]:
        note = f" ({r['note']})" if r["note"] else ""
        lines.append(f"| {_md_escape(r['quantity'] + note)} | {r['unit']} | "
                     f"{_c60_number(r['ours'])} | {_c60_number(r['paper_simulated'])} | "
                     f"{_c60_number(r['paper_measured'])} | "
                     f"{_c60_difference(r['difference'])} |")
    lines.append("")
    lines += [f"- {_md_escape('; '.join(quantities))}. What we believe causes it: "
              f"{_md_escape(cause)}" for quantities, cause in _c60_causes(validation)]
    lines += [f"- {_md_escape(f)}" for f in validation.get("findings", [])]
    for title, path in figure_files.items():
        lines += ["", f"![{title}]({path})"]
    return lines + [""]


def provenance(data: ReportData) -> str:
    """Where the report's figures come from: the store, its runs and revisions."""
    frame = data.frame
    revisions = ", ".join(sorted(set(frame["git_revision"].str[:12]))) if len(frame) else "-"
    return (f"{len(frame)} runs of the results store (revision {revisions}, "
            f"{data.generated[:10]})")


def results(data: ReportData) -> dict:
    """The conclusions as the README's table takes them (:mod:`.readme_table`)."""
    lines = conclusions(data.engines, data.sections, data.c60_engines)
    return results_document(HEAD, [c.cells() for c in lines], standing(data.c60_validation),
                            provenance(data))


def _conclusions_html(data: ReportData) -> str:
    lines = conclusions(data.engines, data.sections, data.c60_engines)
    if not lines:
        return ""
    sentence = standing(data.c60_validation)
    return (heading(2, "Conclusions", "conclusions")
            + "<p class='small'>One line per engine and preset: the C-60's FC-1 against the "
            "reference and the latch (c60-on), each trip event against the reference's "
            "(c60-trip; " + _esc(FLAG) + f" beyond {100 * EVENT_BOUND:g} %), the cheapest "
            "step whose FC-1 error and every finer step's stay within 1 % with its run's "
            "cost, and the verdicts at each scene's comfortable step. The sections below give "
            "each figure.</p>"
            + table(HEAD, [c.cells() for c in lines], "Each engine and preset in one line",
                    css_class="conclusions")
            + (f"<p><b>The model against the paper.</b> {_esc(sentence)}</p>" if sentence
               else ""))


HEADING = re.compile(r"<h([23]) id='([^']+)'>(.*?)</h\1>")


def table_of_contents(body: str) -> str:
    """The page's h2 headings as links, each followed by its h3 headings' links in
    parentheses: a compact paragraph (every heading has an id)."""
    entries: list[tuple[str, list[str]]] = []
    for level, ident, text in HEADING.findall(body):
        link = f"<a href='#{ident}'>{text}</a>"
        if level == "2" or not entries:
            entries.append((link, []))
        else:
            entries[-1][1].append(link)
    if not entries:
        return ""
    items = " · ".join(link + (f" <span class='small'>({', '.join(subs)})</span>" if subs
                                else "") for link, subs in entries)
    return f"<nav class='toc' id='toc'><b>Contents:</b> {items}</nav>"


def render_html(data: ReportData) -> str:
    frame = data.frame
    machines = ", ".join(sorted({f"{h} ({c}, {n} cores)" for h, c, n in
                                 zip(frame["hostname"], frame["cpu"], frame["cores"],
                                     strict=True)})) if len(frame) else "none"
    revisions = ", ".join(sorted(set(frame["git_revision"].str[:12]))) if len(frame) else ""
    counts = frame["status"].value_counts().to_dict() if len(frame) else {}
    summary = ", ".join(f"{v} {k}" for k, v in sorted(counts.items()))
    details = list(data.sections)
    shown: dict[str, str] = {}        # campaign paragraphs already on the page
    body = [
        _conclusions_html(data),
        _overview_html(data, stiff=False),
        _overview_html(data, stiff=True),
        c60_engines_html(data.c60_engines) if data.c60_engines else "",
        _c60_html(data.c60_validation) if data.c60_validation else "",
        (heading(2, "Each scene in detail", "scenes") if details else ""),
        *(_section_html(s) for s in details),
        (heading(2, "Tolerance campaigns", "campaigns") if data.campaigns else ""),
        *(campaign_html(summary, pngs, shown) for summary, pngs in data.campaigns),
        _engines_html(data),
    ]
    text = "".join(body)
    text += glossary_html(text)
    viewer = viewer_scripts() if "class='cb-viewer'" in text else ""
    head = ("<h1>clearbench comparison report</h1>"
            f"<p class='small'>Generated {data.generated} from store {_esc(data.store)}: "
            f"{len(frame)} runs ({_esc(summary)}). Machines: {_esc(machines)}. Revisions: "
            f"{_esc(revisions)}. Metrics are computed by the harness from each trajectory with "
            "shared geometry, never taken from an engine; times are wall-clock seconds of "
            "stepping alone.</p>")
    return ("<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>"
            "<meta name='viewport' content='width=device-width, initial-scale=1'>"
            f"<title>clearbench report</title><style>{CSS}{VIEWER_CSS}</style></head><body>"
            f"{head}{table_of_contents(text)}{text}{viewer}</body></html>\n")


# ---------------------------------------------------------------------------- Markdown
def _md_escape(text) -> str:
    return str(text).replace("|", "\\|").replace("\n", " ")


def render_markdown(data: ReportData, figure_files: dict, c60_figure_files: dict | None = None,
                    c60_engines_figure: str | None = None) -> str:
    lines = ["# clearbench comparison report", "",
             f"Generated {data.generated} from `{data.store}`: {len(data.frame)} runs. "
             "Full report with figures: `report.html`.", ""]
    engines = engine_columns(data.engines)
    for stiff in (False, True):
        lines += matrix_markdown(overview_rows(data, stiff, engines), engines,
                                 "Stiff and extreme suite" if stiff else "Overview")
        if not stiff and data.sections:
            lines += ["Verdicts: " + "; ".join(f"{verdict_text(name)}: {style.meaning}"
                                                for name, style in VERDICTS.items())
                      + f"; {NOT_RUN}: the engine has no run of the scene.", ""]
    if data.c60_engines:
        lines += c60_engines_markdown(data.c60_engines, c60_engines_figure)
    if data.c60_validation:
        lines += _c60_markdown(data.c60_validation, c60_figure_files or {})
    for section in data.sections:
        columns = _metric_columns(section)
        unit = section.scene.units.time if section.scene is not None else ""
        lines += [f"### {section.name}", "",
                  f"| engine | dt [{unit}] | verdict | " + " | ".join(
                      _column_head(c, section.scene) for c in columns) + " | stepping/step |",
                  "|---|---|---|" + "---|" * len(columns) + "---|"]
        for _, run in section.runs.sort_values(["label", "time_step"]).iterrows():
            figures = json.loads(run["metrics"] or "{}")
            role = " (fine ref)" if str(run["campaign"]).endswith(FINE_SUFFIX) else ""
            verdict = verdict_text(row_verdict(run))
            lines.append(f"| {run['label']}{role} | {run['time_step']:.3g} | {verdict} | "
                         + " | ".join(format_value(figures.get(c)) for c in columns)
                         + f" | {format_value(run['stepping_seconds_per_step'], 's')} |")
        for title, path in figure_files.get(section.name, {}).items():
            lines += ["", f"![{title}]({path})", "", f"*{FIGURE_CAPTIONS.get(title, title)}*"]
        lines.append("")
    for summary, pngs in data.campaigns:
        lines += ["", campaign_section_markdown(summary, list(pngs))]
    notes = _engine_notes(data)
    if notes:
        lines += ["## Engine approximations", "", "| engine | feature | support | how |",
                  "|---|---|---|---|"]
        lines += [f"| {a} | {b} | {c} | {_md_escape(d)} |" for a, b, c, d in notes]
        lines.append("")
    return "\n".join(lines)


#: Where ``clearbench c60 validate`` writes its JSON (committed with the repository).
C60_VALIDATION = Path("reports/c60_validation.json")
#: Where ``clearbench campaign report`` writes by default.
CAMPAIGNS = Path("reports/campaigns")


def write_report(store: ResultsStore, out_dir: str | Path,
                 c60_validation: str | Path | None = C60_VALIDATION,
                 campaigns: str | Path | None = CAMPAIGNS,
                 engine_modules: Mapping[str, str] | None = None) -> dict[str, Path]:
    """Write ``report.html``, ``summary.md`` and ``figures/*.png`` into ``out_dir``.

    ``c60_validation``: the JSON of ``clearbench c60 validate``; when it exists the report has
    a section with the C-60 table against the paper and its force-displacement figures.
    ``campaigns``: the folder of ``clearbench campaign report``; each campaign written there
    gets its tolerance section (statistics beside the paper's, histograms, sensitivities).
    ``engine_modules``: engines plugged in (``--engine-module``), whose declared colours the
    figures use."""
    out = Path(out_dir)
    (out / "figures").mkdir(parents=True, exist_ok=True)
    data = collect(store, colours=engine_colours(engine_modules))
    data.c60_validation = load_c60_validation(c60_validation)
    if campaigns is not None and Path(campaigns).is_dir():
        data.campaigns = load_written_sections(campaigns)
        for _, pngs in data.campaigns:
            for name, png in pngs.items():
                (out / "figures" / name).write_bytes(png)
    c60_figure_files: dict[str, str] = {}
    if data.c60_validation:
        for index, (title, png) in enumerate(data.c60_validation["figure_png"].items()):
            name = f"figures/c60-validation-{index}.png"
            (out / name).write_bytes(png)
            c60_figure_files[title] = name
    c60_engines_figure = None
    if data.c60_engines is not None and data.c60_engines.figure is not None:
        c60_engines_figure = "figures/c60-work-precision.png"
        (out / c60_engines_figure).write_bytes(data.c60_engines.figure)
    figure_files: dict[str, dict[str, str]] = {}
    for section in data.sections:
        for index, (title, png) in enumerate(section.figures.items()):
            name = f"figures/{section.name}-{index}.png"
            (out / name).write_bytes(png)
            figure_files.setdefault(section.name, {})[title] = name
    write_results(results(data), out / "results.json")
    html_path = out / "report.html"
    md_path = out / "summary.md"
    html_path.write_text(render_html(data), encoding="utf-8")
    md_path.write_text(render_markdown(data, figure_files, c60_figure_files, c60_engines_figure),
                       encoding="utf-8")
    return {"html": html_path, "markdown": md_path, "results": out / "results.json"}
