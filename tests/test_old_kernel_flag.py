"""The geometry check flags the old kernel's blind spot on a stored c60-trip of ddb0acf.

reports/trajectories/c60-trip_reference_ddb0acf.npz is the reference's c60-trip made with the
gap kernel of ddb0acf (README there); it carries that revision's own penetration figure
(``kernel_penetration_ddb0acf``), and c60-trip_ddb0acf.json is the scene it was given. The
check compares with that stored figure, so the test holds whatever kernel this revision has.
Read at every state from 6.6 to 7.6 ms (101 states, a few seconds), the instrument witnesses
the tripping bar's arcs C4_3 and C4_4 inside the hook's latch solid while the old figure reads
0 there; before 6.8 ms the two agree.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from clearbench.adapters.trajectory import Trajectory
from clearbench.harness.measure import geometry_check
from clearbench.scenarios.serialization import scene_from_json

STORED = Path(__file__).resolve().parent.parent / "reports" / "trajectories"
#: Half a recorded interval [ms]: the samples are 0.01 ms apart.
HALF_SAMPLE = 0.005


def window(start: float, end: float):
    """The stored run's scene, its states in [start, end] [ms], and ddb0acf's figure there."""
    scene = scene_from_json((STORED / "c60-trip_ddb0acf.json").read_text())
    path = STORED / "c60-trip_reference_ddb0acf.npz"
    run = Trajectory.load(path)
    with np.load(path) as data:
        kernel = np.asarray(data["kernel_penetration_ddb0acf"])
    assert run.scene_hash == scene.content_hash
    keep = (run.times >= start - HALF_SAMPLE) & (run.times <= end + HALF_SAMPLE)
    part = dataclasses.replace(run, **{name: getattr(run, name)[keep]
                                       for name in Trajectory.ARRAYS})
    return scene, part, kernel[keep]


def test_the_instrument_flags_the_latch_arcs_the_old_kernel_missed():
    scene, run, kernel = window(6.6, 7.6)
    result = geometry_check.check(scene, run, kernel, stride=1)
    intervals = result.unseen_intervals()
    assert set(intervals) == {"Hook_Tbar_C4_2_side", "Hook_Tbar_C4_3", "Hook_Tbar_C4_4"}
    # First flags 6.80 (C4_4) and 6.83 ms (C4_3), last 7.39 ms: the arcs pass through the
    # latch solid after the release, up to 68 um deep (0.5 mm thick), unseen.
    assert intervals["Hook_Tbar_C4_3"][:2] == (pytest.approx(6.83), pytest.approx(7.39))
    assert intervals["Hook_Tbar_C4_4"][:2] == (pytest.approx(6.80), pytest.approx(7.39))
    deepest = np.nanmax(result.instrument.penetration[:, result.names.index("Hook_Tbar_C4_4")])
    assert deepest == pytest.approx(0.0685, abs=1e-4)
    flagged = result.unseen > 0.0
    # The old figure reads no penetration at every flagged state (1e-13 mm is its round-off
    # on the pins: the largest anywhere in the run is 9.8e-14 mm).
    assert np.all(result.kernel[flagged] <= 1e-13)
    assert np.all(result.instrument.penetration[flagged] > 1e-6)
    message = result.message(scene.units.length, scene.units.time)
    assert message.startswith("unseen penetration: Hook_Tbar_C4_4 at t = 7.37 ms")


def test_before_the_release_both_figures_agree():
    scene, run, kernel = window(6.0, 6.75)
    result = geometry_check.check(scene, run, kernel, stride=1)
    assert result.unseen_max == 0.0 and result.agrees
    # Both see nothing beyond round-off (the reference is rigid: 1e-13 mm); the check's
    # round-off allowance is 1e-9 of the scene's size.
    assert result.agreement_max <= result.round_off
