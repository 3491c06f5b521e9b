"""Number formatting shared by the campaign reports (Markdown and HTML)."""

from __future__ import annotations

import math


def format_number(value, digits: int = 4) -> str:
    """``value`` to ``digits`` significant digits.

    ``-`` for a missing value, ``nan`` for a non-finite one.
    """
    if value is None:
        return "-"
    if isinstance(value, float) and not math.isfinite(value):
        return "nan"
    return f"{value:.{digits}g}"


def counts_text(counts: dict) -> str:
    """``{'ok': 1020, 'diverged': 4}`` -> ``1020 ok, 4 diverged`` (the page's words, not a
    Python dict)."""
    return ", ".join(f"{count} {name}" for name, count in counts.items()) or "none"


def parameters_text(parameters: dict | None) -> str:
    """A scene's parameters as the command line sets them (`` with `variant=latch-0.1` ``),
    empty when there are none."""
    if not parameters:
        return ""
    return " with " + ", ".join(f"`{key}={value}`" for key, value in parameters.items())
