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
