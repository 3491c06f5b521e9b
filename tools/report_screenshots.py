"""Screenshots of the comparison report for the docs, in headless Chromium: the first screen,
the conclusions, and the C-60 viewer at the reference's strike, release and opening.

    python -m tools.report_screenshots [--report reports/out/report.html] [--out docs/images]

Run it after ``make demo`` (which writes the report); it overwrites ``report-first-screen.png``,
``report-conclusions.png`` and ``viewer-strike.png``, ``viewer-release.png``,
``viewer-opening.png`` in ``--out``.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

from clearbench.harness.report import browser

#: (file, query, the element scrolled to the top (none: the first screen), window width and
#: height [CSS px]) of each screenshot.
SHOTS = (
    ("report-first-screen.png", "", "", 1366, 768),
    ("report-conclusions.png", "", "conclusions", 1366, 900),
    ("viewer-strike.png", "?view-event=strike", "c60-viewer", 1366, 900),
    ("viewer-release.png", "?view-event=release", "c60-viewer", 1366, 900),
    ("viewer-opening.png", "?view-event=opening", "c60-viewer", 1366, 900),
)
#: Appended to a copy of the page: the page's blocks before the one that holds the element
#: are hidden, so that the screenshot starts at it (headless Chromium's screenshot does not
#: follow a scroll).
SCROLL = ("<script>(() => {{ let e = document.getElementById('{target}');"
          "while (e && e.parentElement !== document.body) e = e.parentElement;"
          "for (let p = e && e.previousElementSibling; p; p = p.previousElementSibling)"
          " p.style.display = 'none'; }})();</script>")


def starting_at(page: str, target: str) -> str:
    """``page`` with :data:`SCROLL` for ``target`` inserted before the page's own scripts (the
    viewer then lays out in the shortened page); unchanged for no target."""
    if not target:
        return page
    if "class='cb-viewer'" in page:   # three.js and the viewer's script close the page
        cut = page.rfind("<script>", 0, page.rfind("<script>"))
    else:
        cut = page.rfind("</body>")
    return page[:cut] + SCROLL.format(target=target) + page[cut:]


def take(report: Path, out: Path) -> list[Path]:
    """Write every screenshot of :data:`SHOTS` of ``report`` into ``out``.

    Raises
    ------
    browser.BrowserError
        Chromium is missing or failed, or the page logged a console message.
    """
    if not report.is_file():
        raise FileNotFoundError(f"--report {report}: no such file (run `make demo` first)")
    out.mkdir(parents=True, exist_ok=True)
    page = report.read_text(encoding="utf-8")
    written = []
    with tempfile.TemporaryDirectory(prefix="clearbench-shots-") as folder:
        for name, query, target, width, height in SHOTS:
            copy = Path(folder) / f"{target or 'top'}.html"
            if not copy.exists():
                copy.write_text(starting_at(page, target), encoding="utf-8")
            errors = browser.screenshot(copy.as_uri() + query, out / name, width, height)
            if errors:
                raise browser.BrowserError(f"{name}: the page logged {errors}")
            written.append(out / name)
    return written


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--report", default="reports/out/report.html", type=Path)
    parser.add_argument("--out", default="docs/images", type=Path)
    args = parser.parse_args(argv)
    try:
        for path in take(args.report, args.out):
            print(path)
    except (FileNotFoundError, browser.BrowserError) as error:
        print(f"report_screenshots: {error}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
