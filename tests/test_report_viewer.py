"""The viewer: its frames decode to the recorded poses and forces, contacts sit where the
geometry puts them, the C-60's schematic labels every part, joint and contact, the C-60 page
stays under its size limit, and the page plays in headless Chromium with no console error."""

from __future__ import annotations

import base64
import gzip
import json
import math
import re

import numpy as np
import pytest

from clearbench.adapters.trajectory import RunStatus
from clearbench.harness.report import browser
from clearbench.harness.report.viewer.frames import (
    QUANT,
    RecordedRun,
    sample_indices,
    time_grid,
)
from clearbench.harness.report.viewer.payload import (
    Event,
    viewer_page,
    viewer_payload,
)
from clearbench.harness.report.viewer.scene_geometry import schematic_labels
from clearbench.kernels.quaternion import quat_from_axis_angle_batch
from clearbench.scenarios.bodies import Body, Motion
from clearbench.scenarios.contacts import ContactPair
from clearbench.scenarios.inertia import solid_sphere
from clearbench.scenarios.library import get_scene
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.shapes import Plane, Sphere

from .browser_checks import PNG_SIGNATURE, report_checks
from .synthetic_runs import c60_runs as _c60_runs
from .synthetic_runs import synthetic_trajectory as _trajectory

#: The C-60 viewer page's size limit [bytes]: three.js (0.56 MB) and six engines' c60-trip at
#: 300 frames with every one of its contact pairs carrying force in every frame (about three
#: times the pairs a real run loads at once: 14 a frame in mujoco[tuned]'s): 1.33 MB measured,
#: so a real page of six engines stays well below it.
C60_PAGE_LIMIT = 2_000_000


def _ball_on_floor() -> Scene:
    return Scene(name="ball-on-floor", description="A ball on the floor.", horizon=1.0,
                 time_step=1e-2,
                 bodies=(Body("floor", motion=Motion.FIXED, shapes=(Plane("top"),)),
                         Body("ball", mass=1.0, inertia=solid_sphere(1.0, 0.1),
                              position=(0.0, 0.0, 0.1), shapes=(Sphere("s", radius=0.1),))),
                 contacts=(ContactPair("ball_floor", "ball", "s", "floor", "top"),))


def _decode(block: dict, frames: int, bodies: int):
    """An independent reading of a run's block (frames.py's layout): poses (F, nb, 7) int16
    after adding up the differences, counts (F,), contacts (n, 7)."""
    raw = np.frombuffer(gzip.decompress(base64.b64decode(block["data"])), dtype="<i2")
    poses = np.cumsum(raw[:frames * bodies * 7].reshape(frames, bodies, 7), axis=0,
                      dtype=np.int16)
    counts = raw[frames * bodies * 7:frames * bodies * 7 + frames]
    table = raw[frames * bodies * 7 + frames:].reshape(-1, 7)
    return poses, counts, table


def test_frames_decode_to_the_recorded_poses_and_forces():
    scene = _ball_on_floor()
    times = np.linspace(0.0, 1.0, 101)
    rng = np.random.default_rng(7)
    positions = np.zeros((101, 2, 3))
    positions[:, 1] = [0.0, 0.0, 0.1] + 0.05 * rng.standard_normal((101, 3))   # [m]
    positions[:, 1, 2] = 0.1                                  # resting: touching the floor
    angles = np.linspace(0.0, 7.0, 101)                       # more than a turn: wraps
    orientations = np.zeros((101, 2, 4))
    orientations[:, 0] = [1.0, 0.0, 0.0, 0.0]
    orientations[:, 1] = quat_from_axis_angle_batch(np.tile([0.0, 1.0, 0.0], (101, 1)), angles)
    normal = np.linspace(1.0, 3.0, 101)[:, None]              # [N], every sample loaded
    force = np.zeros((101, 1, 3))
    force[:, 0, 2] = normal[:, 0]
    trajectory = _trajectory(scene, times, positions, orientations, normal, force)
    payload = viewer_payload(scene, [RecordedRun("test", trajectory)], frames=101)
    assert len(payload["times"]) == 101
    poses, counts, table = _decode(payload["runs"][0], 101, 2)
    step = payload["quant"]["step"]
    centre = np.asarray(payload["quant"]["centre"])
    decoded = centre + poses[..., :3] * step
    # each coordinate within half a quantisation step (and the step well below the scene)
    assert np.max(np.abs(decoded - positions)) <= 0.5 * step + 1e-12
    assert step < 1e-4 * 0.2
    quaternions = poses[..., 3:] / 32767
    assert np.max(np.abs(quaternions - orientations)) <= 0.5 / 32767 + 1e-9
    # One contact per frame, at the ball's lowest point (the geometry: centre - r z), its force
    # the recorded one (quantised to force_max / 32767).
    assert counts.tolist() == [1] * 101 and np.all(table[:, 0] == 0)
    point = centre + table[:, 1:4] * step
    lowest = positions[:, 1] - [0.0, 0.0, 0.1]
    assert np.max(np.abs(point - lowest)) <= step
    force_max = payload["force_range"] * payload["force_scale"]
    assert np.allclose(table[:, 6] * force_max / 32767, normal[:, 0], atol=force_max / 32767)
    assert payload["force_scale"] == pytest.approx(np.percentile(normal, 99.0))


