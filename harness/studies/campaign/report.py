"""The tolerance section of the report: a campaign's statistics beside the paper's, with
histograms, convergence and sensitivities, as Markdown, HTML and a JSON summary.

Statistics use the samples whose run ended ``ok``; every other status is counted and listed,
never dropped silently.
"""

from __future__ import annotations

import base64
import html
import json
import math
from dataclasses import asdict
from pathlib import Path

import numpy as np
from scipy import stats

from clearbench.harness.report.figures import _png, _pyplot
from clearbench.harness.run.store import ResultsStore
from clearbench.harness.studies.campaign.definition import CampaignDefinition, CampaignError
from clearbench.harness.studies.campaign.formatting import counts_text, parameters_text
from clearbench.harness.studies.campaign.formatting import format_number as _fmt
from clearbench.harness.studies.campaign.results import (
    definition_summary,
    report_table,
    throughput,
)
from clearbench.harness.studies.campaign.statistics import (
    Capability,
    capability,
    running_moments,
    runs_needed,
    sensitivities,
)

#: The study's cost per run and cluster (Section 4.2), for the projection beside ours.
PAPER_SECONDS_PER_RUN = 810.0
PAPER_CPUS = 160
PAPER_RUNS = 30_850
#: Half-width of Cpk's 95 % interval the report sizes the campaign for.
CPK_HALF_WIDTH = 0.1


def summarise(definition: CampaignDefinition, store: ResultsStore, table,
              companions: tuple[CampaignDefinition, ...] = ()) -> dict:
    """Everything the section shows, as plain data (also written as JSON), from the
    campaign's ``table`` (:func:`report_table`'s) and its log in ``store``."""
    ok = table[table["status"] == "ok"]
    statuses = table["status"].value_counts().to_dict()
    outputs = []
    for spec in definition.outputs:
        values = ok[spec.name].to_numpy(dtype=float)
        cap = capability(values, spec.lower_limit, spec.upper_limit)
        entry = {"name": spec.name, "unit": spec.unit, "output": spec.output,
                 "statistic": spec.statistic, "window": spec.window,
                 "limits": [spec.lower_limit, spec.upper_limit] if spec.has_limits else None,
                 "limits_source": spec.limits_source if spec.has_limits else "not published",
                 "capability": _capability_dict(cap),
                 "paper": asdict(spec.paper) if spec.paper else None,
                 "non_finite_ok_runs": int(np.count_nonzero(~np.isfinite(values)))}
        if spec.paper is not None and cap.count >= 2:
            entry["mean_difference_in_paper_sigmas"] = (
                (cap.mean.value - spec.paper.mean) / spec.paper.sigma)
        if cap.cpk is not None:
            entry["runs_for_cpk_half_width"] = runs_needed(cap.cpk.value, CPK_HALF_WIDTH)
        if len(ok) > definition.dimension + 2:
            sens = sensitivities(ok[[law.name for law in definition.inputs]].to_numpy(),
                                 values, [law.name for law in definition.inputs],
                                 seed=definition.seed)
            entry["sensitivity"] = {"inputs": list(sens.names),
                                    "src": sens.src.tolist(), "r_squared": sens.r_squared,
                                    "s1": sens.s1.tolist(),
                                    "s1_confidence": sens.s1_confidence.tolist()}
        outputs.append(entry)
    speed = throughput(store, definition)
    projected = (PAPER_RUNS / speed["samples_per_hour"]
                 if speed["samples_per_hour"] == speed["samples_per_hour"]
                 and speed["samples_per_hour"] > 0 else math.nan)
    return {
        "definition": definition_summary(definition),
        "samples_planned": int(len(table)), "statuses": statuses,
        "sources": {str(k): int(v) for k, v in table["source"].value_counts().items()},
        "not_ok": table[~table["status"].isin(["ok", "pending"])][
            ["sample", "key", "status", "message"]].to_dict("records"),
        "outputs": outputs, "throughput": speed,
        "projection_hours_for_paper_runs": projected,
        "paper_cluster_hours": PAPER_RUNS * PAPER_SECONDS_PER_RUN / PAPER_CPUS / 3600.0,
        "companions": [c.name for c in companions],
    }


def _capability_dict(cap: Capability) -> dict:
    return json.loads(json.dumps(asdict(cap), default=float))


