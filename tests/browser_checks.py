"""The browser tests' helper: a copy of a page with tests/browser/page_checks.js appended,
opened in headless Chromium, and what that script measured (layout, links, viewers)."""

from __future__ import annotations

import html
import json
import re
from pathlib import Path

from clearbench.harness.report import browser

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
CHECKS = Path(__file__).resolve().parent / "browser" / "page_checks.js"


def report_checks(page: Path, tmp_path: Path, width: int = 1366, query: str = ""
                  ) -> tuple[dict, list[str]]:
    """(measurements of page_checks.js, the page's console messages) of ``page`` opened with
    ``query`` (e.g. ``?view-event=opening``) in a window ``width`` CSS pixels wide."""
    text = page.read_text(encoding="utf-8")
    copy = tmp_path / f"checked-{page.name}"
    script = f"<script>{CHECKS.read_text(encoding='utf-8')}</script>"
    copy.write_text(text.replace("</body>", script + "</body>"), encoding="utf-8")
    dom, errors = browser.dump_dom(copy.as_uri() + query, width, 900)
    found = re.search(r'<body[^>]*data-check="([^"]*)"', dom)
    assert found, "the checks did not run: " + dom[:500]
    return json.loads(html.unescape(found.group(1))), errors
