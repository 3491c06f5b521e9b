"""The report section of a metamodel campaign: validation (predicted against run, Q2), the
figures with their bootstrap intervals, Sobol' indices with error bars, the rare-event
estimates and their confirmation runs, the convergence over the stages, side by side with a
sampling campaign of the same study (its written JSON and CSV: ``--against c60-paper``).
"""

from __future__ import annotations

import base64
import html
import json
import math
from pathlib import Path

import numpy as np

from clearbench.harness.report.figures import _png, _pyplot
from clearbench.harness.studies.campaign.definition import CampaignDefinition
from clearbench.harness.studies.campaign.formatting import counts_text, parameters_text
from clearbench.harness.studies.campaign.formatting import format_number as _fmt
from clearbench.harness.studies.campaign.results import definition_summary


def _ci(interval, digits: int = 4) -> str:
    if not interval:
        return "limits not published"
    return (f"{_fmt(interval['value'], digits)} [{_fmt(interval['low'], digits)}, "
            f"{_fmt(interval['high'], digits)}]")


def _inside(value: float, interval: dict | None) -> str:
    if not interval:
        return "-"
    return "yes" if interval["low"] <= value <= interval["high"] else "no"


def _overlap(ours: dict, low: float, high: float) -> str:
    return "yes" if ours["low"] <= high and low <= ours["high"] else "no"


def summarise(definition: CampaignDefinition, state: dict, against: dict | None) -> dict:
    """The section's data: the definition, the stop, the last stage's figures per output,
    with the sampling campaign ``against`` (its written summary) beside them."""
    final = state["stages"][-1]
    reference = {e["name"]: e for e in (against or {}).get("outputs", [])}
    outputs = []
    for spec, entry in zip(definition.outputs, final["outputs"], strict=True):
        row = {key: entry[key] for key in ("name", "kind", "degree", "q2", "residual_rms",
                                             "candidates", "runs", "mean", "sigma", "cp",
                                             "cpk", "s1", "st", "interaction", "unexplained",
                                             "short")}
        row["unit"] = spec.unit
        row["limits"] = [spec.lower_limit, spec.upper_limit] if spec.has_limits else None
        theirs = reference.get(spec.name)
        if theirs is not None:
            cap = theirs["capability"]
            sens = theirs.get("sensitivity", {})
            row["against"] = {
                "count": cap["count"], "mean": cap["mean"], "sigma": cap["sigma"],
                "mean_inside": _inside(entry["mean"]["value"], cap["mean"]),
                "sigma_inside": _inside(entry["sigma"]["value"], cap["sigma"]),
                "s1": sens.get("s1"), "s1_confidence": sens.get("s1_confidence"),
                "s1_agree": [_overlap(ours, s - c, s + c) for ours, s, c in zip(
                    entry["s1"], sens.get("s1", []), sens.get("s1_confidence", []),
                    strict=False)]}
        outputs.append(row)
    return {"method": "metamodel", "definition": definition_summary(definition),
            "settings": {k: (list(v) if isinstance(v, tuple) else v) for k, v in
                         vars(definition.metamodel).items()},
            "stop": state["stop"], "runs": state["runs"], "budget": state["budget"],
            "sources": final.get("sources", {}),
            "stages": [{"size": s["size"], "runs": s["runs"], "met": s["met"],
                        "short": s["short"],
                        "outputs": [{k: o[k] for k in ("name", "kind", "degree", "q2", "mean",
                                                       "sigma", "s1", "st")}
                                    for o in s["outputs"]]} for s in state["stages"]],
            "outputs": outputs, "rare_events": state.get("rare_events"),
            "against": (against or {}).get("definition", {}).get("name")}