# ---------------------------------------------------------------------- figures
def histogram_figure(name: str, unit: str, values: np.ndarray, limits, paper) -> bytes:
    """Histogram of ``values`` with the fitted normal, the limits and the paper's normal."""
    plt = _pyplot()
    figure, axes = plt.subplots(figsize=(5.2, 3.4))
    values = values[np.isfinite(values)]
    axes.hist(values, bins=max(10, int(math.sqrt(len(values)))), density=True, color="#9ecae1",
              edgecolor="#3182bd", label=f"ours ({len(values)} runs)")
    lo, hi = float(np.min(values)), float(np.max(values))
    if paper:
        lo, hi = min(lo, paper["mean"] - 4 * paper["sigma"]), max(hi, paper["mean"]
                                                                   + 4 * paper["sigma"])
    grid = np.linspace(lo, hi, 400)
    if len(values) > 1 and np.std(values) > 0:
        axes.plot(grid, stats.norm.pdf(grid, np.mean(values), np.std(values, ddof=1)),
                  color="#08519c", label="fitted normal")
    if paper:
        axes.plot(grid, stats.norm.pdf(grid, paper["mean"], paper["sigma"]), "--",
                  color="#d95f02", label=f"paper: {paper['mean']:g} +- {paper['sigma']:g}")
    if limits:
        for limit, text in zip(limits, ("LSL", "USL"), strict=True):
            axes.axvline(limit, color="#a50f15", linestyle=":", label=text)
    axes.set_xlabel(f"{name} [{unit}]" if unit else name)
    axes.set_ylabel("density")
    axes.legend(fontsize=7)
    return _png(figure)


def convergence_figure(name: str, unit: str, series: dict[str, np.ndarray]) -> bytes:
    """Running mean and standard deviation of an output against the number of runs, one line
    per design (label -> values in sample order)."""
    plt = _pyplot()
    figure, (top, bottom) = plt.subplots(2, 1, figsize=(5.2, 4.4), sharex=True)
    colours = {"sobol": "#1b9e77", "monte-carlo": "#d95f02", "corners": "#7570b3"}
    for label, values in series.items():
        values = values[np.isfinite(values)]
        if len(values) < 2:
            continue
        mean, sigma = running_moments(values)
        runs = np.arange(1, len(values) + 1)
        colour = colours.get(label.split(" ")[0], None)
        top.plot(runs, mean, label=label, color=colour)
        bottom.plot(runs, sigma, label=label, color=colour)
    top.set_ylabel(f"mean [{unit}]")
    bottom.set_ylabel(f"sigma [{unit}]")
    bottom.set_xlabel("runs")
    top.set_xscale("log")
    top.legend(fontsize=7)
    top.set_title(f"{name}: convergence with the number of runs", fontsize=9)
    return _png(figure)


# ---------------------------------------------------------------------- writing
def write_campaign_report(definition: CampaignDefinition, store: ResultsStore,
                          out_dir: str | Path,
                          companions: tuple[CampaignDefinition, ...] = (),
                          given: dict | None = None) -> dict:
    """Write ``<name>.md``, ``<name>.html``, ``<name>.json``, ``<name>.csv`` and figures
    under ``out_dir``; ``companions`` are campaigns of the same study with other designs,
    drawn in the convergence figures; ``given`` maps a name (the CSV's path) to a campaign
    CSV's DataFrame that supplies runs the store lacks, for this campaign or a companion
    (each must supply some). Returns the summary."""
    frames = tuple((given or {}).values())
    table, filled = report_table(definition, store, frames)
    others = {}
    for companion in companions:
        others[companion.design + f" ({companion.name})"], theirs = report_table(
            companion, store, frames)
        filled = [a + b for a, b in zip(filled, theirs, strict=True)]
    for name, frame, count in zip(given or {}, frames, filled, strict=True):
        if count == 0:
            raise CampaignError(f"given {name}", f"{len(frame)} rows", "none is a pending "
                                "sample of this report's campaigns with the same inputs")
    out = Path(out_dir)
    figures_dir = out / "figures"
    figures_dir.mkdir(parents=True, exist_ok=True)
    summary = summarise(definition, store, table, companions)
    ok = table[table["status"] == "ok"]
    pngs: dict[str, bytes] = {}
    for spec, entry in zip(definition.outputs, summary["outputs"], strict=True):
        values = ok[spec.name].to_numpy(dtype=float)
        if np.isfinite(values).sum() >= 2:
            pngs[f"{definition.name}_{spec.name}_histogram.png"] = histogram_figure(
                spec.name, spec.unit, values, entry["limits"], entry["paper"])
            series = {f"{definition.design} ({definition.name})": values}
            for label, frame in others.items():
                series[label] = frame[frame["status"] == "ok"][spec.name].to_numpy(float)
            pngs[f"{definition.name}_{spec.name}_convergence.png"] = convergence_figure(
                spec.name, spec.unit, series)
    for file_name, png in pngs.items():
        (figures_dir / file_name).write_bytes(png)
    (out / f"{definition.name}.json").write_text(json.dumps(summary, indent=1, default=float),
                                                 encoding="utf-8")
    markdown = render_markdown(summary, list(pngs))
    (out / f"{definition.name}.md").write_text(markdown, encoding="utf-8")
    (out / f"{definition.name}.html").write_text(render_html(summary, pngs), encoding="utf-8")
    table.drop(columns="source").to_csv(out / f"{definition.name}.csv", index=False)
    return summary


