"""The report renders from a small store, is self-contained, and opens in headless Chromium."""

from __future__ import annotations

import base64
import html
import json
import re

import numpy as np
import pandas as pd
import pytest

from clearbench.harness.cli.main import main
from clearbench.harness.measure.verdicts import VERDICTS, run_verdict
from clearbench.harness.report.figures import work_precision_figure
from clearbench.harness.report.page import write_report
from clearbench.harness.run.runner import Runner
from clearbench.harness.run.spec import make_run_spec
from clearbench.harness.run.store import ResultsStore
from clearbench.harness.studies.sweep import pareto_front, work_precision_points
from clearbench.scenarios.bodies import Body
from clearbench.scenarios.expectations import Expectation
from clearbench.scenarios.inertia import solid_sphere
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.shapes import Sphere

from .harness_helpers import FAKE

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def _resting_block() -> Scene:
    """A ball at rest without gravity that must not move (a ``sticks`` expectation)."""
    return Scene(name="resting-block", description="A ball at rest, no gravity: it stays.",
                 gravity=(0.0, 0.0, 0.0), horizon=0.3, time_step=1e-3,
                 bodies=(Body("ball", mass=1.0, inertia=solid_sphere(1.0, 0.1),
                              shapes=(Sphere("sphere", radius=0.1),)),),
                 expectations=(Expectation("still", kind="sticks", body="ball",
                                          parameters={"start_time": 0.0, "end_time": 0.3}),))


@pytest.fixture(scope="module")
def small_store(tmp_path_factory):
    """A store with ok, diverged, crashed and unsupported runs over a few scenes."""
    directory = tmp_path_factory.mktemp("store")
    store = ResultsStore(directory)
    specs = [make_run_spec("bouncing-ball-e0.5", "fake", time_step=dt, horizon=0.3,
                           extra_engine_modules=FAKE, campaign="sweep") for dt in (1e-3, 5e-4)]
    specs += [
        make_run_spec("torque-free-flip", "fake[nan]", horizon=0.3, extra_engine_modules=FAKE),
        make_run_spec("pendulum", "fake[segfault]", horizon=0.3, extra_engine_modules=FAKE),
        make_run_spec("clearance-pendulum", "fake", horizon=0.3, extra_engine_modules=FAKE),
        make_run_spec("stiff-spring", "fake", horizon=0.3, extra_engine_modules=FAKE),
        # Finishes (status ok) but fails its physics: the fake engine's bias moves a body
        # that must stay still.
        make_run_spec(_resting_block(), "fake", options={"bias": 0.01},
                      extra_engine_modules=FAKE),
    ]
    Runner(store, jobs=2).run_all(specs)
    return store


def test_report_writes_html_and_markdown(small_store, tmp_path):
    paths = write_report(small_store, tmp_path / "out")
    page = paths["html"].read_text()
    summary = paths["markdown"].read_text()
    for scene in ("bouncing-ball-e0.5", "torque-free-flip", "pendulum", "clearance-pendulum",
                  "stiff-spring"):
        assert scene in page and scene in summary
    for status in ("ok", "diverged", "crashed", "unsupported"):
        assert status in page
    assert "Stiff and extreme suite" in page and "Overview" in page
    assert "SIGSEGV" in page  # the crash's message is shown
    assert "clearance_joints" in page  # the fake engine's stated limitation
    # Self-contained: no external resource of any kind.
    assert not re.search(r"""(src|href)=['"](https?:|//|file:)""", page)
    for encoded in re.findall(r"data:image/png;base64,([A-Za-z0-9+/=]+)", page):
        assert base64.b64decode(encoded).startswith(PNG_SIGNATURE)


def test_report_command(small_store, tmp_path, capsys):
    out = tmp_path / "report"
    assert main(["report", "--store", str(small_store.directory), "--out", str(out)]) == 0
    assert (out / "report.html").exists() and (out / "summary.md").exists()
    assert main(["report", "--store", str(tmp_path / "empty"), "--out", str(out)]) == 2
    assert "no results store" in capsys.readouterr().err


#: status of a run -> its verdict, for every status but ok.
NOT_FINISHED = {"diverged": "diverged", "crashed": "crashed", "timed_out": "timed out",
                "unsupported": "unsupported"}


