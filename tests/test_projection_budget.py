"""The projection's corrections are bounded by the violation they set out to remove.

A Gauss–Newton correction is the least motion that removes the linearised violations; where
the rows are nearly dependent and their values not compatible it is far larger than them and
follows a direction the linearisation does not describe. In the reference's ``c60-trip`` of
the variant ``paper-table-4`` at 16 us, the projection of step 706 (11.296 ms) moved the hook by
13.9 mm and turned it by 2.07 rad to remove a violation of 2.1 um, met its active rows again at
other candidates, and the run went on with the plate's journals 1.5 m out of their bores while
its status read ok. ``projection_kernel.correction_budget`` bounds the sum of a projection's
corrections (docs/reference-solver.md, "The projection's bound").

Lengths in mm, times in ms (the C-60's units).
"""

from __future__ import annotations

import numpy as np
import pytest

from clearbench.adapters.base import RunSettings
from clearbench.adapters.reference import create
from clearbench.harness.measure import series
from clearbench.ref_solver.projection_kernel import (
    CORRECTION_FLOOR,
    PROJECTION_REACH,
    correction_budget,
    correction_size,
)
from clearbench.scenarios.library import get_scene

#: The C-60's length scale [mm] (its largest feature), as the reference engine sets it.
C60_LENGTH = 7.8


def test_a_correction_moves_a_body_point_by_its_translation_and_its_turn_at_the_length():
    delta = np.zeros((3, 6))
    delta[0, :3] = (3e-3, 4e-3, 0.0)        # 5e-3 mm
    delta[1, :3] = (1e-3, 0.0, 0.0)         # 1e-3 mm, and
    delta[1, 3:] = (0.0, 0.0, 1e-3)         # 1e-3 rad at 7.8 mm: 7.8e-3 mm
    # Exact to round-off: a sum of two square roots of sums of three squares.
    assert correction_size(delta, C60_LENGTH) == pytest.approx(8.8e-3, rel=1e-14)
    assert correction_size(np.zeros((2, 6)), C60_LENGTH) == 0.0


def test_the_budget_is_the_reach_times_the_violation_above_a_floor_of_the_length():
    assert correction_budget(2e-3, C60_LENGTH) == pytest.approx(
        PROJECTION_REACH * 2e-3 + CORRECTION_FLOOR * C60_LENGTH, rel=1e-15)
    # A violation at round-off (1e-13 mm) keeps the floor, 7.8e-6 mm (the reach's share,
    # 1e-10 mm, is 1.3e-5 of it, inside the 1e-4 asked): the corrections of redundant rows
    # near convergence (1e-7 mm on the C-60) are not bounded.
    assert correction_budget(1e-13, C60_LENGTH) == pytest.approx(7.8e-6, rel=1e-4)


def test_a_coarse_step_does_not_take_the_c60_apart():
    # 16 us, the coarsest step of the C-60's ladder, to 11.5 ms (719 steps, past step 706).
    # Without the budget the plate's journals read 19 mm out of their bores from 11.296 ms on
    # (1.5 m by 20 ms). With it every pair's penetration stays at the projection's round-off
    # (1e-13 mm measured); the bound, 1e-6 mm, is the scene's own no-penetration limit, four
    # orders below the C-60's smallest clearance (0.01 mm) and seven below the jump.
    scene = get_scene("c60-trip", variant="paper-table-4")
    trajectory = create().run(scene, RunSettings(time_step=0.016, horizon=11.5,
                                                 record_every=1))
    penetration = series.penetration(scene, trajectory)
    names = [contact.name for contact in scene.expanded.contacts]
    deepest = int(np.argmax(penetration.max(axis=0)))
    assert penetration.max() <= 1e-6, (
        f"{names[deepest]} {penetration[:, deepest].max():.3g} mm deep at "
        f"{trajectory.times[int(np.argmax(penetration[:, deepest]))]:.4f} ms")
    # And no body moves by more than 1 mm in a step: at 16 us the fastest part (the hook, at
    # most 8.7 mm/ms as the latch lets go) travels at most 0.14 mm a step (0.089 mm measured);
    # the jump was 13.9 mm.
    step_moves = np.linalg.norm(np.diff(trajectory.positions, axis=0), axis=2)
    assert step_moves.max() <= 1.0, f"a body moved {step_moves.max():.3g} mm in one step"