def _rows(summary: dict) -> list[list[str]]:
    rows = []
    for entry in summary["outputs"]:
        cap = entry["capability"]
        paper = entry["paper"] or {}
        rows.append([
            entry["name"], entry["unit"], str(cap["count"]),
            f"{_fmt(cap['mean']['value'])} [{_fmt(cap['mean']['low'], 5)}, "
            f"{_fmt(cap['mean']['high'], 5)}]",
            f"{_fmt(cap['sigma']['value'], 3)} [{_fmt(cap['sigma']['low'], 3)}, "
            f"{_fmt(cap['sigma']['high'], 3)}]",
            _fmt(paper.get("mean")), _fmt(paper.get("sigma"), 3),
            _fmt(entry.get("mean_difference_in_paper_sigmas"), 3),
            f"{_fmt(cap['minimum'])} .. {_fmt(cap['maximum'])}",
            "-" if not entry["limits"] else f"{entry['limits'][0]:g} .. {entry['limits'][1]:g}",
            _ci(cap.get("cp")), _ci(cap.get("cpk")), _fmt(cap.get("cc"), 3),
            "-" if cap.get("ppm_observed") is None else
            f"{_fmt(cap['ppm_observed'], 3)} (<= {_fmt(cap['ppm_observed_upper'], 3)}); "
            f"normal {_fmt(cap['ppm_normal'], 3)}",
        ])
    return rows


def _ci(value) -> str:
    if not value:
        return "limits not published"
    return f"{_fmt(value['value'], 3)} [{_fmt(value['low'], 3)}, {_fmt(value['high'], 3)}]"


HEADER = ["output", "unit", "ok runs", "mean [95 % CI]", "sigma [95 % CI]", "paper mean",
          "paper sigma", "(mean - paper) / paper sigma", "min .. max", "LSL .. USL",
          "Cp [CI]", "Cpk [CI]", "Cc", "PPM outside (95 % upper); normal fit"]


def _definition_lines(summary: dict) -> list[str]:
    d = summary["definition"]
    inputs = ", ".join(
        f"{i['name']} ({i['parameter']}: {i['law']}"
        + (f" {i['mean']:g} +- {i['sigma']:g}" if i["law"] == "normal" else "")
        + f" in [{i['lower']:g}, {i['upper']:g}] {i['unit']})" for i in d["inputs"])
    speed = summary["throughput"]
    return [
        f"Scene `{d['scene']}`{parameters_text(d['scene_parameters'])} in `{d['engine']}`, design "
        f"`{d['design']}`, seed {d['seed']}, {summary['samples_planned']} samples planned; "
        f"statuses: {counts_text(summary['statuses'])}."
        + (f" Runs by source: {counts_text(summary['sources'])} (given: taken from a campaign "
           "CSV)."
           if summary.get("sources", {}).get("given") else ""),
        f"Inputs: {inputs}.",
        f"Throughput (campaign log): {speed['samples']} samples in {speed['sessions']} "
        f"session(s)"
        + (f" ({speed['recovered']} stored by a killed session before it logged them, "
           "left out of the rate)" if speed.get("recovered") else "")
        + f", {_fmt(speed['samples_per_hour'], 3)} samples/hour with "
        f"{speed['workers']} worker(s), median {_fmt(speed['worker_seconds_per_sample'], 3)} "
        f"s of worker time per sample; the paper's {PAPER_RUNS} runs would take "
        f"{_fmt(summary['projection_hours_for_paper_runs'], 3)} h here (the study: "
        f"{PAPER_SECONDS_PER_RUN:g} s per run on {PAPER_CPUS} CPUs, "
        f"{_fmt(summary['paper_cluster_hours'], 3)} h).",
    ]


def render_markdown(summary: dict, figure_files: list[str]) -> str:
    """The section as Markdown (figures referenced from ``figures/``; a metamodel campaign's
    its own)."""
    if summary.get("method") == "metamodel":
        from clearbench.harness.studies.campaign import metamodel_report

        return metamodel_report.render_markdown(summary, figure_files)
    name = summary["definition"]["name"]
    lines = [f"## Tolerance campaign `{name}`", ""] + _definition_lines(summary) + [""]
    lines.append("| " + " | ".join(HEADER) + " |")
    lines.append("|" + "---|" * len(HEADER))
    for row in _rows(summary):
        lines.append("| " + " | ".join(row) + " |")
    lines += ["", "Limits: " + "; ".join(
        f"{e['name']}: {e['limits_source']}" for e in summary["outputs"]) + ".", ""]
    lines += _sensitivity_markdown(summary)
    if summary["not_ok"]:
        lines += ["", "Runs that did not end ok (counted, left out of the statistics):", ""]
        lines += [f"- sample {r['sample']} ({r['key']}): {r['status']}: {r['message']}"
                  for r in summary["not_ok"][:50]]
    lines.append("")
    lines += [f"![{f}](figures/{f})" for f in figure_files]
    return "\n".join(lines) + "\n"


