"""The viewer's HTML: recorded runs of one scene, side by side on one time slider.

:func:`viewer_fragment` gives a ``<div class='cb-viewer'>`` with its data (the scene's shapes,
the runs' frames) for a page that also carries :func:`viewer_scripts` once (three.js and the
viewer's script, inlined: the page needs no network); :func:`viewer_page` a whole page.
"""

from __future__ import annotations

import html
import json
import math
from dataclasses import dataclass
from functools import cache
from importlib import resources

import numpy as np

from clearbench.harness.report.viewer.frames import (
    FORCE_RANGE,
    Quantiser,
    RecordedRun,
    encode_run,
    force_scale,
    time_grid,
)
from clearbench.harness.report.viewer.scene_geometry import scene_description, scene_points
from clearbench.scenarios.scene import Scene

#: Frames of the time grid (the events' own frames added): 300 frames are 0.03 ms apart on an
#: 8.5 ms c60-trip, finer than its events are from one another (0.8-4 ms).
FRAMES = 300

CSS = """
.cb-viewer{margin:.6em 0}.cb-stage{position:relative;overflow:hidden;border:1px solid #ccc}
.cb-stage canvas{display:block}.cb-title{position:absolute;font-size:12px;padding:2px 4px;
pointer-events:none;background:rgba(255,255,255,.75)}.cb-ended{color:#b00000}
.cb-labels{position:absolute;left:0;top:0;pointer-events:none}
.cb-label{position:absolute;font-size:11px;transform:translate(-50%,-50%);padding:0 2px;
background:rgba(255,255,255,.8);border-radius:2px;white-space:nowrap}
.cb-label.joint{color:#004a80;font-weight:600}.cb-label.contact{color:#a00000;font-weight:600}
.cb-controls{display:flex;flex-wrap:wrap;gap:.6em;align-items:center;margin:.3em 0;font-size:.9em}
.cb-slider{flex:1 1 300px}
"""


@cache
def _asset(name: str) -> str:
    return resources.files("clearbench.harness.report.viewer").joinpath(name).read_text(
        encoding="utf-8")


def _inline_script(text: str) -> str:
    if "</script" in text.lower():
        raise ValueError("a script to inline contains '</script'")
    return f"<script>{text}</script>"


def viewer_scripts() -> str:
    """three.js and the viewer's script, inlined (once per page, after every viewer)."""
    return _inline_script(_asset("vendor/three-viewer.min.js")) + _inline_script(
        _asset("viewer.js"))


@dataclass(frozen=True)
class Event:
    """A named instant the viewer offers a button for (``source``: whose event it is)."""

    name: str
    time: float
    source: str


def camera(scene: Scene, runs: list[RecordedRun]) -> dict:
    """Where the camera looks from: along the world axis the bodies move least along in the
    runs (the C-60's normal to its plane of motion), never along gravity (a ball bouncing
    along z is seen from the side), up against gravity (else the next axis), a little from
    above and aside, at a distance that frames the scene."""
    points = scene_points(scene)
    centre = 0.5 * (points.min(axis=0) + points.max(axis=0))
    spread = np.ptp(points, axis=0)
    motion = np.zeros(3)
    for run in runs:
        positions = run.trajectory.positions.reshape(-1, 3)
        positions = positions[np.all(np.isfinite(positions), axis=1)]
        if len(positions):
            motion = np.maximum(motion, np.ptp(positions, axis=0))
    score = motion + 1e-3 * spread
    gravity = np.asarray(scene.gravity, dtype=float)
    candidates = [0, 1, 2]
    if np.linalg.norm(gravity) > 0:
        candidates.remove(int(np.argmax(np.abs(gravity))))
    axis = min(candidates, key=lambda k: score[k])
    if np.linalg.norm(gravity) > 0:
        up = -gravity / np.linalg.norm(gravity)
    else:
        up = np.eye(3)[(axis + 2) % 3]
    direction = np.eye(3)[axis]
    tilt = direction + 0.3 * up + 0.2 * np.cross(up, direction)
    size = float(np.linalg.norm(spread)) or 1.0
    return {"target": centre.tolist(), "direction": (tilt / np.linalg.norm(tilt)).tolist(),
            "up": up.tolist(), "distance": 1.7 * size}