def test_time_grid_holds_each_event_and_samples_hold_the_last_pose():
    scene = _ball_on_floor()
    times = np.array([0.0, 0.1, 0.2, 0.3])
    positions = np.zeros((4, 2, 3))
    orientations = np.tile([1.0, 0.0, 0.0, 0.0], (4, 2, 1))
    run = RecordedRun("a", _trajectory(scene, times, positions, orientations))
    grid = time_grid([run], 4, [0.15, 9.0])        # 9.0 is beyond the runs: left out
    assert 0.15 in grid and grid[-1] == 0.3 and len(grid) == 5
    assert sample_indices(times, grid).tolist() == [0, 1, 1, 2, 3]


def test_a_pose_that_flies_off_is_clamped_and_said():
    scene = _ball_on_floor()
    times = np.array([0.0, 0.1])
    positions = np.zeros((2, 2, 3))
    positions[1, 1] = [1e6, 0.0, math.nan]
    orientations = np.tile([1.0, 0.0, 0.0, 0.0], (2, 2, 1))
    run = RecordedRun("a", _trajectory(scene, times, positions, orientations,
                                       status=RunStatus.DIVERGED), status="diverged")
    block = viewer_payload(scene, [run], frames=2)["runs"][0]
    assert block["clamped"] is True
    poses, _, _ = _decode(block, 2, 2)
    assert np.max(np.abs(poses[..., :3])) <= QUANT


@pytest.fixture(scope="module")
def c60_trip():
    return get_scene("c60-trip", horizon=8.5)


def test_the_c60_schematic_labels_every_part_joint_and_contact(c60_trip):
    labels = {label.text: label for label in schematic_labels(c60_trip)}
    moving = {b.name for b in c60_trip.bodies if b.motion is not Motion.FIXED}
    assert moving <= set(labels)
    assert {f"J{k}" for k in range(1, 8)} | {"S3"} <= set(labels)
    contacts = {m.group(1) for c in c60_trip.contacts
                for m in [re.search(r"_(C\d)(?:_|$)", c.name)] if m}
    assert contacts and contacts <= set(labels)
    # J6 (rod on hook) sits at its rings: its label lies within a ring's radius of the
    # middle of the two rings' centres (the rings' placements, not the label code's points).
    hook = c60_trip.body("hook")
    rings = [s for c in c60_trip.contacts if "_J6_" in c.name
             for s in [hook.shape(c.shape_a)]]
    centre = np.mean([s.position for s in rings], axis=0)
    point = np.asarray(labels["J6"].point)
    assert labels["J6"].body == c60_trip.body_index("hook")
    assert np.linalg.norm(point[:2] - centre[:2]) <= max(s.radius for s in rings)


@pytest.fixture(scope="module")
def c60_page(c60_trip, tmp_path_factory):
    runs = _c60_runs(c60_trip, 6)
    events = [Event(name, time, runs[0].label) for name, time in runs[0].events.items()]
    payload = viewer_payload(c60_trip, runs, events)
    path = tmp_path_factory.mktemp("viewer") / "c60-trip.html"
    path.write_text(viewer_page(payload, "c60-trip"), encoding="utf-8")
    return path, payload


def test_the_c60_viewer_page_stays_under_its_size_limit(c60_page):
    path, payload = c60_page
    assert len(payload["runs"]) == 6 and len(payload["times"]) >= 300
    # every pair drawn in every frame: the worst case the limit is stated for
    # (41 of the 45 pairs give a contact point in these turned poses: 9,300 of 13,500)
    assert all(block["contacts"] > 300 * 30 for block in payload["runs"])
    assert path.stat().st_size < C60_PAGE_LIMIT, path.stat().st_size
    # self-contained: no address outside the page
    assert not re.search(r"""(src|href)=['"](https?:|//|file:)""", path.read_text())


needs_chromium = pytest.mark.skipif(
    browser.chromium() is None, reason="Debian's chromium is not installed (the Makefile's "
    "test target installs it when run as root)")


@needs_chromium
def test_the_c60_viewer_plays_in_headless_chromium(c60_page, tmp_path):
    """The page `clearbench view` writes, opened at the opening (``?view-event=opening``):
    no console message; its first and last frames differ, the slider moved to the middle
    shows a third picture, each event's button its own (tests/browser/page_checks.js)."""
    path, payload = c60_page
    checks, errors = report_checks(path, tmp_path, query="?view-event=opening")
    assert not errors, errors
    (viewer,) = checks["viewers"]
    assert viewer["ready"] == "true" and viewer["frames"] == len(payload["times"])
    assert viewer["differ"] and viewer["middle"]["differ"] and viewer["eventsDiffer"]
    assert set(viewer["events"]) == {"strike", "release", "opening"}
    assert viewer["start"] == viewer["events"]["opening"]


