"""The pieces every section of the report's page is written with: escaped text, a table
with its caption, figures two per row inside a ``<details>``, headings with ids (the table of
contents lists them)."""

from __future__ import annotations

import base64
import html
import math
import re
from collections.abc import Sequence

from clearbench.scenarios.units import LENGTH_UNITS


def esc(value) -> str:
    return html.escape(str(value))


def slug(text: str) -> str:
    """An id for a heading: lower case, runs of other characters as one ``-``."""
    return re.sub(r"[^a-z0-9]+", "-", str(text).lower()).strip("-") or "section"


def length_text(value: float, unit: str) -> str:
    """A length given in ``unit`` (a key of :data:`~clearbench.scenarios.units.LENGTH_UNITS`)
    in the unit that reads best: m from 1 m up, mm from 0.1 mm, µm below (``7.2e-04 mm``
    reads as ``0.72 µm``, ``4.83e-05 m`` as ``48.3 µm``); "—" when missing."""
    if value is None or not math.isfinite(value):
        return "—"
    metres = value * LENGTH_UNITS[unit]
    if metres == 0:
        return "0"
    if abs(metres) >= 1.0:
        return f"{metres:.3g} m"
    if abs(metres) >= 1e-4:
        return f"{1e3 * metres:.3g} mm"
    micrometres = 1e6 * metres
    return f"{micrometres:.3g} µm" if abs(micrometres) >= 1e-3 else f"{micrometres:.1e} µm"


def heading(level: int, text: str, ident: str | None = None) -> str:
    """``<hN id=...>``: every heading of the page has an id (the table of contents links
    them)."""
    return f"<h{level} id='{esc(ident or slug(text))}'>{esc(text)}</h{level}>"


def table(head: Sequence[str], rows: Sequence[Sequence[str]], caption: str = "",
          raw: bool = False, css_class: str = "", numeric: Sequence[int] = ()) -> str:
    """An HTML table: ``head`` cells, ``rows`` of cells (escaped unless ``raw``: already HTML),
    a ``caption`` above it; columns ``numeric`` right-aligned."""
    cell = (lambda value: str(value)) if raw else esc
    header = "".join(f"<th>{esc(h)}</th>" for h in head)
    number = " class='num'"
    body = "".join(
        "<tr>" + "".join(f"<td{number if k in numeric else ''}>{cell(value)}</td>"
                         for k, value in enumerate(row)) + "</tr>"
        for row in rows)
    cls = f" class='{esc(css_class)}'" if css_class else ""
    title = f"<caption>{esc(caption)}</caption>" if caption else ""
    return f"<div class='scroll'><table{cls}>{title}<thead><tr>{header}</tr></thead>" \
           f"<tbody>{body}</tbody></table></div>"


def png_figure(png: bytes, caption: str, alt: str = "") -> str:
    """A figure with the PNG embedded and its caption."""
    data = base64.b64encode(png).decode("ascii")
    return (f"<figure><img alt='{esc(alt or caption)}' src='data:image/png;base64,{data}'>"
            f"<figcaption class='small'>{esc(caption)}</figcaption></figure>")


def figure_grid(figures: Sequence[tuple[bytes, str]], summary: str, open_: bool = False) -> str:
    """Figures (PNG, caption) two per row inside a ``<details>`` whose summary says what
    they are; empty when there is none."""
    if not figures:
        return ""
    cells = "".join(png_figure(png, caption) for png, caption in figures)
    return (f"<details{' open' if open_ else ''}><summary>{esc(summary)} ({len(figures)})"
            f"</summary><div class='figs'>{cells}</div></details>")
