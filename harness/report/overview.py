"""The overview matrix: one row per scene, one column per engine (the reference first), each
cell one line per preset the engine ran the scene with: the preset, the verdict (symbol,
word, colour) and the figure that matters: the failing expectation's value against its limit
for a failed run, the run's message for one that stopped, the C-60's FC-1 against the
reference's and the latch, else the scene's headline figure. Every word a cell uses is in the
legend beside it."""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from dataclasses import dataclass

from clearbench.harness.measure.geometry_check import UNSEEN_PENETRATION
from clearbench.harness.measure.headline import METRIC_LABELS, format_value, headline
from clearbench.harness.measure.units import unit_text
from clearbench.harness.measure.verdicts import VERDICTS, criteria, run_verdict, verdict_text
from clearbench.harness.report.html_parts import esc, heading, length_text
from clearbench.scenarios.scene import Scene

REFERENCE_ENGINE = "reference"
#: The word of a cell whose engine has no run of the scene.
NOT_RUN = "not run"
#: Longest text of a line's figure before it is cut (the whole text is the cell's title).
FIGURE_CHARS = 120


@dataclass(frozen=True)
class CellLine:
    """One preset's line of a cell: its verdict (a key of VERDICTS), the figure shown under
    it and the run's full message and failed expectations (the cell's title)."""

    label: str
    preset: str
    verdict: str
    figure: str
    title: str
    failed_kinds: tuple = ()


def engine_of(label: str) -> tuple[str, str]:
    """``'mujoco[tuned]'`` -> ``('mujoco', 'tuned')``."""
    name, _, preset = label.partition("[")
    return name, preset.rstrip("]") or "default"


def engine_columns(labels: Sequence[str]) -> list[str]:
    """The engines of ``labels``, the reference first, then in alphabetical order."""
    names = sorted({engine_of(label)[0] for label in labels})
    return sorted(names, key=lambda name: (name != REFERENCE_ENGINE, name))


def row_verdict(row) -> str:
    """The verdict of a stored run (a dict or DataFrame row): its status and its expectations
    together (:func:`~clearbench.harness.measure.verdicts.run_verdict`); the one place the
    report asks for it. An ok run whose stored figures hold an unseen penetration (the
    run-wide geometry check) is "unseen penetration"."""
    return run_verdict(row["status"], row.get("expectations_passed"),
                       json.loads(row.get("metrics") or "{}"))


def unseen_text(row: dict) -> str:
    """The run-wide geometry check's finding for an "unseen penetration" run (the pair, the
    time, the instrument's figure against the kernel's), without the verdict's name; ""
    for any other run."""
    if row_verdict(row) != UNSEEN_PENETRATION:
        return ""
    return (row.get("verdict_reason") or "").removeprefix(f"{UNSEEN_PENETRATION}: ")


def failed_expectations(row: dict) -> list[dict]:
    """The expectation results of a run that failed (each with its ``detail``: the value
    against its limit)."""
    return [r for r in json.loads(row.get("expectations") or "[]") if r.get("passed") is False]


def run_figure(row: dict, scene: Scene | None, c60_text: str = "") -> str:
    """What a cell shows under a run's verdict: the message of a run that did not finish;
    the geometry check's finding for an unseen penetration; ``c60_text`` (the C-60's FC-1
    against the reference's and the latch, or its trip events) for a C-60 run and the failed
    expectations' values against their limits; else the scene's headline figure."""
    if row["status"] != "ok":
        return (row.get("message") or "").split("\n", 1)[0]
    failed = "; ".join(r.get("detail") or r.get("name", "") for r in failed_expectations(row))
    unseen = unseen_text(row)
    if c60_text or failed or unseen:
        return "; ".join(filter(None, [unseen, c60_text, failed]))
    figures = json.loads(row.get("metrics") or "{}")
    name, value = headline(scene, figures) if scene is not None else ("", math.nan)
    if not name:
        return ""
    label, kind = METRIC_LABELS.get(name, (name, ""))
    if kind == "length":
        return f"{label} {length_text(value, scene.units.length)}"
    return f"{label} {format_value(value, unit_text(name, scene, short=True))}"