def viewer_payload(scene: Scene, runs: list[RecordedRun], events: list[Event] = (),
                   frames: int = FRAMES, contacts: bool = True) -> dict:
    """The JSON a viewer is built from: scene description, time grid [T], camera, force
    scale [F], quantisation and each run's block (:mod:`.frames`)."""
    description = scene_description(scene)
    grid = time_grid(runs, frames, [e.time for e in events])
    points = scene_points(scene)
    centre = 0.5 * (points.min(axis=0) + points.max(axis=0)) if len(points) else np.zeros(3)
    quantiser = Quantiser.around(centre, description["size"])
    scale = force_scale(runs)
    force_max = FORCE_RANGE * scale
    blocks = [encode_run(scene, run, grid, quantiser, force_max, contacts) for run in runs]
    return {"scene": description, "times": [float(t) for t in grid],
            "camera": camera(scene, runs), "force_scale": scale, "force_range": FORCE_RANGE,
            "quant": {"centre": quantiser.centre.tolist(), "step": quantiser.step},
            "events": [{"name": e.name, "time": e.time, "source": e.source}
                       for e in events if math.isfinite(e.time)],
            "runs": blocks}


def _esc(value) -> str:
    return html.escape(str(value))


def _run_title(block: dict, time_unit: str) -> str:
    events = ", ".join(f"{name} {value:.3f}" for name, value in block["events"].items()
                       if value is not None)
    missing = [name for name, value in block["events"].items() if value is None]
    text = block["label"] + ("" if block["status"] == "ok" else f": {block['status']}")
    if events:
        text += f"; {events} {time_unit}"
    if missing:
        text += f"; no {', '.join(missing)}"
    if block["clamped"]:
        text += "; left the drawn box (clamped)"
    return text


def viewer_fragment(payload: dict, element_id: str, caption: str = "") -> str:
    """The viewer's HTML element for ``payload`` (:func:`viewer_payload`): the canvas, one title
    per run, the labels layer, and the controls (play, time slider, one button per event,
    contacts and labels on or off)."""
    time_unit = payload["scene"]["time_unit"]
    titles = "".join(f"<div class='cb-title'><b>{_esc(_run_title(block, time_unit))}</b>"
                     f"<div class='cb-ended'></div></div>" for block in payload["runs"])
    labels = "".join(f"<div class='cb-label {_esc(lb['kind'])}'>{_esc(lb['text'])}</div>"
                     for lb in payload["scene"]["labels"])
    events = "".join(
        f"<button type='button' class='cb-event' data-time='{e['time']!r}'>{_esc(e['name'])} "
        f"({e['time']:.3f} {_esc(time_unit)}, {_esc(e['source'])})</button>"
        for e in payload["events"])
    data = json.dumps(payload, separators=(",", ":")).replace("</", "<\\/")
    note = (f"<figcaption class='small'>{_esc(caption)}</figcaption>" if caption else "")
    return (f"<figure class='cb-viewer' id='{_esc(element_id)}'>"
            f"<div class='cb-controls'><button type='button' class='cb-play'>play</button>"
            f"<input type='range' class='cb-slider' min='0' max='0' value='0' "
            f"aria-label='time'><span class='cb-time'></span>{events}"
            f"<label><input type='checkbox' class='cb-contacts' checked> contacts and forces"
            f"</label><label><input type='checkbox' class='cb-show-labels' checked> labels"
            f"</label></div>"
            f"<div class='cb-stage'><canvas></canvas>{titles}"
            f"<div class='cb-labels'>{labels}</div></div>{note}"
            f"<script type='application/json' class='cb-viewer-data'>{data}</script></figure>")


def viewer_page(payload: dict, title: str, caption: str = "") -> str:
    """A whole self-contained page with one viewer."""
    return ("<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>"
            f"<title>{_esc(title)}</title><style>body{{font-family:system-ui,sans-serif;"
            f"margin:1em auto;max-width:1100px;padding:0 1em}}.small{{color:#555;"
            f"font-size:.85em}}{CSS}</style></head><body><h1>{_esc(title)}</h1>"
            f"{viewer_fragment(payload, 'viewer', caption)}{viewer_scripts()}</body></html>\n")
