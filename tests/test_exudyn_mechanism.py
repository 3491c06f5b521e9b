"""The Exudyn preset for mechanisms on the C-60 (``exudyn[mechanism]``): Newton's absolute
tolerance scaled to the scene's force scale, and the run through the contact-closing transient
of ``c60-on`` that stopped both older presets at 0.11 ms.

Cost: the quick test about 10 s (build and 30 steps of 1 us, two Newton iterations each); the
slow one, 0.2 ms of ``c60-on`` (6,000 Exudyn steps for 200 nominal ones as the journals close
their clearances), minutes on two shared cores.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from clearbench.adapters.base import RunSettings
from clearbench.adapters.exudyn import create
from clearbench.adapters.exudyn.settings import PRESETS
from clearbench.adapters.trajectory import RunStatus
from clearbench.scenarios.library import get_scene

warnings.filterwarnings("ignore", category=DeprecationWarning)


def _c60_on(horizon: float):
    scene = get_scene("c60-on")
    return create("mechanism").run(scene, RunSettings(horizon=horizon, record_every=10))


def test_mechanism_preset_scales_newton_s_tolerance_to_the_force_scale():
    """30 steps of 1 us (before the first clearance closes): the absolute tolerance is the
    preset's fraction of the force scale, the largest law-load force at t = 0."""
    trajectory = _c60_on(0.03)
    assert trajectory.status is RunStatus.OK, trajectory.message
    meta = trajectory.metadata
    fraction = PRESETS["mechanism"]["newton_force_tolerance"]
    # The C-60's law loads (springs of the mechanism) are tens of newtons in mm-g-ms (1 N):
    # a scale outside 1-1000 N would be a unit or read-out error, not a model change.
    assert 1.0 < meta["force_scale"] < 1000.0
    # Same product computed twice in double precision: equal to round-off.
    assert meta["newton_absolute_tolerance"] == pytest.approx(fraction * meta["force_scale"],
                                                              rel=1e-12)
    # Exudyn's residual floor on the C-60 is 1.1e-5 N (docs/engines/exudyn.md): the scaled
    # tolerance must lie above it, else Newton cannot converge at contact instants.
    assert meta["newton_absolute_tolerance"] > 1.1e-5


@pytest.mark.slow
def test_mechanism_preset_passes_the_first_0p2_ms_of_c60_on():
    """0.2 ms: past the journals' first closures (0.034-0.11 ms), where `tuned` stopped with
    Newton stalled at its round-off floor; no step reduction failure, no non-finite state."""
    trajectory = _c60_on(0.2)
    assert trajectory.status is RunStatus.OK, trajectory.message
    # The samples reach the horizon on the grid (record_every 10 steps of 1 us = 0.01 ms);
    # 1e-9 ms is round-off on sums of 1e-3 ms steps.
    assert trajectory.times[-1] == pytest.approx(0.2, abs=1e-9)
    assert np.isfinite(trajectory.positions).all()
    # Exudyn shortens steps to contact instants: more solver steps than nominal ones.
    assert trajectory.metadata["solver_steps"] >= trajectory.metadata["nominal_steps"]