def _sensitivity_markdown(summary: dict) -> list[str]:
    entries = [e for e in summary["outputs"] if "sensitivity" in e]
    if not entries:
        return []
    names = entries[0]["sensitivity"]["inputs"]
    lines = ["Sensitivities: standardised regression coefficients (SRC, with the linear fit's "
             "R^2) and the first-order index S1 (given data: SALib's delta-method estimator on all "
             "the runs) per input.", "",
             "| output | R^2 | " + " | ".join(f"{n} SRC / S1" for n in names) + " |",
             "|" + "---|" * (len(names) + 2)]
    for entry in entries:
        s = entry["sensitivity"]
        cells = [f"{_fmt(a, 2)} / {_fmt(b, 2)}" for a, b in zip(s["src"], s["s1"], strict=True)]
        lines.append(f"| {entry['name']} | {_fmt(s['r_squared'], 3)} | " + " | ".join(cells)
                     + " |")
    return lines + [""]


def section_html(summary: dict, pngs: dict[str, bytes]) -> str:
    """The section as an HTML fragment (figures embedded), for this report and the
    comparison report (a metamodel campaign's its own)."""
    if summary.get("method") == "metamodel":
        from clearbench.harness.studies.campaign import metamodel_report

        return metamodel_report.section_html(summary, pngs)
    esc = html.escape
    name = summary["definition"]["name"]
    parts = [f"<h2>Tolerance campaign <code>{esc(name)}</code></h2>"]
    parts += [f"<p>{esc(line)}</p>" for line in _definition_lines(summary)]
    parts.append("<table><thead><tr>" + "".join(f"<th>{esc(h)}</th>" for h in HEADER)
                 + "</tr></thead><tbody>")
    for row in _rows(summary):
        parts.append("<tr>" + "".join(f"<td>{esc(c)}</td>" for c in row) + "</tr>")
    parts.append("</tbody></table>")
    sensitivity = _sensitivity_markdown(summary)
    if sensitivity:
        parts.append("<pre>" + esc("\n".join(sensitivity)) + "</pre>")
    for file_name, png in pngs.items():
        parts.append(f"<figure><img alt='{esc(file_name)}' src='data:image/png;base64,"
                     f"{base64.b64encode(png).decode()}'><figcaption>{esc(file_name)}"
                     "</figcaption></figure>")
    return "\n".join(parts)


def render_html(summary: dict, pngs: dict[str, bytes]) -> str:
    """The section as a self-contained HTML page."""
    esc = html.escape
    name = summary["definition"]["name"]
    body = section_html(summary, pngs)
    return (f"<!doctype html><html><head><meta charset='utf-8'><title>{esc(name)}</title>"
            "<style>body{font-family:sans-serif;max-width:1200px;margin:auto}"
            "table{border-collapse:collapse;font-size:12px}td,th{border:1px solid #ccc;"
            "padding:2px 5px}</style></head><body>" + body + "</body></html>\n")


def load_written_sections(folder: str | Path) -> list[tuple[dict, dict[str, bytes]]]:
    """The campaign sections written by :func:`write_campaign_report` into ``folder``: each
    summary with its figures (file name -> PNG), by campaign name (a study before the
    companions named after it: ``c60-paper``, ``c60-paper-mc``, ``c60-paper-mc-identified``)."""
    folder = Path(folder)
    sections = []
    for path in sorted(folder.glob("*.json"), key=lambda path: path.stem):
        summary = json.loads(path.read_text(encoding="utf-8"))
        if "definition" not in summary or "outputs" not in summary:
            continue
        name = summary["definition"]["name"]
        table = folder / f"{name}.csv"
        if table.exists() and summary.get("method") != "metamodel":
            # the statistics by this code, from the samples as recorded
            _restate_capability(summary, table)
        pngs = {figure.name: figure.read_bytes()
                for figure in sorted((folder / "figures").glob(f"{name}_*.png"))}
        sections.append((summary, pngs))
    return sections


def _restate_capability(summary: dict, table: Path) -> None:
    """Recompute each output's capability from the per-sample CSV (its ok rows) with this
    code's statistics, so a section written by an older revision shows today's figures."""
    import pandas as pd  # lazily, as the results store does

    frame = pd.read_csv(table)
    ok = frame[frame["status"] == "ok"]
    for entry in summary["outputs"]:
        limits = entry["limits"] or (None, None)
        cap = capability(ok[entry["name"]].to_numpy(dtype=float), *limits)
        entry["capability"] = _capability_dict(cap)