# ---------------------------------------------------------------------- figures
def validation_figure(final: dict, units: dict) -> bytes:
    """Validation predictions against the runs, one panel per output, Q2 in each title."""
    plt = _pyplot()
    outputs = final["outputs"]
    columns = min(3, len(outputs))
    rows = math.ceil(len(outputs) / columns)
    figure, axes = plt.subplots(rows, columns, figsize=(3.4 * columns, 3.2 * rows),
                                squeeze=False)
    for ax, entry in zip(axes.flat, outputs, strict=False):
        observed = np.asarray(entry["observed"])
        predicted = np.asarray(entry["validation_predictions"])
        ax.plot(observed, predicted, ".", markersize=3, color="#3182bd")
        low, high = float(min(observed.min(), predicted.min())), float(
            max(observed.max(), predicted.max()))
        ax.plot([low, high], [low, high], color="#636363", linewidth=0.8)
        ax.set_title(f"{entry['name']}: {entry['kind']}"
                     + (f" degree {entry['degree']}" if entry["kind"] == "chaos" else "")
                     + f", Q2 {entry['q2']:.3f}", fontsize=8)
        unit = units.get(entry["name"], "")
        ax.set_xlabel(f"run [{unit}]", fontsize=7)
        ax.set_ylabel(f"predicted, left out [{unit}]", fontsize=7)
        ax.tick_params(labelsize=6)
    for ax in list(axes.flat)[len(outputs):]:
        ax.axis("off")
    figure.tight_layout()
    return _png(figure)


def sobol_figure(entry: dict, inputs: list[str], against: dict | None) -> bytes:
    """S1 and ST of one output with their bootstrap intervals, and the sampling campaign's
    given-data S1 with its confidence half-width."""
    plt = _pyplot()
    figure, ax = plt.subplots(figsize=(5.4, 3.2))
    positions = np.arange(len(inputs))
    series = [("S1, metamodel", entry["s1"], -0.25, "#1b9e77"),
              ("ST, metamodel", entry["st"], 0.0, "#7570b3")]
    for label, values, shift, colour in series:
        centre = np.array([v["value"] for v in values])
        error = np.array([[v["value"] - v["low"] for v in values],
                          [v["high"] - v["value"] for v in values]])
        ax.bar(positions + shift, centre, width=0.25, yerr=np.maximum(error, 0), capsize=2,
               label=label, color=colour)
    if against and against.get("s1"):
        ax.bar(positions + 0.25, against["s1"], width=0.25, yerr=against["s1_confidence"],
               capsize=2, color="#d95f02",
               label=f"S1, {against['count']} runs (given data)")
    ax.set_xticks(positions, inputs)
    ax.set_ylabel("share of the variance")
    ax.set_title(f"{entry['name']}: Sobol' indices (95 % intervals)", fontsize=9)
    ax.legend(fontsize=7)
    return _png(figure)


def convergence_figure(name: str, unit: str, stages: list[dict], against: dict | None,
                       sampled: np.ndarray | None) -> bytes:
    """Mean and sigma with their intervals at each stage against the runs, the sampling
    campaign's running values and its 95 % band."""
    plt = _pyplot()
    figure, (top, bottom) = plt.subplots(2, 1, figsize=(5.2, 4.4), sharex=True)
    runs = [s["runs"] for s in stages]
    for axis, key in ((top, "mean"), (bottom, "sigma")):
        entries = [next(o for o in s["outputs"] if o["name"] == name)[key] for s in stages]
        centre = np.array([e["value"] for e in entries])
        # a point estimate may lie outside its percentile interval (few refits): no negative bar
        below = np.maximum(centre - [e["low"] for e in entries], 0.0)
        above = np.maximum([e["high"] for e in entries] - centre, 0.0)
        axis.errorbar(runs, centre, yerr=[below, above],
                      marker="o", capsize=3, color="#1b9e77", label="metamodel")
        if against:
            band = against[key]
            axis.axhspan(band["low"], band["high"], color="#fdd0a2", alpha=0.6,
                         label=f"{against['count']} runs, 95 %")
        if sampled is not None and len(sampled) > 2:
            values = sampled[: max(runs)]
            k = np.arange(1, len(values) + 1)
            series = (np.cumsum(values) / k if key == "mean" else np.array(
                [np.std(values[:i], ddof=1) if i > 1 else np.nan for i in k]))
            axis.plot(k[1:], series[1:], color="#d95f02", linewidth=0.8,
                      label="sample statistics, same runs")
        axis.set_ylabel(f"{key} [{unit}]")
    bottom.set_xlabel("runs")
    top.legend(fontsize=7)
    top.set_title(f"{name}: estimates against runs", fontsize=9)
    return _png(figure)


