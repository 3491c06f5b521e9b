"""The comparison report: a self-contained HTML page and a Markdown summary from a results store.

Contents, the tables a reader looks at first: an overview matrix (scene x engine: verdict and
headline metric), the stiff and extreme suite in the same form, the C-60 across engines
(:mod:`.c60_section`: c60-on and c60-trip per engine, work-precision) and, when ``clearbench
c60 validate`` has written its JSON, the C-60 table against the paper and its
force-displacement figures; then the detail: per scene a table of every run with its metrics, the
work–precision plot with its Pareto front and drift and creep over time, and per engine the
features it approximates or does not support (from ``Engine.capabilities``, recorded with each
run; each once per engine and feature, the detail folded). Figures are embedded as base64 PNG
in the HTML and written as PNG files beside the Markdown.
"""

from __future__ import annotations

import base64
import html
import json
import logging
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path

import numpy as np

from clearbench.harness.measure.headline import (
    METRIC_LABELS,
    format_value,
    headline,
    scene_metric_names,
)
from clearbench.harness.measure.units import unit_text
from clearbench.harness.measure.verdicts import VERDICTS, run_verdict, verdict_text
from clearbench.harness.report.c60_section import C60Section, build_section
from clearbench.harness.report.c60_section import section_html as c60_engines_html
from clearbench.harness.report.c60_section import section_markdown as c60_engines_markdown
from clearbench.harness.report.engine_style import engine_colours
from clearbench.harness.report.figures import time_series_figure, work_precision_figure
from clearbench.harness.run.store import ResultsStore
from clearbench.harness.studies.campaign.report import load_written_sections
from clearbench.harness.studies.campaign.report import render_markdown as campaign_section_markdown
from clearbench.harness.studies.campaign.report import section_html as campaign_section_html
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
def _cell(row: dict | None, scene: Scene | None) -> tuple[str, str, str]:
    """(verdict (a key of VERDICTS, "" when not run), headline figure, title: the run's
    message and its failed expectations) of an overview cell."""
    if row is None:
        return "", "not run", ""
    figures = json.loads(row["metrics"] or "{}")
    name, value = headline(scene, figures) if scene is not None else ("", math.nan)
    label = METRIC_LABELS.get(name, (name, ""))[0]
    text = f"{label} {format_value(value, unit_text(name, scene, short=True))}" if name else ""
    return (run_verdict(row["status"], row.get("expectations_passed"), figures), text,
            _run_title(row))


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
max-width:1100px;color:#222;line-height:1.4;padding:0 1em}
h1{font-size:1.6em}h2{border-bottom:1px solid #ccc;padding-bottom:.2em;margin-top:2em}
table{border-collapse:collapse;margin:.6em 0;font-size:.86em}
th,td{border:1px solid #ccc;padding:.25em .5em;text-align:left;vertical-align:top}
th{background:#f3f3f3}td.num{text-align:right;font-variant-numeric:tabular-nums}
.status{font-weight:600}.small{color:#666;font-size:.85em}img{max-width:100%}
.figs{display:flex;flex-wrap:wrap;gap:1em}.figs figure{margin:0}
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
    colour, body = _verdict_body(run_verdict(run["status"], run["expectations_passed"],
                                             json.loads(run["metrics"] or "{}")), "")
    return f"<td style='background:{colour}' title='{_esc(_run_title(run))}'>{body}</td>"


def _verdict_td(verdict: str, text: str, title: str, scene: str, engine: str) -> str:
    """An overview cell: the verdict's colour, symbol and name, the headline figure under it;
    ``data-*`` attributes name the scene, engine and verdict for tools reading the page."""
    colour, body = _verdict_body(verdict, text)
    return (f"<td class='verdict' data-scene='{_esc(scene)}' data-engine='{_esc(engine)}' "
            f"data-verdict='{_esc(verdict or 'not run')}' style='background:{colour}' "
            f"title='{_esc(title)}'>{body}</td>")


def _verdict_legend_html() -> str:
    items = "".join(f"<tr><td style='background:{style.colour}'><span class='status'>"
                    f"{_esc(verdict_text(name))}</span></td><td>{_esc(style.meaning)}</td></tr>"
                    for name, style in VERDICTS.items())
    return (f"<table class='legend'><tr><th>verdict</th><th>meaning</th></tr>{items}</table>"
            "<p class='small'>Under the verdict: the scene's headline figure. Hover a cell for "
            "the run's message and the expectations it failed (docs/harness.md: verdicts).</p>")


def _overview_html(data: ReportData, stiff: bool) -> str:
    sections = [s for s in data.sections
                if (s.scene is not None and STIFF in s.scene.tags) == stiff]
    if not sections:
        return ""
    head = "".join(f"<th>{_esc(label)}</th>" for label in data.engines)
    body = []
    for section in sections:
        cells = "".join(_verdict_td(*_cell(section.representative.get(label), section.scene),
                                    section.name, label)
                        for label in data.engines)
        step = f"{section.scene.time_step:g} {section.scene.units.time}" if section.scene else ""
        body.append(f"<tr><td><a href='#scene-{_esc(section.name)}'>{_esc(section.name)}</a>"
                    f"<br><span class='small'>dt {step}</span></td>{cells}</tr>")
    title = "Stiff and extreme suite" if stiff else "Overview"
    note = ("each engine at the case's own (hard) step" if stiff else
            "each engine at the scene's comfortable step")
    table_id = "stiff-matrix" if stiff else "overview-matrix"
    return (f"<h2>{title}</h2><p class='small'>{note}: one verdict per run, from its status and "
            "the scene's expectations together, and the scene's headline figure.</p>"
            f"<table id='{table_id}'><tr><th>scene</th>{head}</tr>{''.join(body)}</table>"
            + ("" if stiff else _verdict_legend_html()))


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
            else ("pass" if int(passed) else "FAIL")
        rows.append(
            f"<tr><td>{_esc(run['label'] + role)}</td><td class='num'>{run['time_step']:.3g}"
            f"</td>{_run_verdict_td(run)}<td>{mark}</td>{cells}"
            f"<td class='num'>{_esc(format_value(run['stepping_seconds_per_step'], 's'))}</td>"
            f"<td class='num'>"
            f"{_esc(format_value(run['stepping_seconds_per_simulated_second'], 's'))}</td></tr>")
    return ("<table><tr><th>engine</th><th>dt</th><th>verdict</th><th>expectations</th>"
            f"{head}<th>stepping / step</th><th>stepping / sim. unit</th></tr>"
            f"{''.join(rows)}</table>")


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
    units = f" Units: {_esc(scene.units.describe())}." if scene is not None and hasattr(
        scene.units, "describe") else ""
    figures = "".join(
        f"<figure><img alt='{_esc(title)} of {_esc(section.name)}' "
        f"src='data:image/png;base64,{base64.b64encode(png).decode()}'>"
        f"<figcaption class='small'><b>{_esc(title)}.</b> "
        f"{_esc(FIGURE_CAPTIONS.get(title, ''))}</figcaption></figure>"
        for title, png in section.figures.items())
    notes = "".join(f"<p class='small'>{_esc(n)}</p>" for n in section.notes)
    return (f"<h2 id='scene-{_esc(section.name)}'>{_esc(section.name)}</h2><p>{intro}{units}</p>"
            f"{_runs_table_html(section)}{_messages_html(section)}"
            f"<div class='figs'>{figures}</div>{notes}")


def _engines_html(data: ReportData) -> str:
    rows = "".join(f"<tr><td>{_esc(a)}</td><td>{_esc(b)}</td><td>{_esc(c)}</td>"
                   f"<td>{_folded(d)}</td></tr>" for a, b, c, d in _engine_notes(data))
    versions = data.frame.groupby("label")["engine_version"].last() if len(data.frame) else {}
    version_rows = "".join(f"<tr><td>{_esc(k)}</td><td>{_esc(v)}</td></tr>"
                           for k, v in dict(versions).items())
    table = (f"<table><tr><th>engine</th><th>feature</th><th>support</th><th>how</th></tr>"
             f"{rows}</table>") if rows else "<p>Every feature used was native.</p>"
    return ("<h2>Engines and their approximations</h2>"
            f"<table><tr><th>engine</th><th>version</th></tr>{version_rows}</table>"
            "<p class='small'>Features of the scenes run that an engine only approximates or "
            f"does not support, as the engine states it (Engine.capabilities):</p>{table}")


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


def _c60_html(validation: dict) -> str:
    rows = "".join(
        f"<tr><td>{_esc(r['quantity'])}{_esc(' (' + r['note'] + ')') if r['note'] else ''}"
        f"</td><td>{_esc(r['unit'])}</td><td>{_c60_number(r['ours'])}</td>"
        f"<td>{_c60_number(r['paper_simulated'])}</td><td>{_c60_number(r['paper_measured'])}"
        f"</td><td>{_c60_difference(r['difference'])}</td></tr>" for r in validation["rows"])
    causes = "".join(f"<li>{_esc(r['quantity'])}: {_c60_difference(r['difference'])}. What we "
                     f"believe causes it: {_esc(r['believed_cause'])}</li>"
                     for r in validation["rows"] if r.get("believed_cause"))
    findings = "".join(f"<li>{_esc(f)}</li>" for f in validation.get("findings", []))
    figures = "".join(
        f"<figure><img alt='{_esc(title)}' src='data:image/png;base64,"
        f"{base64.b64encode(png).decode()}'><figcaption>{_esc(title)}</figcaption></figure>"
        for title, png in validation.get("figure_png", {}).items())
    return (f"<h2>{_esc(validation['title'])}</h2>"
            f"<p class='small'>From <code>{_esc(validation['source'])}</code> (reference "
            f"engine, preset {_esc(validation['preset'])}); paper: {_esc(validation['paper'])}."
            " Differences are relative to the measured value where there is one, else to the "
            "paper's simulated value; nothing is tuned to them.</p>"
            "<table><tr><th>quantity</th><th>unit</th><th>ours</th><th>paper, simulated</th>"
            f"<th>paper, measured</th><th>difference</th></tr>{rows}</table>"
            f"<h3>Differences above 10 %</h3><ul class='small'>{causes}</ul>"
            f"<h3>Findings</h3><ul class='small'>{findings}</ul>{figures}")


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
    lines += [f"- {_md_escape(r['quantity'])}: {_c60_difference(r['difference'])}. What we "
              f"believe causes it: {_md_escape(r['believed_cause'])}"
              for r in validation["rows"] if r.get("believed_cause")]
    lines += [f"- {_md_escape(f)}" for f in validation.get("findings", [])]
    for title, path in figure_files.items():
        lines += ["", f"![{title}]({path})"]
    return lines + [""]


def render_html(data: ReportData) -> str:
    frame = data.frame
    machines = ", ".join(sorted({f"{h} ({c}, {n} cores)" for h, c, n in
                                 zip(frame["hostname"], frame["cpu"], frame["cores"],
                                     strict=True)})) if len(frame) else "none"
    revisions = ", ".join(sorted(set(frame["git_revision"].str[:12]))) if len(frame) else ""
    counts = frame["status"].value_counts().to_dict() if len(frame) else {}
    summary = ", ".join(f"{v} {k}" for k, v in sorted(counts.items()))
    body = [
        "<h1>clearbench comparison report</h1>",
        f"<p class='small'>Generated {data.generated} from store {_esc(data.store)}: "
        f"{len(frame)} runs ({_esc(summary)}). Machines: {_esc(machines)}. Revisions: "
        f"{_esc(revisions)}. Metrics are computed by the harness from each trajectory with "
        "shared geometry, never taken from an engine; times are wall-clock seconds of "
        "stepping alone.</p>",
        _overview_html(data, stiff=False),
        _overview_html(data, stiff=True),
        c60_engines_html(data.c60_engines) if data.c60_engines else "",
        _c60_html(data.c60_validation) if data.c60_validation else "",
        *(_section_html(s) for s in data.sections),
        *(campaign_section_html(summary, pngs) for summary, pngs in data.campaigns),
        _engines_html(data),
    ]
    return ("<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>"
            "<meta name='viewport' content='width=device-width, initial-scale=1'>"
            f"<title>clearbench report</title><style>{CSS}</style></head><body>"
            f"{''.join(body)}</body></html>\n")


# ---------------------------------------------------------------------------- Markdown
def _md_escape(text) -> str:
    return str(text).replace("|", "\\|").replace("\n", " ")


def render_markdown(data: ReportData, figure_files: dict, c60_figure_files: dict | None = None,
                    c60_engines_figure: str | None = None) -> str:
    lines = ["# clearbench comparison report", "",
             f"Generated {data.generated} from `{data.store}`: {len(data.frame)} runs. "
             "Full report with figures: `report.html`.", ""]
    for stiff in (False, True):
        sections = [s for s in data.sections
                    if (s.scene is not None and STIFF in s.scene.tags) == stiff]
        if not sections:
            continue
        lines += [f"## {'Stiff and extreme suite' if stiff else 'Overview'}", "",
                  "| scene | " + " | ".join(data.engines) + " |",
                  "|---|" + "---|" * len(data.engines)]
        for section in sections:
            cells = []
            for label in data.engines:
                verdict, text, _ = _cell(section.representative.get(label), section.scene)
                cells.append(_md_escape(f"**{verdict_text(verdict)}** {text}".strip()
                                        if verdict else text))
            lines.append(f"| {section.name} | " + " | ".join(cells) + " |")
        lines.append("")
        if not stiff:
            lines += ["Verdicts: " + "; ".join(f"{verdict_text(name)}: {style.meaning}"
                                                for name, style in VERDICTS.items()) + ".", ""]
    if data.c60_engines:
        lines += c60_engines_markdown(data.c60_engines, c60_engines_figure)
    if data.c60_validation:
        lines += _c60_markdown(data.c60_validation, c60_figure_files or {})
    for section in data.sections:
        columns = _metric_columns(section)
        lines += [f"### {section.name}", "",
                  "| engine | dt | verdict | " + " | ".join(
                      _column_head(c, section.scene) for c in columns) + " | stepping/step |",
                  "|---|---|---|" + "---|" * len(columns) + "---|"]
        for _, run in section.runs.sort_values(["label", "time_step"]).iterrows():
            figures = json.loads(run["metrics"] or "{}")
            role = " (fine ref)" if str(run["campaign"]).endswith(FINE_SUFFIX) else ""
            verdict = verdict_text(run_verdict(run["status"], run["expectations_passed"],
                                               figures))
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
    html_path = out / "report.html"
    md_path = out / "summary.md"
    html_path.write_text(render_html(data), encoding="utf-8")
    md_path.write_text(render_markdown(data, figure_files, c60_figure_files, c60_engines_figure),
                       encoding="utf-8")
    return {"html": html_path, "markdown": md_path}
