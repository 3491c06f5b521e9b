"""Headless Chromium for the report: screenshots of a page (the docs' pictures of the report
and the viewer) and the DOM after its scripts ran (the browser tests), with the flags that work
as root, offline, with software WebGL (Debian's chromium)."""

from __future__ import annotations

import shutil
import subprocess
import tempfile
from pathlib import Path

#: How long the page's timers may run (virtual time) before the screenshot or the DOM dump
#: [ms]: the viewer decompresses its frames and draws within a second.
VIRTUAL_TIME_MS = 10_000
#: Wall-clock limit of one Chromium call [s] (a loaded 2-core machine).
TIMEOUT_S = 180


class BrowserError(RuntimeError):
    """Chromium is missing or failed (its exit status and the end of its stderr)."""


def chromium() -> str | None:
    """The Chromium executable on PATH (Debian's ``chromium``), or None."""
    return shutil.which("chromium") or shutil.which("chromium-browser")


def flags(profile: Path, width: int, height: int) -> list[str]:
    """Headless flags: no sandbox (root), software WebGL, no network of Chromium's own, a
    fresh profile, console messages on stderr."""
    return ["--headless", "--no-sandbox", "--disable-gpu", "--enable-unsafe-swiftshader",
            "--use-angle=swiftshader", "--disable-quic", "--no-first-run",
            "--disable-background-networking", "--disable-component-update", "--disable-sync",
            "--hide-scrollbars", f"--user-data-dir={profile}", "--enable-logging=stderr",
            "--v=0", f"--window-size={width},{height}",
            f"--virtual-time-budget={VIRTUAL_TIME_MS}"]


def _run(arguments: list[str]) -> subprocess.CompletedProcess:
    browser = chromium()
    if browser is None:
        raise BrowserError("chromium is not installed (Debian's package chromium)")
    with tempfile.TemporaryDirectory(prefix="clearbench-chromium-") as profile:
        done = subprocess.run([browser, *flags(Path(profile), *arguments[:2]), *arguments[2:]],
                              capture_output=True, text=True, timeout=TIMEOUT_S)
    if done.returncode != 0:
        raise BrowserError(f"chromium exited with {done.returncode}: {done.stderr[-2000:]}")
    return done


def page_errors(stderr: str) -> list[str]:
    """The page's console messages and load failures in Chromium's log (the GPU driver's
    performance notes about reading pixels back, which a screenshot causes, left out)."""
    return [line for line in stderr.splitlines()
            if ("CONSOLE" in line or "Uncaught" in line or "Failed to load" in line)
            and "GL Driver Message" not in line]


def screenshot(url: str, out: str | Path, width: int = 1366, height: int = 900) -> list[str]:
    """Write a PNG of ``url`` at ``width`` x ``height`` CSS pixels to ``out``; the page's
    console messages (:func:`page_errors`)."""
    done = _run([width, height, f"--screenshot={Path(out).resolve()}", url])
    return page_errors(done.stderr)


def dump_dom(url: str, width: int = 1366, height: int = 900) -> tuple[str, list[str]]:
    """The DOM of ``url`` after its scripts ran, and the page's console messages."""
    done = _run([width, height, "--dump-dom", url])
    return done.stdout, page_errors(done.stderr)