def test_view_writes_a_page_of_the_stored_runs(tmp_path, capsys):
    """`clearbench view`: a scene's stored runs (per engine its finest step), or one run by a
    key prefix; a scene, run or engine the store does not have exits with status 2 naming it."""
    from clearbench.harness.cli.main import main
    from clearbench.harness.run.runner import Runner
    from clearbench.harness.run.spec import make_run_spec
    from clearbench.harness.run.store import ResultsStore

    from .harness_helpers import FAKE

    store = ResultsStore(tmp_path / "store")
    specs = [make_run_spec("bouncing-ball-e0.5", "fake", time_step=dt, horizon=0.2,
                           extra_engine_modules=FAKE) for dt in (1e-3, 5e-4)]
    Runner(store, jobs=1, runs_per_worker=5).run_all(specs)
    out = tmp_path / "view.html"
    common = ["--store", str(store.directory), "--out", str(out)]
    assert main(["view", "bouncing-ball-e0.5", *common, "--frames", "50"]) == 0
    page = out.read_text()
    payload = json.loads(re.search(r"class='cb-viewer-data'>(.*?)</script>", page).group(1)
                         .replace("<\\/", "</"))
    assert [run["label"] for run in payload["runs"]] == ["fake[default] dt 0.0005 s"]
    assert len(payload["times"]) == 50 and "three.js" not in capsys.readouterr().err
    key = store.dataframe()["key"].iloc[0]
    assert main(["view", key[:8], *common]) == 0
    for argument, named in (("nosuch", "'nosuch'"), (key[:3] + "zzz", "zzz")):
        assert main(["view", argument, *common]) == 2
        assert named in capsys.readouterr().err
    assert main(["view", "bouncing-ball-e0.5", "-e", "mujoco", *common]) == 2
    assert "--engines 'mujoco': no run of bouncing-ball-e0.5" in capsys.readouterr().err
    assert main(["view", "bouncing-ball-e0.5", "--dt", "-1", *common]) == 2


def test_the_docs_screenshots_start_at_their_section():
    from tools.report_screenshots import SHOTS, starting_at

    page = ("<html><body><h1>t</h1><p>a</p><h2 id='conclusions'>C</h2><figure "
            "class='cb-viewer' id='c60-viewer'></figure><script>three</script>"
            "<script>viewer</script></body></html>")
    shortened = starting_at(page, "c60-viewer")
    # the hiding script runs before three.js and the viewer's script
    assert shortened.index("getElementById('c60-viewer')") < shortened.index("<script>three")
    assert starting_at(page, "") == page
    assert {name for name, *_ in SHOTS} == {
        "report-first-screen.png", "report-conclusions.png", "viewer-strike.png",
        "viewer-release.png", "viewer-opening.png"}


def test_time_series_keep_the_finished_runs_readable(c60_trip):
    """Every engine on one plot per quantity: the y range holds the finished runs, so a run
    that diverged (here its hook turned 1e6 degrees) leaves the plot instead of squashing
    the others; the figure marks the trip's events."""
    from clearbench.harness.c60.cross_engine import C60RunFigures
    from clearbench.harness.report.c60_motion import (
        ShownRun,
        motion_series,
        readable_limits,
        time_series_figure,
    )

    calm = np.sin(np.linspace(0, 3, 50))
    wild = calm.copy()
    wild[-5:] = 1e6
    low, high = readable_limits([(calm, True), (wild, False)])
    assert low == pytest.approx(calm.min() - 0.08 * np.ptp(calm))
    assert high == pytest.approx(calm.max() + 0.08 * np.ptp(calm))
    assert readable_limits([(wild, False)])[1] > 1e6     # nothing finished: every curve

    runs = _c60_runs(c60_trip, 2)
    shown = []
    for k, (run, status) in enumerate(zip(runs, ("ok", "diverged"), strict=True)):
        figures = C60RunFigures(key=f"k{k}", scene_name="c60-trip", label=f"engine{k}[default]",
                                engine_version="x", time_step=1e-3, horizon=8.5, status=status,
                                message="", strike=3.1, release=6.8, opening=7.6)
        shown.append(ShownRun(figures, run.trajectory))
    series = motion_series(c60_trip, shown[0].trajectory)
    assert list(series) == ["hook angle [deg]", "tripping-bar angle [deg]", "C7 gap [mm]",
                            "FC-1: C7 force [N]"]
    hook = c60_trip.body_index("hook")
    # the synthetic hook turns by 20 deg sin(...) about z: its angle since t = 0, in degrees
    expected = 20 * np.sin(np.linspace(0.0, 8.5, 851) * (1 + 0.3 * hook))
    assert np.allclose(series["hook angle [deg]"], expected, atol=1e-6)
    png = time_series_figure(c60_trip, shown)
    assert png is not None and png.startswith(PNG_SIGNATURE)
