"""The tolerance campaigns in the report: each campaign's Markdown section (the one
``clearbench campaign report`` writes, :func:`render_markdown`) as HTML: headings with ids,
paragraphs, tables with a caption (the paragraph that introduces them), lists, and its figures
two per row inside a ``<details>``, each with a caption that says what it shows."""

from __future__ import annotations

import re

from clearbench.harness.report.html_parts import esc, figure_grid, heading, slug, table
from clearbench.harness.studies.campaign.report import render_markdown

#: Figure kind (the file name's last part) -> what the figure shows.
FIGURE_KINDS = {
    "histogram": "histogram of the runs' values with the specification limits and the "
                 "normal fit",
    "convergence": "running mean and standard deviation against the number of runs (do the "
                   "estimates settle?)",
    "sobol": "Sobol' indices S1 and ST of each joint's clearance from the metamodel, with "
             "their 95 % intervals",
    "validation": "the metamodels' predictions against the runs held out (validation)",
}


def figure_caption(campaign: str, file_name: str) -> str:
    """``c60-paper_FC-1_histogram.png`` -> ``c60-paper, FC-1: histogram of ...``."""
    stem = file_name.removesuffix(".png").removeprefix(f"{campaign}_")
    output, _, kind = stem.rpartition("_")
    meaning = FIGURE_KINDS.get(kind, kind.replace("_", " "))
    return f"{campaign}{', ' + output if output else ''}: {meaning}"


def _inline(text: str) -> str:
    """Markdown's inline code and bold as HTML (the rest escaped)."""
    out = esc(text)
    out = re.sub(r"`([^`]+)`", r"<code>\1</code>", out)
    return re.sub(r"\*\*([^*]+)\*\*", r"<b>\1</b>", out)


def _cells(line: str) -> list[str]:
    parts = re.split(r"(?<!\\)\|", line.strip().strip("|"))
    return [part.strip().replace("\\|", "|") for part in parts]


def markdown_html(markdown: str, prefix: str, seen: dict[str, str] | None = None,
                  name: str = "") -> tuple[str, list[str]]:
    """(HTML, image file names) of a campaign section's Markdown: ``#`` headings (ids
    ``prefix-...``), tables (captioned by the paragraph just before, else by the heading),
    ``- `` lists and paragraphs; images are returned, not drawn. ``seen``: paragraph -> the
    campaign ``name`` that showed it first (a paragraph another campaign already showed says
    so instead of repeating it; ``seen`` is updated)."""
    seen = {} if seen is None else seen
    blocks: list[list[str]] = []
    for line in markdown.splitlines():
        if not line.strip():
            blocks.append([])
        elif blocks and blocks[-1] and (line.startswith("|") == blocks[-1][0].startswith("|")):
            blocks[-1].append(line)
        else:
            blocks.append([line])
    blocks = [b for b in blocks if b]
    parts: list[str] = []
    images: list[str] = []
    title = ""
    caption = ""         # a paragraph ending with ':' that introduces the next table
    for block in blocks:
        first = block[0]
        if first.startswith("|"):
            rows = [_cells(line) for line in block if not re.match(r"^\|[-:| ]+\|$", line)]
            parts.append(table(rows[0], [[_inline(c) for c in row] for row in rows[1:]],
                               caption=re.sub(r"[*`]", "", caption or title), raw=True))
            caption = ""
            continue
        if caption:
            parts.append(f"<p>{_inline(caption)}</p>")
            caption = ""
        if first.startswith("#"):
            level = min(4, len(first) - len(first.lstrip("#")) + 1)
            title = first.lstrip("#").strip().replace("`", "")
            parts.append(heading(level, title, f"{prefix}-{slug(title)}"))
        elif all(line.startswith("![") for line in block):
            images += [m.group(1) for line in block
                       for m in [re.search(r"\(figures/([^)]+)\)", line)] if m]
        elif first.startswith("- "):
            items = "".join(f"<li>{_inline(line[2:])}</li>" for line in block)
            parts.append(f"<ul class='small'>{items}</ul>")
        elif " ".join(block).rstrip().endswith(":"):
            caption = " ".join(block).rstrip()
        else:
            text = " ".join(block)
            if text in seen:
                first = text.split(":", 1)[0] if ":" in text[:40] else "This paragraph"
                parts.append(f"<p class='small'>{esc(first)}: as for {esc(seen[text])} "
                             "above.</p>")
            else:
                seen[text] = name
                parts.append(f"<p>{_inline(text)}</p>")
    if caption:
        parts.append(f"<p>{_inline(caption)}</p>")
    return "".join(parts), images


def campaign_html(summary: dict, pngs: dict[str, bytes], seen: dict[str, str] | None = None
                  ) -> str:
    """One campaign's section: its text and tables as HTML, its figures folded two per row.
    ``seen``: as :func:`markdown_html` (shared by the page's campaigns)."""
    name = summary["definition"]["name"]
    body, images = markdown_html(render_markdown(summary, list(pngs)), f"campaign-{slug(name)}",
                                 seen, name)
    figures = [(pngs[f], figure_caption(name, f)) for f in images if f in pngs]
    return body + figure_grid(figures, f"Figures of {name}")
