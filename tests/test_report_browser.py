"""The report read in headless Chromium, built once for every test of this module: six engines
on three library scenes (two of them with a second preset on one scene, one scene left out for
one engine), a run the independent instrument flagged, and the six engines' recorded c60-trip
(synthetic motions, so the C-60 section has its viewer). page_checks.js measures the page once;
each test asserts one thing a reader needs: the overview fits the 1,100 px column, 'not run'
is at most 10 % of its cells, no text block is wider than the page, the table of contents
resolves, the viewer plays (the slider and each event change the picture) with no console
error, and every cell shows the verdict the store implies (the viewer opening at an event
named in the address: tests/test_report_viewer.py, on the page `clearbench view` writes)."""

from __future__ import annotations

import fcntl
import hashlib
import html
import json
import math
import shutil
from types import SimpleNamespace

import pytest

from clearbench.harness.report import browser
from clearbench.harness.report.page import write_report
from clearbench.harness.run.runner import Runner
from clearbench.harness.run.spec import make_run_spec
from clearbench.harness.run.store import COLUMNS, ResultsStore, RunRecord

from .browser_checks import report_checks
from .synthetic_runs import TRIP_EVENTS, c60_runs

pytestmark = pytest.mark.skipif(
    browser.chromium() is None, reason="Debian's chromium is not installed (the Makefile's "
    "test target installs it when run as root)")

#: Engines of the store: the fake engine under six names (the demo's six engines).
ENGINES = {name: "tests.fake_engine"
           for name in ("reference", "alpha", "beta", "gamma", "delta", "epsilon")}
LIBRARY = ("bouncing-ball-e0.5", "pendulum", "clearance-pendulum")
#: The run the instrument flagged (its figures and reason as the run-wide check stores them).
UNSEEN_RUN = ("bouncing-ball-e0.5", "gamma")
UNSEEN_REASON = ("unseen penetration: ball_floor at t = 0.1 s: the instrument witnesses "
                 "0.002 m, the kernel's figure is 0 m")
#: Samples of each synthetic c60-trip (8.5 ms): enough for the events to be a sample apart.
TRIP_SAMPLES = 171


def _flag_unseen(store: ResultsStore, folder) -> None:
    """Give the UNSEEN_RUN run the figures of an unseen penetration."""
    frame = store.dataframe(expand_metrics=False)
    scene, engine = UNSEEN_RUN
    key = frame[(frame["scene_name"] == scene) & (frame["label"] == f"{engine}[default]")][
        "key"].iloc[0]
    row = store.get(key)
    figures = json.loads(row["metrics"] or "{}")
    figures.update(unseen_penetration=0.002, unseen_penetration_time=0.1,
                   instrument_penetration_max=0.002)
    row.update(metrics=json.dumps(figures, sort_keys=True), verdict_reason=UNSEEN_REASON)
    kept = folder / "unseen.npz"
    shutil.copy(store.trajectory_path(key), kept)   # record() moves the file into the store
    store.record(RunRecord(**{c: row[c] for c in COLUMNS}), kept, replace=True)


def _record_c60_trip(store: ResultsStore, folder) -> None:
    """Each engine's c60-trip at dt 1 us: a synthetic recording (every moving body turning at
    its own pace, the trip's forces switching at TRIP_EVENTS) stored as a finished run."""
    spec = make_run_spec("c60-trip", "reference", time_step=1e-3, horizon=8.5,
                         extra_engine_modules=ENGINES)
    template = store.get(store.dataframe(expand_metrics=False)["key"].iloc[0])
    recordings = c60_runs(spec.scene, len(ENGINES), TRIP_SAMPLES, trip=True)
    for k, (name, run) in enumerate(zip(ENGINES, recordings, strict=True)):
        path = folder / f"c60-trip-{name}.npz"
        run.trajectory.save(path)
        row = dict(template, key=hashlib.sha256(f"c60-trip {name}".encode()).hexdigest()[:24],
                   campaign="c60", scene_name="c60-trip", scene_hash=spec.scene.content_hash,
                   scene_source=json.dumps(spec.source.to_dict(), sort_keys=True),
                   engine=name, preset="default", time_step=1e-3, horizon=8.5, status="ok",
                   message="", engine_status="ok", steps=8500, samples=TRIP_SAMPLES,
                   stepping_seconds=10.0 * (k + 1), stepping_seconds_per_step=(k + 1) / 850,
                   stepping_seconds_per_simulated_second=(k + 1) / 0.85, error=math.nan,
                   expectations_passed=None, metrics="{}", expectations="[]",
                   verdict_reason="")
        store.record(RunRecord(**{c: row[c] for c in COLUMNS}), path, scene=spec.scene)


def _build(folder) -> None:
    """The store, the report and page_checks.js's measurements (checks.json) in ``folder``."""
    store = ResultsStore(folder / "store")
    specs = [make_run_spec(scene, name, horizon=0.2, extra_engine_modules=ENGINES)
             for scene in LIBRARY for name in ENGINES if (scene, name) != ("pendulum", "epsilon")]
    specs += [make_run_spec("bouncing-ball-e0.5", f"{name}[energy]", horizon=0.2,
                            extra_engine_modules=ENGINES) for name in ("alpha", "beta")]
    Runner(store, jobs=2, runs_per_worker=20).run_all(specs)
    _flag_unseen(store, folder)
    _record_c60_trip(store, folder)
    paths = write_report(store, folder / "out", c60_validation=None, campaigns=None)
    checks, errors = report_checks(paths["html"], folder)
    (folder / "checks.json").write_text(json.dumps({"checks": checks, "errors": errors}))


