"""The ``clearbench fclib`` command: table, CSV, performance profile, bad input."""

import csv

from clearbench.harness.cli.main import main
from clearbench.harness.fclib.compare import RunRow, performance_profile
from clearbench.harness.fclib.problems import shipped_problem_dir

DATA = shipped_problem_dir()


def test_fclib_command_writes_table_csv_and_profile(tmp_path, capsys):
    out = tmp_path / "runs.csv"
    profile = tmp_path / "profile.png"
    status = main(["fclib", str(DATA / "OneObject-i1028-138.hdf5.dat"),
                   str(DATA / "Chute-ndof-768-nc-4-3.hdf5"), "--solver", "nsgs-ac",
                   "--solver", "newton-ac", "--repeat", "1", "--min-time", "0", "--no-siconos",
                   "--out", str(out),
                   "--profile", str(profile)])
    text = capsys.readouterr().out
    assert status == 0
    assert "OneObject-i1028-138.hdf5.dat" in text and "skipped" in text
    rows = list(csv.DictReader(out.open()))
    assert [row["solver"] for row in rows] == ["nsgs-ac", "newton-ac"]
    assert all(row["solved"] == "True" for row in rows)
    assert all(row["solves"] == "1" for row in rows)  # --repeat 1 and no minimum time
    assert profile.stat().st_size > 1000


def test_fclib_command_rejects_a_missing_file(tmp_path, capsys):
    assert main(["fclib", str(tmp_path / "nope.hdf5"), "--no-siconos"]) == 2
    assert "no such problem file" in capsys.readouterr().err


def test_performance_profile_fractions():
    def row(problem, solver, time, solved=True):
        return RunRow(problem, "local", 1, solver, 1, time, 0.0, 0.0, "converged", solved)

    rows = [row("a", "x", 1.0), row("a", "y", 2.0), row("b", "x", 3.0, solved=False),
            row("b", "y", 1.0)]
    tau, fractions = performance_profile(rows)
    assert tau[0] == 1.0
    # at tau = 1: x is fastest on a, y on b; at tau >= 2 y solves both, x never solves b
    assert fractions["x"][0] == 0.5 and fractions["y"][0] == 0.5
    assert fractions["y"][-1] == 1.0 and fractions["x"][-1] == 0.5