# ---------------------------------------------------------------------- text
def _stop_line(summary: dict) -> str:
    settings = summary["settings"]
    targets = ", ".join(f"{k} half-width <= {v:g}" + (" sigma" if k in ("mean", "sigma")
                                                      else "")
                        for k, v in settings["targets"].items()) or "none"
    last = summary["stages"][-1]
    text = (f"Stopped: **{summary['stop']}** after {summary['runs']} runs of a budget of "
            f"{summary['budget']} (stages of {', '.join(str(s['runs']) for s in summary['stages'])}"
            f" runs; design rows: {counts_text(summary['sources'])}). Targets: Q2 >= "
            f"{settings['q2']:g} ({settings['validation']}"
            + (f", {settings['folds']} folds" if settings["validation"] == "k-fold" else "")
            + f") for every output; {targets}.")
    if last["short"]:
        text += " Still short: " + "; ".join(last["short"]) + "."
    return text


def render_markdown(summary: dict, figure_files: list[str]) -> str:
    """The section as Markdown (figures referenced from ``figures/``)."""
    d = summary["definition"]
    inputs = [i["name"] for i in d["inputs"]]
    lines = [f"## Metamodel campaign `{d['name']}`", "",
             f"Scene `{d['scene']}`{parameters_text(d['scene_parameters'])} in "
             f"`{d['engine']}`, design "
             f"`{d['design']}`, seed {d['seed']}. Metamodels tried: "
             f"{', '.join(summary['settings']['candidates'])} (chaos up to total degree "
             f"{summary['settings']['max_degree']}, terms by LARS); the one with the best Q2 "
             f"is kept per output. Intervals: 95 %, {summary['settings']['bootstrap']} "
             "bootstrap refits over the design.", "", _stop_line(summary), ""]
    against = summary.get("against")
    header = ["output", "metamodel", "Q2", "mean [95 %]", "sigma [95 %]", "Cpk [95 %]",
              "1 - sum S1 [95 %]", "unexplained share"]
    if against:
        header += [f"{against}: mean [95 %]", "inside", f"{against}: sigma [95 %]", "inside"]
    lines += ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    for o in summary["outputs"]:
        unit = f" {o['unit']}" if o["unit"] else ""
        cells = [o["name"] + unit, o["kind"] + (f" {o['degree']}" if o["kind"] == "chaos"
                                                else ""), f"{o['q2']:.3f}", _ci(o["mean"]),
                 _ci(o["sigma"], 3), _ci(o["cpk"], 3), _ci(o["interaction"], 2),
                 _fmt(o["unexplained"], 2)]
        if against:
            a = o.get("against") or {}
            cells += [_ci(a.get("mean")) if a else "-", a.get("mean_inside", "-"),
                      _ci(a.get("sigma"), 3) if a else "-", a.get("sigma_inside", "-")]
        lines.append("| " + " | ".join(cells) + " |")
    lines += ["", "Sobol' indices (shares of the output's variance; first-order S1 and total "
              "ST from the metamodel, 95 % bootstrap intervals"
              + (f"; {against}'s given-data S1 +- its confidence half-width, and whether the "
                 "intervals overlap" if against else "") + "):", ""]
    lines += ["| output | index | " + " | ".join(inputs) + " |",
              "|" + "---|" * (len(inputs) + 2)]
    for o in summary["outputs"]:
        lines.append(f"| {o['name']} | S1 | " + " | ".join(_ci(v, 2) for v in o["s1"]) + " |")
        lines.append(f"| {o['name']} | ST | " + " | ".join(_ci(v, 2) for v in o["st"]) + " |")
        a = o.get("against") or {}
        if a.get("s1"):
            lines.append(f"| {o['name']} | S1 {against} | " + " | ".join(
                f"{s:.2f} +- {c:.2f} ({agree})" for s, c, agree in zip(
                    a["s1"], a["s1_confidence"], a["s1_agree"], strict=False)) + " |")
    lines += [""] + _rare_markdown(summary) + [""]
    lines += [f"![{f}](figures/{f})" for f in figure_files]
    return "\n".join(lines) + "\n"