@pytest.fixture(scope="module")
def report(tmp_path_factory, worker_id):
    """The report built and measured once per test session: pytest-xdist's workers share the
    first one's (its documented pattern: a folder beside the workers' own, under a lock), so
    a module split between workers does not build it twice."""
    root = tmp_path_factory.getbasetemp()
    if worker_id != "master":
        root = root.parent
    folder = root / "report-browser"
    with open(root / "report-browser.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)      # released when the file closes
        if not (folder / "checks.json").exists():
            shutil.rmtree(folder, ignore_errors=True)
            folder.mkdir()
            _build(folder)
    measured = json.loads((folder / "checks.json").read_text())
    page = folder / "out" / "report.html"
    return SimpleNamespace(store=ResultsStore(folder / "store"), html=page,
                           checks=measured["checks"], errors=measured["errors"],
                           page=page.read_text(encoding="utf-8"))


def test_the_page_logs_no_console_message(report):
    assert report.errors == []


def test_the_overview_fits_the_column(report):
    assert report.checks["column"] <= 1100
    assert report.checks["matrix"] <= report.checks["column"], report.checks


def test_not_run_is_at_most_a_tenth_of_the_matrix(report):
    # four scenes (the three library scenes and c60-trip) by six engines; pendulum was not
    # given to epsilon
    assert report.checks["cells"] == 4 * 6
    assert report.checks["notRun"] == 1 and report.checks["notRun"] <= 0.1 * report.checks["cells"]


def test_no_text_block_is_wider_than_the_page(report):
    assert report.checks["pageScroll"] <= 0
    assert report.checks["wide"] == [], report.checks["wide"]


def test_the_table_of_contents_resolves(report):
    assert report.checks["tocLinks"] >= 5
    assert report.checks["broken"] == []


def test_the_viewer_plays(report):
    """The C-60 viewer: ready, its first and last frames differ, the slider moved to the middle
    shows a third picture, each event's button shows its instant with a picture of its own."""
    (viewer,) = report.checks["viewers"]
    assert viewer["ready"] == "true" and viewer["frames"] >= TRIP_SAMPLES
    assert viewer["differ"] and viewer["middle"]["differ"]
    assert viewer["middle"]["frame"] == (viewer["frames"] - 1) // 2
    assert viewer["width"] > 500     # laid out in the page's column, not collapsed
    # The reference's events happen where its forces switch (and, for the opening, C7's gap
    # is open: the synthetic turning opens it): a viewer frame apart at most, 8.5 ms / 302.
    events = viewer["events"]
    assert set(events) == set(TRIP_EVENTS)
    for name, time in events.items():
        assert abs(time - TRIP_EVENTS[name]) <= 8.5 / (viewer["frames"] - 1), (name, time)
    assert viewer["eventsDiffer"]


#: The verdict of a run that did not finish, by its status.
NOT_FINISHED = {"diverged": "diverged", "crashed": "crashed", "timed_out": "timed out",
                "unsupported": "unsupported"}


def _verdict(row) -> str:
    """A stored run's verdict read from the store alone (not the report's code): its status;
    for a finished run an unseen penetration among its figures, else its expectations."""
    if row["status"] != "ok":
        return NOT_FINISHED[row["status"]]
    if json.loads(row["metrics"] or "{}").get("unseen_penetration", 0) > 0:
        return "unseen penetration"
    passed = [r["passed"] for r in json.loads(row["expectations"] or "[]")
              if r["passed"] is not None]
    return "no check" if not passed else "pass" if all(passed) else "physics failed"


def _expected_cells(store: ResultsStore) -> dict[str, str]:
    """scene|engine -> the verdicts of its lines (the default preset first), from the store
    (one run per scene and label: each has one step)."""
    frame = store.dataframe(expand_metrics=False)
    cells: dict[str, list] = {}
    for _, row in frame.iterrows():
        engine, _, preset = row["label"].rstrip("]").partition("[")
        cells.setdefault(f"{row['scene_name']}|{engine}", []).append(
            ((preset != "default", row["label"]), _verdict(row)))
    expected = {cell: ",".join(v for _, v in sorted(lines)) for cell, lines in cells.items()}
    expected["pendulum|epsilon"] = "not run"
    return expected


def test_every_cell_shows_the_verdict_the_store_implies(report):
    assert report.checks["matrixCells"] == _expected_cells(report.store)
    # the unseen penetration is a verdict of its own, its finding in the cell
    assert report.checks["matrixCells"]["bouncing-ball-e0.5|gamma"] == "unseen penetration"
    finding = UNSEEN_REASON.removeprefix("unseen penetration: ")
    overview = report.page[report.page.index("id='overview-matrix'"):]
    assert html.escape(finding) in overview[:overview.index("</table>")]
    # and the conclusions count it among gamma's library verdicts
    conclusions = report.page[report.page.index("<h2 id='conclusions'>"):
                              report.page.index("<h2 id='overview'>")]
    gamma = conclusions[conclusions.index("gamma[default]"):]
    assert "1 unseen penetration" in gamma[:gamma.index("</tr>")]


def test_the_synthetic_runs_are_what_the_page_shows(report):
    """The fixture's own premise: six finished c60-trip runs reach the C-60 section."""
    frame = report.store.dataframe(expand_metrics=False)
    trips = frame[frame["scene_name"] == "c60-trip"]
    assert len(trips) == len(ENGINES) and set(trips["status"]) == {"ok"}
    assert "id='c60-viewer'" in report.page

