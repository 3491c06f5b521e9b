"""``clearbench bench c60|reference|engines --against REV``: baseline export, worker protocol,
ratio."""

from __future__ import annotations

import argparse
import subprocess
import sys

import pytest

from clearbench.harness.cli.main import main
from clearbench.harness.studies import against


def _run(**fields):
    base = {"stepping_seconds": 1.0, "steps": 10, "unconverged_steps": 0,
            "mean_iterations": 1.0}
    return base | fields


def test_pair_keeps_the_best_run_of_each_side_and_their_ratio():
    pair = against.Pair(against.Case("ball"), [_run(stepping_seconds=4.0),
                                               _run(stepping_seconds=3.0)],
                        [_run(stepping_seconds=2.0), _run(stepping_seconds=1.5)])
    assert pair.best_baseline["stepping_seconds"] == 3.0
    assert pair.best_current["stepping_seconds"] == 1.5
    assert pair.speedup == 2.0


def test_a_case_that_raised_on_a_side_has_an_error_and_no_ratio():
    # e.g. a library scene the baseline revision does not have: reported, the others go on
    pair = against.Pair(against.Case("new-scene"), [{"error": "KeyError: 'new-scene'"}], [])
    assert pair.error == "baseline: KeyError: 'new-scene'"
    assert against.Pair(against.Case("ball"), [_run()], [_run()]).error is None


@pytest.mark.parametrize("benchmark", ["c60", "engines"])
def test_unknown_revision_is_a_user_error(capsys, benchmark):
    assert main(["bench", benchmark, "--against", "no-such-revision-anywhere"]) == 2
    assert "does not know the revision" in capsys.readouterr().err


@pytest.mark.parametrize("benchmark, scene", [("reference", "pendulum"), ("c60", "c60-bogus")])
def test_a_scene_outside_the_benchmarks_cases_is_refused_before_any_run(capsys, benchmark,
                                                                         scene):
    # --scenes filters the benchmark's own cases: a name outside them used to leave a table
    # without that scene and no word why
    assert main(["bench", benchmark, "--against", "HEAD", "--scenes", scene]) == 2
    err = capsys.readouterr().err
    assert repr(scene) in err and "bench engines --against REV --scene NAME" in err


def test_bench_engines_against_takes_any_library_scene():
    # its --scene (dest ``scenes`` too) is not filtered by the c60 / reference cases
    from clearbench.harness.cli import bench_against
    args = argparse.Namespace(benchmark="engines", against="HEAD", repeat=1, dt=None,
                              scenes=["pendulum"])
    assert len(bench_against._checked_baseline(args)) == 40


def test_against_applies_to_c60_reference_and_engines_only(capsys):
    # --against is an option of those three benchmarks only: argparse refuses it elsewhere
    with pytest.raises(SystemExit) as caught:
        main(["bench", "clearance-ladder", "--against", "HEAD"])
    assert caught.value.code == 2
    assert "unrecognized arguments: --against" in capsys.readouterr().err


def test_namespace_links_follow_the_package_dir_mapping(tmp_path):
    source = tmp_path / "src"
    (source / "clearbench").mkdir(parents=True)
    (source / "clearbench" / "__init__.py").write_text("")
    (source / "ref_solver").mkdir()
    (source / "ref_solver" / "__init__.py").write_text("VALUE = 7\n")
    (source / "pyproject.toml").write_text(
        '[tool.setuptools]\npackage-dir = { "clearbench" = "clearbench", '
        '"clearbench.ref_solver" = "ref_solver" }\n')
    against._namespace_links(source, tmp_path / "shim")
    out = subprocess.run([sys.executable, "-I", "-c",
                          "import sys; sys.path.insert(0, sys.argv[1]); "
                          "import clearbench.ref_solver as r; print(r.VALUE)",
                          str(tmp_path / "shim")], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "7"
    assert not (tmp_path / "shim" / "clearbench" / "ref_solver").readlink().is_absolute()


def test_worker_answers_one_request_per_line():
    request = against.Case("bouncing-ball-e0.5", horizon=0.01).request()
    out = subprocess.run([sys.executable, "-P", str(against.WORKER)], input=request + "\n",
                         capture_output=True, text=True, check=True, timeout=600)
    reply = __import__("json").loads(out.stdout.splitlines()[0])
    assert reply.get("error") is None, reply
    assert reply["steps"] > 0 and reply["stepping_seconds"] > 0.0


@pytest.mark.slow
def test_side_by_side_against_head_runs_both_sides():
    case = against.Case("bouncing-ball-e0.5", horizon=0.01)
    pairs = against.side_by_side([case], "HEAD", repeat=2)
    assert len(pairs[0].baseline) == len(pairs[0].current) == 2
    assert pairs[0].best_baseline["steps"] == pairs[0].best_current["steps"]