def _expected_verdicts(store) -> dict:
    """(scene, engine label) -> the verdict the overview must show, from the store alone: the
    run at the scene's own step; its status, and for a finished run its expectations; and
    (scene, engine) -> 'not run' for an engine with no run of the scene."""
    frame = store.dataframe()
    expected = {(scene, label.partition("[")[0]): "not run"
                for scene in frame["scene_name"].unique() for label in frame["label"].unique()}
    for (scene_name, label), runs in frame.groupby(["scene_name", "label"]):
        expected.pop((scene_name, label.partition("[")[0]), None)
        step = store.scene(runs.iloc[-1]["scene_hash"]).time_step
        row = runs.iloc[int(np.argmin(np.abs(np.log(runs["time_step"] / step))))]
        if row["status"] != "ok":
            verdict = NOT_FINISHED[row["status"]]
        else:
            passed = [r["passed"] for r in json.loads(row["expectations"] or "[]")
                      if r["passed"] is not None]
            verdict = "no check" if not passed else "pass" if all(passed) else "physics failed"
        expected[(scene_name, label)] = verdict
    return expected


MATRIX_CELL = re.compile(r"""<td class=["']verdict[^"']*["'] data-scene=["']([^"']+)["'] """
                         r"""data-engine=["']([^"']+)["'] data-verdict=["']([^"']+)["']>"""
                         r"""(.*?)</td>""", re.S)
#: A preset's line in a cell: its engine label and verdict.
CELL_LINE = re.compile(r"""<div class=["']line["'][^>]*data-label=["']([^"']+)["'] """
                       r"""data-verdict=["']([^"']+)["']""")


#: A run's row of a per-scene table: engine, step, then the verdict cell (colour, text).
RUN_ROW = re.compile(r"<tr><td>[^<]+</td><td class='num'>[^<]+</td><td style='background:"
                     r"(#[0-9a-f]+)' title='[^']*'><span class='status'>([^<]+)</span></td>")


def _matrix_cells(page: str) -> dict:
    """(scene, engine label) -> verdict of each preset's line, (scene, engine) -> 'not run'
    of an empty cell."""
    cells = {}
    for scene, engine, verdict, body in MATRIX_CELL.findall(page):
        lines = CELL_LINE.findall(body)
        if not lines:
            cells[(html.unescape(scene), html.unescape(engine))] = html.unescape(verdict)
        for label, line_verdict in lines:
            cells[(html.unescape(scene), html.unescape(label))] = html.unescape(line_verdict)
    return cells


def test_overview_matrix_shows_the_verdict_of_status_and_expectations(small_store, tmp_path):
    paths = write_report(small_store, tmp_path / "out")
    page = paths["html"].read_text()
    cells = _matrix_cells(page)
    expected = _expected_verdicts(small_store)
    assert cells == expected
    # The store holds a finished run that failed its physics, and the matrix says so.
    assert "physics failed" in cells.values(), cells
    # Colour and symbol both, and a legend naming every verdict.
    for name, style in VERDICTS.items():
        assert f"{style.symbol} {name}" in page and style.colour in page
    summary = paths["markdown"].read_text()
    for verdict in set(expected.values()) - {"not run"}:
        assert f"**{VERDICTS[verdict].symbol} {verdict}**" in summary
    # A failed run's line shows the failing expectation's value against its limit.
    frame = small_store.dataframe()
    failed = frame[frame["expectations_passed"] == 0].iloc[0]
    detail = next(r["detail"] for r in json.loads(failed["expectations"])
                  if r["passed"] is False)
    assert html.escape(detail) in page and re.search(r"[<>]=? ", detail), detail
    # Per scene, every run's verdict column holds its verdict (not its status), with the
    # verdict's colour, in the page and in the summary.
    runs = small_store.dataframe()
    verdicts = sorted(run_verdict(r["status"], r["expectations_passed"])
                      for _, r in runs.iterrows())
    shown = RUN_ROW.findall(page)
    assert sorted(verdict.split(" ", 1)[1] for _, verdict in shown) == verdicts
    assert all(VERDICTS[verdict.split(" ", 1)[1]].colour == colour for colour, verdict in shown)
    assert "physics failed" in verdicts
    table_rows = [line.split(" | ")[2] for line in summary.splitlines()
                  if re.match(r"^\| fake\[\w+\] \| [\d.e-]+ \|", line)]
    assert sorted(v.split(" ", 1)[1] for v in table_rows) == verdicts


def test_pareto_front_keeps_the_non_dominated_points():
    times = np.array([1.0, 2.0, 3.0, 2.5, np.nan, 4.0])
    errors = np.array([1e-1, 1e-2, 1e-3, 5e-2, 1e-9, 1e-3])
    # (2.5, 5e-2) is beaten by (2.0, 1e-2); (4.0, 1e-3) by (3.0, 1e-3); NaN never on it.
    assert pareto_front(times, errors).tolist() == [True, True, True, False, False, False]