def _cut(text: str) -> str:
    return text if len(text) <= FIGURE_CHARS else text[:FIGURE_CHARS - 3].rsplit(" ", 1)[0] + " ..."


def cell_lines(representative: dict, engine: str, scene: Scene | None,
               c60_texts: dict | None = None) -> list[CellLine]:
    """The lines of the cell of ``engine`` in a scene whose runs at its step are
    ``representative`` (label -> row); ``c60_texts``: label -> the C-60 figure text."""
    lines = []
    labels = sorted((label for label in representative if engine_of(label)[0] == engine),
                    key=lambda label: (engine_of(label)[1] != "default", label))
    for label in labels:
        row = representative[label]
        verdict = row_verdict(row)
        figure = run_figure(row, scene, (c60_texts or {}).get(label, ""))
        failed = [r.get("name", "") for r in failed_expectations(row)]
        title = "; ".join(filter(None, [row.get("message") or "", figure,
                                        f"failed: {', '.join(failed)}" if failed else ""]))
        kinds = tuple(r.get("kind", "") for r in failed_expectations(row))
        lines.append(CellLine(label, engine_of(label)[1], verdict, figure, title, kinds))
    return lines


def cell_html(lines: list[CellLine], scene: str, engine: str) -> str:
    """A cell: one coloured line per preset (``data-*`` attributes name the scene, engine,
    preset and verdict for tools reading the page), or 'not run'."""
    if not lines:
        return (f"<td class='verdict notrun' data-scene='{esc(scene)}' "
                f"data-engine='{esc(engine)}' data-verdict='{NOT_RUN}'>{NOT_RUN}</td>")
    parts = []
    for line in lines:
        colour = VERDICTS[line.verdict].colour
        figure = f"<br><span class='small'>{esc(_cut(line.figure))}</span>" if line.figure else ""
        parts.append(f"<div class='line' style='background:{colour}' "
                     f"data-label='{esc(line.label)}' data-verdict='{esc(line.verdict)}' "
                     f"title='{esc(line.title)}'><b>{esc(line.preset)}</b> "
                     f"<span class='status'>{esc(verdict_text(line.verdict))}</span>"
                     f"{figure}</div>")
    verdicts = ",".join(line.verdict for line in lines)
    return (f"<td class='verdict' data-scene='{esc(scene)}' data-engine='{esc(engine)}' "
            f"data-verdict='{esc(verdicts)}'>{''.join(parts)}</td>")


def legend_html(words: dict[str, str]) -> str:
    """The legend: every verdict with its colour and meaning, 'not run', then ``words`` (a
    cell's other words: presets, figure labels) with what each means."""
    items = "".join(f"<tr><td style='background:{style.colour}'><span class='status'>"
                    f"{esc(verdict_text(name))}</span></td><td>{esc(style.meaning)}</td></tr>"
                    for name, style in VERDICTS.items())
    items += (f"<tr><td class='notrun'>{NOT_RUN}</td><td>the engine has no run of this "
              "scene in the store (an engine not available here, or a scene the comparison "
              "did not give it)</td></tr>")
    items += "".join(f"<tr><td><b>{esc(word)}</b></td><td>{esc(meaning)}</td></tr>"
                     for word, meaning in sorted(words.items()))
    return (f"<table class='legend'><caption>Legend of the matrix</caption><thead><tr>"
            f"<th>word</th><th>meaning</th></tr></thead><tbody>{items}</tbody></table>")


