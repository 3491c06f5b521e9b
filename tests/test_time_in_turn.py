"""tools/time_in_turn.py: two commands timed in turn, exit codes kept, the ratio pair by pair."""

from __future__ import annotations

import sys

from tools.time_in_turn import main, time_once


def test_time_once_reports_the_exit_code_and_the_childs_cpu():
    busy = "sum(range(3_000_000)); raise SystemExit(3)"
    wall, cpu, code = time_once([sys.executable, "-c", busy])
    assert code == 3
    # The child's CPU is counted (a busy loop of a few tens of milliseconds), and a single
    # process cannot use more CPU than wall time plus the clocks' granularity (10 ms).
    assert 0 < cpu <= wall + 0.01


def test_runs_alternate_and_a_failed_run_is_reported_not_raised(capsys):
    code = main(["-n", "2", "--vs", f"{sys.executable} -c pass", "--",
                 sys.executable, "-c", "raise SystemExit(2)"])
    out = capsys.readouterr().out
    assert code == 0  # it measures and never judges
    runs = [line.split(":")[0] for line in out.splitlines() if line.startswith("run ")]
    assert runs == ["run 1 A", "run 1 B", "run 2 A", "run 2 B"]
    assert "A/B" in out
    assert "A run 1: exit 2; A run 2: exit 2" in out