def test_work_precision_points_and_figure():
    frame = pd.DataFrame({
        "scene_name": ["s"] * 4, "campaign": ["sweep", "sweep", "sweep", "sweep:fine-reference"],
        "label": ["a[default]", "a[default]", "b[default]", "reference[default]"],
        "time_step": [1e-3, 5e-4, 1e-3, 1e-5], "error": [1e-2, 5e-3, 1e-3, np.nan],
        "stepping_seconds_per_simulated_second": [0.1, 0.2, 0.5, 20.0],
        "status": ["ok"] * 4, "key": ["k1", "k2", "k3", "k4"],
    })
    points = work_precision_points(frame, "s")
    assert list(points["key"]) == ["k2", "k1", "k3"]  # by engine, then step; no fine reference
    assert points["pareto"].tolist() == [True, True, True]
    png = work_precision_figure(points, "s")
    assert png.startswith(PNG_SIGNATURE)


def test_a_run_that_diverged_is_never_on_the_pareto_front():
    # mujoco[default]'s diverged run on clearance-pendulum: fastest and, up to where it
    # stopped, most accurate; the front is drawn over the runs that finished only.
    frame = pd.DataFrame({
        "scene_name": ["s"] * 4, "campaign": ["sweep"] * 4,
        "label": ["a[default]", "a[default]", "b[default]", "b[default]"],
        "time_step": [1e-3, 5e-4, 1e-3, 5e-4], "error": [1e-2, 5e-3, 1e-9, 2e-3],
        "stepping_seconds_per_simulated_second": [0.1, 0.2, 0.01, 0.5],
        "status": ["ok", "ok", "diverged", "crashed"], "key": ["k1", "k2", "k3", "k4"],
    })
    points = work_precision_points(frame, "s").set_index("key")
    assert not points.loc["k3", "pareto"] and not points.loc["k4", "pareto"]
    assert points.loc["k1", "pareto"] and points.loc["k2", "pareto"]


def test_time_series_figure_from_a_fake_run(small_store):
    from clearbench.harness.report.figures import time_series_figure

    frame = small_store.dataframe()
    row = frame[(frame["scene_name"] == "bouncing-ball-e0.5")].iloc[0]
    scene = small_store.scene(row["scene_hash"])
    png = time_series_figure(scene, {"fake": small_store.load_trajectory(row["key"])})
    assert png is not None and png.startswith(PNG_SIGNATURE)


def test_report_has_the_c60_section_when_the_validation_json_exists(small_store, tmp_path):
    import math

    from clearbench.harness.c60.validation import Row, ValidationReport, write_json

    figure = tmp_path / "reports" / "figures" / "c60_trip_force.png"
    figure.parent.mkdir(parents=True)
    figure.write_bytes(PNG_SIGNATURE + b"figure")  # stands for the PNG c60 validate draws
    report = ValidationReport(rows=[
        Row("Trip test: peak force", "N", 1.5, 1.87, 1.77),
        Row("c60-trip: contacts open", "ms", 7.6, note="no published figure")],
        findings=["a finding"])
    validation = tmp_path / "reports" / "c60_validation.json"
    write_json(report, validation, {"Trip force vs displacement": figure}, "default")
    # The relative difference -15.3 % = (1.5 - 1.77) / 1.77 (measured value preferred);
    # a missing paper figure is shown as "-", never as NaN.
    assert math.isclose(report.rows[0].difference(), (1.5 - 1.77) / 1.77)
    # (no campaign sections: the committed reports/campaigns of the working directory would
    # sit inside the slice checked below)
    paths = write_report(small_store, tmp_path / "out", c60_validation=validation,
                         campaigns=None)
    page = paths["html"].read_text()
    summary = paths["markdown"].read_text()
    assert "C-60: the reference engine against the published figures" in page
    # The C-60 tables come first, before the per-scene detail.
    assert page.index("<h2 id='c60-paper'>") < page.index("<h3 id='scene-")
    section = page[page.index("<h2 id='c60-paper'>"):page.index("<h3 id='scene-")]
    assert "-15.3 %" in section and "nan" not in section.lower()
    assert page.count("data:image/png;base64,") >= 1 and "Trip force vs displacement" in page
    assert "| Trip test: peak force | N | 1.500 | 1.870 | 1.770 | -15.3 % |" in summary
    assert (tmp_path / "out" / "figures" / "c60-validation-0.png").read_bytes() == \
        figure.read_bytes()
    # Without the file the section is left out.
    plain = write_report(small_store, tmp_path / "plain", c60_validation=tmp_path / "none.json")
    assert "C-60: the reference" not in plain["html"].read_text()


#: Words of the page that are not abbreviations a reader needs explained.
PLAIN_CAPITALS = {"HTML", "PNG", "CSV", "JSON", "TOML", "CPU", "CPUs", "NaN", "ON", "OFF", "URL",
                  "BLAS", "SIGSEGV", "II", "III", "IV", "VTK", "CAD", "STEP", "OK"}
