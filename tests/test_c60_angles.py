"""``clearbench c60 angles``: each body's angle about z along a C-60 trajectory."""

from __future__ import annotations

import math

import pytest

from clearbench.adapters.base import RunSettings
from clearbench.adapters.reference import create
from clearbench.harness.c60.angles import body_angles
from clearbench.harness.cli.main import main
from clearbench.scenarios.library import get_scene


@pytest.fixture(scope="module")
def trajectory_file(tmp_path_factory):
    trajectory = create().run(get_scene("c60-on", horizon=0.05), RunSettings())
    path = tmp_path_factory.mktemp("c60") / "c60-on.npz"
    trajectory.save(path)
    return path, trajectory


def test_angles_are_printed_for_every_body_at_each_interval(trajectory_file, capsys):
    path, trajectory = trajectory_file
    assert main(["c60", "angles", str(path), "--every", "0.01"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].split()[:3] == ["t", "[ms]", "frame"]
    assert lines[0].endswith("max speed")
    assert len(lines) == 1 + 6  # 0, 0.01, ..., 0.05 ms
    first = lines[1].split()
    assert len(first) == 1 + len(trajectory.body_names) + 1
    assert float(first[1]) == 0.0  # the fixed frame does not turn


def test_angles_lie_in_the_principal_range(trajectory_file):
    _, trajectory = trajectory_file
    samples = body_angles(trajectory, 0.025)
    assert [s.time for s in samples] == pytest.approx([0.0, 0.025, 0.05])
    assert all(-math.pi < a <= math.pi for s in samples for a in s.angles)


def test_angles_of_a_missing_file_is_an_input_error(tmp_path, capsys):
    assert main(["c60", "angles", str(tmp_path / "none.npz")]) == 2
    assert "no such file" in capsys.readouterr().err