#: What a preset word means in a cell (an engine's other presets: its docs page).
PRESET_WORDS = {
    "default": "preset: the engine's own defaults (the reference: its nonsmooth Moreau-Jean "
               "scheme at its default tolerances)",
    "tuned": "preset: settings chosen for contact accuracy (the engine's page in docs/engines/)",
    "mechanism": "preset (Exudyn): settings for the C-60 mechanism (docs/engines/exudyn.md)",
    "projection": "preset (Siconos): the combined projection scheme (docs/engines/siconos.md)",
    "nsn-ac": "preset (Siconos): the Alart-Curnier Newton solver (docs/engines/siconos.md)",
}
#: What a figure's words mean in a cell.
FIGURE_WORDS = {
    "error": "relative error of the scene's outputs against its analytic solution, else "
             "against the reference at a fine step",
    "penetration": "largest depth of one shape in another over the run",
    "clearance excess": "largest eccentricity of a clearance joint beyond its radial "
                        "clearance",
    "joint gap": "largest distance between the two halves of an ideal joint",
    "joint angle": "largest angular violation of an ideal joint",
    "|q|-1": "largest error of a quaternion's norm",
    "stick slip": "displacement of a body physics says must stick",
    "creep rate": "speed of that displacement",
    "energy drift": "change of mechanical energy where it is conserved, over its scale",
    "energy growth": "largest rise of mechanical energy where it may only fall, over its "
                     "scale",
    "unconverged": "steps whose contact problem did not converge",
    "FC-1": "C-60: the C7 contact force (moving on fixed contact) at equilibrium, here "
            "against the reference's",
    "latch": "C-60: whether the hook stays on the tripping bar (creep within the scene's "
             "bound)",
}


def words_used(lines: Sequence[CellLine]) -> dict[str, str]:
    """The legend entries for the presets and figure words the matrix's lines use."""
    used = {}
    for line in lines:
        used[line.preset] = PRESET_WORDS.get(line.preset, "preset: the engine's named "
                                             "settings (its page in docs/engines/)")
        for word, meaning in FIGURE_WORDS.items():
            if line.figure.startswith(word) or f" {word} " in f" {line.figure} ":
                used[word] = meaning
        rules = criteria()
        for kind in line.failed_kinds:
            if kind in rules:
                used[f"failed: {kind.replace('_', ' ')}"] = (
                    f"the scene's {kind} expectation failed; it passes when "
                    f"{rules[kind].passes_when} (the cell gives the value against the limit)")
    return used


def matrix_html(rows: Sequence[tuple[str, str, dict[str, list[CellLine]]]],
                engines: Sequence[str], title: str, table_id: str, note: str,
                legend: bool) -> str:
    """``rows``: (scene name, its step text, engine -> lines)."""
    if not rows:
        return ""
    head = "".join(f"<th>{esc(engine)}</th>" for engine in engines)
    body = []
    every = []
    for scene, step, cells in rows:
        tds = "".join(cell_html(cells.get(engine, []), scene, engine) for engine in engines)
        every += [line for engine in engines for line in cells.get(engine, [])]
        body.append(f"<tr><th class='scene'><a href='#scene-{esc(scene)}'>{esc(scene)}</a>"
                    f"<br><span class='small'>{esc(step)}</span></th>{tds}</tr>")
    return (heading(2, title, table_id.replace("-matrix", ""))
            + f"<p class='small'>{esc(note)}</p>"
            f"<table id='{table_id}' class='matrix'><caption>{esc(title)}: scene by engine"
            f"</caption><thead><tr><th>scene</th>{head}</tr></thead><tbody>{''.join(body)}"
            "</tbody></table>" + (legend_html(words_used(every)) if legend else ""))


def matrix_markdown(rows, engines: Sequence[str], title: str) -> list[str]:
    if not rows:
        return []
    lines = [f"## {title}", "", "| scene | " + " | ".join(engines) + " |",
             "|---|" + "---|" * len(engines)]
    for scene, _, cells in rows:
        texts = []
        for engine in engines:
            mine = cells.get(engine, [])
            texts.append("<br>".join(
                f"{line.preset}: **{verdict_text(line.verdict)}** {_cut(line.figure)}".strip()
                for line in mine).replace("|", "\\|") or NOT_RUN)
        lines.append(f"| {scene} | " + " | ".join(texts) + " |")
    lines.append("")
    return lines
