"""An engine plugged in from outside the package runs in every command of the harness from what
it declares (tests/toy_engine: the adapter contract and its HARNESS_DEFAULTS), with no harness
file naming it: ``compare``, ``regress`` (its declared quick run added to a baseline, measured,
then checked), ``stability``, ``c60 compare`` (it cannot build the C-60: recorded unsupported,
with its reason) and ``report``.

The runs measure their figures with the shared numba kernels: from an empty numba cache (the
first harness test after a source change) the first run compiles them, about a minute on a
loaded 2-core machine; with the cache filled the test takes about 30 s.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

from clearbench.harness.cli.main import main
from clearbench.harness.report.engine_style import engine_colours, engine_style
from clearbench.harness.run.store import ResultsStore
from clearbench.harness.studies.c60_comparison import c60_plan

from .toy_engine import HARNESS_DEFAULTS

TOY = {"toy": "tests.toy_engine"}
TOY_OPTION = ["--engine-module", "toy=tests.toy_engine"]
HARNESS = Path(__file__).resolve().parent.parent / "harness"
#: One round-off seed: the toy has no numba or OpenBLAS code path of its own to perturb.
ROUNDOFF_ONLY = [{"name": "roundoff", "kind": "roundoff", "ulps": 4, "seeds": 1,
                  "why": "test"}]


def test_no_harness_file_names_the_toy():
    named = [str(path) for path in HARNESS.rglob("*.py")
             if re.search(r"\btoy\b", path.read_text())]
    assert named == []


def test_the_toy_declares_its_plan_and_colour():
    plan = c60_plan("demo", TOY)
    assert plan.ladders["c60-on"]["toy[default]"] == (1e-3,)
    assert "toy[default]" not in c60_plan("full", TOY).labels()   # declared for the demo only
    assert "toy[default]" not in c60_plan("demo").labels()        # not without its module
    assert engine_colours(TOY)["toy"] == HARNESS_DEFAULTS.colour
    assert engine_style("toy[default]", engine_colours(TOY)).colour == HARNESS_DEFAULTS.colour


def test_a_plugged_in_engine_runs_in_every_command(tmp_path, capsys):
    store_dir, out = tmp_path / "store", tmp_path / "out"
    common = ["--store", str(store_dir), "--no-progress", *TOY_OPTION]

    # compare: the toy alone on the bounce, at the comfortable step and half of it.
    assert main(["compare", "-e", "toy", "--scenes", "bouncing-ball-e0.5", "--dt", "1x,0.5x",
                 "--c60", "none", "--out", str(out), *common]) == 0
    assert "Comparing toy[default] on 1 scenes" in capsys.readouterr().out
    runs = ResultsStore(store_dir).dataframe()
    assert sorted(runs["time_step"]) == [5e-4, 1e-3] and set(runs["engine"]) == {"toy"}
    assert set(runs["status"]) == {"ok"}

    # regress: a baseline of another engine; --update -e toy adds the toy's declared quick run,
    # measures it and keeps the other engine's result; the check then passes.
    baseline = tmp_path / "quick.json"
    other = {"id": "reference pendulum", "scene": "pendulum", "engine": "reference",
             "horizon": 0.01}
    kept = {"status": "ok", "metrics": {"x": 1.0}, "note": "not run: another engine"}
    baseline.write_text(json.dumps({"suite": [other], "perturbations": ROUNDOFF_ONLY,
                                    "results": {"reference pendulum": kept}}))
    regress = ["regress", "--baseline", str(baseline), "-e", "toy", *TOY_OPTION]
    assert main([*regress, "--update"]) == 0
    assert "toy: the quick runs it declares added to the suite" in capsys.readouterr().out
    written = json.loads(baseline.read_text())
    ident = "toy[default] bouncing-ball-e0.5"
    assert written["suite"] == [other, {"id": ident, "scene": "bouncing-ball-e0.5",
                                        "engine": "toy[default]", "horizon": 0.5}]
    assert written["results"]["reference pendulum"] == kept
    assert set(written["results"][ident]["checks"]) == set(written["results"][ident]["metrics"])
    assert main(regress) == 0
    assert "no regression: 1 runs" in capsys.readouterr().out

    # stability: two stiff cases the toy can represent.
    assert main(["stability", "-e", "toy", "--scenes", "stiff-elastic", "stiff-large-step-ball",
                 *common]) == 0
    printed = capsys.readouterr().out
    assert printed.count("toy[default]") == 2

    # c60 compare: the toy's declared demo step, recorded unsupported with its reason.
    assert main(["c60", "compare", "-e", "toy", "--out", str(out), *common]) == 0
    printed = capsys.readouterr().out
    assert re.search(r"c60-on\s+toy\[default\]\s+0\.001\s+unsupported", printed)
    c60 = ResultsStore(store_dir).dataframe().query("scene_name == 'c60-on'")
    assert list(c60["status"]) == ["unsupported"]
    assert "the toy engine has free bodies" in c60["message"].iloc[0]

    # report: the toy in the overview matrix, its scenes and the C-60 section.
    assert main(["report", "--store", str(store_dir), "--out", str(out), *TOY_OPTION]) == 0
    page = (out / "report.html").read_text()
    # The overview has one column per engine, the preset named in the cell.
    assert "data-engine='toy'" in page and "data-label='toy[default]'" in page
    assert "toy[default]" in (out / "summary.md").read_text()
    c60_part = page[page.index("C-60 across engines"):]
    assert "toy" in c60_part and "unsupported" in c60_part