#: What looks like an abbreviation: capitals (and digits) of two or more, a letter and a digit.
ABBREVIATION = re.compile(r"(?<![\w-])(?:[A-Z][A-Z0-9]+(?:-\d)?|[A-Z]\d|R\^2)(?![\w-])")


def test_the_whole_page_is_readable(small_store, tmp_path):
    """With the committed C-60 validation and campaigns: tables (no raw Markdown in <pre>)
    with captions, an id on every heading and a table of contents that resolves, figures two
    per row inside <details>, a glossary entry for every abbreviation, no paragraph twice."""
    from clearbench.harness.report.glossary import TERMS, _visible_text
    from clearbench.harness.report.page import C60_VALIDATION, CAMPAIGNS

    paths = write_report(small_store, tmp_path / "out", c60_validation=C60_VALIDATION,
                         campaigns=CAMPAIGNS)
    page = paths["html"].read_text()
    assert "<pre" not in page and "{'" not in _visible_text(page)
    tables = re.findall(r"<table\b.*?</table>", page, flags=re.S)
    assert tables and all("<caption>" in t for t in tables)
    headings = re.findall(r"<h([1-4])( id='[^']+')?>", page)
    assert all(ident for level, ident in headings if level != "1")
    ids = set(re.findall(r"\bid='([^']+)'", page))
    links = re.findall(r"href='#([^']+)'", page)
    assert links and set(map(html.unescape, links)) <= ids
    assert "Tolerance campaign" in page and re.search(r"<details><summary>Figures of c60-paper",
                                                      page)
    assert re.search(r"<div class='figs'>(<figure>.*?</figure>){2,}", page, flags=re.S)
    glossary = page[page.index("<h2 id='glossary'>"):]
    text = _visible_text(page[:page.index("<h2 id='glossary'>")])
    used = set(ABBREVIATION.findall(text)) - PLAIN_CAPITALS
    explained = {t for t in TERMS if f">{html.escape(t)}</dt>" in glossary}
    assert used <= explained | {"C-60"}, sorted(used - explained)
    for term in ("C4", "J1", "Q2", "FORM", "FC-1"):
        assert term in explained
    paragraphs = [p for p in re.findall(r"<p[^>]*>(.*?)</p>", page, flags=re.S) if len(p) > 80]
    assert len(paragraphs) == len(set(paragraphs)), "a paragraph is repeated"
    # The conclusions the page shows are those results.json keeps (the README's table).
    results = json.loads(paths["results"].read_text())
    conclusions = page[page.index("<h2 id='conclusions'>"):page.index("<h2 id='overview'>")]
    for row in results["rows"]:
        for cell in row:
            assert html.escape(cell) in conclusions, cell
    assert results["standing"] and html.escape(results["standing"]) in conclusions


def test_the_legend_explains_every_registered_expectation_kind_by_its_criterion():
    """Every kind of the expectation registry (implied ones too), failed in a cell, gets a
    legend line with its criterion's own words: the report has no list of kinds of its own."""
    from clearbench.harness.measure.kinds import KINDS
    from clearbench.harness.report.overview import CellLine, words_used

    for name, kind in KINDS.items():
        line = CellLine("e[default]", "default", "physics failed", "", "", (name,))
        used = words_used([line])
        entry = used[f"failed: {name.replace('_', ' ')}"]
        assert kind.criterion.passes_when in entry, name


def test_an_unseen_penetration_is_its_own_verdict_with_its_finding():
    """A finished run whose stored figures hold an unseen penetration (the run-wide geometry
    check) reads "unseen penetration" in the overview, its cell giving the pair, the time and
    the instrument's figure against the kernel's; one without it keeps its other verdict."""
    from clearbench.harness.report.overview import cell_lines, row_verdict

    reason = ("unseen penetration: ball_floor at t = 0.1 s: the instrument witnesses 0.002 m, "
              "the kernel's figure is 0 m")
    row = {"status": "ok", "expectations_passed": 1, "message": "", "expectations": "[]",
           "metrics": json.dumps({"unseen_penetration": 0.002}), "verdict_reason": reason}
    assert row_verdict(row) == "unseen penetration"
    (line,) = cell_lines({"e[default]": row}, "e", None)
    assert line.verdict == "unseen penetration"
    assert line.figure.startswith("ball_floor at t = 0.1 s: the instrument witnesses 0.002 m")
    seen = {**row, "metrics": json.dumps({"unseen_penetration": 0.0}), "verdict_reason": ""}
    assert row_verdict(seen) == "pass"
    # a run that did not finish keeps its status's verdict whatever its figures
    assert row_verdict({**row, "status": "diverged"}) == "diverged"