def _rare_markdown(summary: dict) -> list[str]:
    events = summary["rare_events"]
    if events is None:
        return ["Failure probabilities: pending (the campaign stopped before its rare-event "
                "estimates and confirmation runs; run it again to complete them)."]
    if not events:
        return ["No output has specification limits: no failure probability."]
    lines = ["Failure probability outside the limits, on the metamodel with its unexplained "
             "part as a normal variable of the validation residual's RMS: FORM, and "
             "importance sampling around FORM's design point (coefficient of variation, 95 % "
             "interval p (1 +- 1.96 CV)).", "",
             "| output | side | limit | beta | P FORM | P importance sampling (CV) | "
             "true runs near the design point |", "|---|---|---|---|---|---|---|"]
    for event in events:
        for side in event["sides"]:
            runs = side.get("confirmation", [])
            if side.get("note"):
                check = f"none: {side['note']}"
            elif side["origin_fails"]:
                check = "none: the median design is outside this limit (no rare event)"
            elif not runs:
                check = "none"
            else:
                check = "; ".join(
                    f"t {r['t']:.2f}: run {_fmt(r.get('observed'))}, metamodel "
                    f"{_fmt(r['predicted'])}" for r in runs)
                verdict = side.get("confirmed")
                check += {True: " (confirmed: each within 3 residual RMS)",
                          False: " (not confirmed)", None: " (runs pending)"}[verdict]
            lines.append(f"| {event['name']} | {side['side']} | {side['limit']:g} | "
                         f"{_fmt(side['beta'], 3)} | {_fmt(side['form'], 3)} | "
                         f"{_fmt(side['importance'], 3)} ({_fmt(side['importance_cv'], 2)}) | "
                         f"{check} |")
        low, high = event["ppm_importance_interval"]
        lines.append(f"| {event['name']} | PPM | | | {_fmt(event['ppm_form'], 3)} | "
                     f"{_fmt(event['ppm_importance'], 3)} [{_fmt(low, 3)}, {_fmt(high, 3)}] "
                     "| |")
    return lines


def section_html(summary: dict, pngs: dict[str, bytes]) -> str:
    """The section as an HTML fragment (figures embedded; the Markdown's tables as text)."""
    esc = html.escape
    name = summary["definition"]["name"]
    parts = [f"<h2>Metamodel campaign <code>{esc(name)}</code></h2>",
             "<pre>" + esc(render_markdown(summary, [])) + "</pre>"]
    for file_name, png in pngs.items():
        parts.append(f"<figure><img alt='{esc(file_name)}' src='data:image/png;base64,"
                     f"{base64.b64encode(png).decode()}'><figcaption>{esc(file_name)}"
                     "</figcaption></figure>")
    return "\n".join(parts)


def write_metamodel_report(definition: CampaignDefinition, state: dict, out_dir: str | Path,
                           against: str | None = None, table=None) -> dict:
    """Write ``<name>.md``, ``.html``, ``.json`` (and the design's ``.csv`` from ``table``)
    and figures under ``out_dir``; ``against`` names a sampling campaign whose report is in
    ``out_dir`` (its JSON and CSV)."""
    import pandas as pd  # lazily, as the results store does

    out = Path(out_dir)
    figures = out / "figures"
    figures.mkdir(parents=True, exist_ok=True)
    reference = sampled = None
    if against:
        path = out / f"{against}.json"
        if not path.exists():
            raise FileNotFoundError(f"{path}: no written report of campaign {against!r}")
        reference = json.loads(path.read_text(encoding="utf-8"))
        csv = out / f"{against}.csv"
        sampled = pd.read_csv(csv).sort_values("sample") if csv.exists() else None
    summary = summarise(definition, state, reference)
    units = {o.name: o.unit for o in definition.outputs}
    final = state["stages"][-1]
    pngs = {f"{definition.name}_validation.png": validation_figure(final, units)}
    for spec, entry in zip(definition.outputs, summary["outputs"], strict=True):
        pngs[f"{definition.name}_{spec.name}_sobol.png"] = sobol_figure(
            entry, [law.name for law in definition.inputs], entry.get("against"))
        values = None
        if sampled is not None:
            ok = sampled[sampled["status"] == "ok"]
            values = ok[spec.name].to_numpy(float)
        pngs[f"{definition.name}_{spec.name}_convergence.png"] = convergence_figure(
            spec.name, spec.unit, state["stages"], entry.get("against"), values)
    for file_name, png in pngs.items():
        (figures / file_name).write_bytes(png)
    (out / f"{definition.name}.json").write_text(json.dumps(summary, indent=1, default=float),
                                                 encoding="utf-8")
    (out / f"{definition.name}.md").write_text(render_markdown(summary, list(pngs)),
                                               encoding="utf-8")
    page = section_html(summary, pngs)
    (out / f"{definition.name}.html").write_text(
        f"<!doctype html><html><head><meta charset='utf-8'><title>{html.escape(definition.name)}"
        "</title></head><body>" + page + "</body></html>\n", encoding="utf-8")
    if table is not None:
        table.to_csv(out / f"{definition.name}.csv", index=False)
    return summary
