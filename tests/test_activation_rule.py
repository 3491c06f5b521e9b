"""The first activation round's rules (ref_solver/activation.py): which contacts a step starts
with, the option that chooses the rule, and both step loops applying it alike."""

from __future__ import annotations

import numpy as np
import pytest

from clearbench.adapters.base import RunSettings
from clearbench.adapters.options import OptionError
from clearbench.adapters.reference.build import build
from clearbench.adapters.reference.engine import create
from clearbench.adapters.reference.settings import stepper_settings
from clearbench.ref_solver.activation import (
    RULE_GAP,
    RULE_HELD,
    RULE_MOREAU,
    RULE_PREDICTED,
    first_round,
)
from clearbench.scenarios.library import get_scene
from clearbench.scenarios.scales import feature_lengths

H = 1e-3        # step [s]
THETA = 0.5
MARGIN = 1e-12  # activation margin [m]
HOLD = 1e-8     # hold margin [m]
THRESHOLD = 0.02  # restitution threshold [m/s]


def _rule(rule, gap, u_start, u_free, restitution=(0.0,), previous_normal=None):
    """first_round on one pair of ``len(gap)`` slots; ``previous_normal``: the previous
    step's normal impulses of the slots (default none)."""
    row = np.array([gap], dtype=float)
    previous = np.zeros((1, len(gap), 3))
    if previous_normal is not None:
        previous[0, :, 0] = previous_normal
    return first_round(rule, row, np.array([u_start], dtype=float),
                       np.array([u_free], dtype=float), previous, H, THETA, MARGIN, HOLD,
                       np.array(restitution, dtype=float), THRESHOLD)[0]


def test_gap_rule_takes_the_contacts_closed_at_the_start_only():
    # Slots: closed, open by 1 um approaching at 1 m/s (it closes within the 1 ms step),
    # open by 1 nm at rest after carrying an impulse, an empty slot (inf).
    active = _rule(RULE_GAP, [-1e-9, 1e-6, 1e-9, np.inf], [0.0, -1.0, 0.0, 0.0],
                   [0.0, -1.0, 0.0, 0.0], previous_normal=[1.0, 0.0, 1.0, 0.0])
    assert active.tolist() == [True, False, False, False]


@pytest.mark.parametrize("rule", [RULE_HELD, RULE_PREDICTED])
def test_held_and_predicted_rules_hold_contacts_that_carried_an_impulse(rule):
    # Separating (the free motion would not close them), open by half and by twice the hold
    # margin, each with and without a normal impulse in the previous step: held only when it
    # carried one and is open by at most the margin.
    active = _rule(rule, [0.5 * HOLD, 0.5 * HOLD, 2 * HOLD, 2 * HOLD],
                   [1e-3] * 4, [1e-3] * 4, previous_normal=[1e-6, 0.0, 1e-6, 0.0])
    assert active.tolist() == [True, False, False, False]


def test_held_rule_does_not_predict():
    # Open by 1 um and closing within the step at 1 m/s (start and free velocity), no impulse
    # in the previous step: the held rule leaves it to the activation loop.
    assert not _rule(RULE_HELD, [1e-6], [-1.0], [-1.0])[0]
    assert _rule(RULE_PREDICTED, [1e-6], [-1.0], [-1.0])[0]


def test_free_motion_adds_what_the_free_motion_closes_within_the_step():
    # The end-of-step gap of the free motion is g + h (theta u_free + (1 - theta) u_start):
    # slot 1: 1e-6 + 1e-3 (0.5 (-1e-3) + 0.5 (-1e-3)) = 0: closes exactly at the step's end;
    # slot 2: 1e-6 + 1e-3 (0.5 (1e-3) + 0.5 (-1e-3)) = 1e-6 stays open: it approached at the
    #         start but the free velocity separates it;
    # slot 3: resting (u_start 0), pulled in by the free velocity (gravity): 1e-9 - 1e-3 x
    #         0.5 x 1e-5 < 0;
    # slot 4: separating; slot 5: closed (taken by the gap rule whatever its velocity);
    # slot 6: an empty slot.
    active = _rule(RULE_PREDICTED,
                   [1e-6, 1e-6, 1e-9, 1e-6, -1e-9, np.nan],
                   [-1e-3, -1e-3, 0.0, 1e-3, 1.0, -1.0],
                   [-1e-3, 1e-3, -1e-5, 1e-3, 1.0, -1.0])
    assert active.tolist() == [True, False, True, False, True, False]


def test_free_motion_leaves_elastic_impacts_to_impact_localisation():
    # e > 0 and approaching faster than the restitution threshold: an impact whose crossing
    # time impact localisation finds among the first round's closing contacts, not activated;
    # slower than the threshold (plastic by the threshold) it is.
    fast, slow = -10 * THRESHOLD, -0.5 * THRESHOLD
    gap = H * abs(fast)  # closes exactly at the step's end at the fast speed
    assert not _rule(RULE_PREDICTED, [gap], [fast], [fast], restitution=(0.5,))[0]
    assert _rule(RULE_PREDICTED, [gap], [fast], [fast], restitution=(0.0,))[0]
    small = 0.25 * H * abs(slow)  # closes within the step at the slow speed
    assert _rule(RULE_PREDICTED, [small], [slow], [slow], restitution=(0.5,))[0]


def test_moreau_rule_is_the_half_step_prediction_at_the_start_velocity():
    # g + (h/2) u_start <= margin: 1e-6 - 0.5e-3 x 3e-3 < 0, 1e-6 - 0.5e-3 x 1e-3 > 0; the
    # free velocity is not read.
    active = _rule(RULE_MOREAU, [1e-6, 1e-6], [-3e-3, -1e-3], [-1.0, -1.0])
    assert active.tolist() == [True, False]


def test_the_option_reaches_the_stepper_and_refuses_unknown_rules():
    scene = get_scene("clearance-pendulum")
    assert stepper_settings("default", scene, RunSettings()).activation == "gap"
    chosen = stepper_settings("default", scene, RunSettings(options={"activation": "held"}))
    assert chosen.activation == "held"
    # The hold margin defaults to 1e-2 of the scene's smallest feature, like the activation
    # margin (1e-10 of it) a length of the scene's own scale.
    assert chosen.activation_hold == pytest.approx(1e-2 * min(feature_lengths(scene)),
                                                   rel=1e-12)
    with pytest.raises(OptionError, match="activation"):
        create("default").check_options({"activation": "free-motion"})
    with pytest.raises(OptionError, match="activation_hold"):
        create("default").check_options({"activation_hold": -1e-9})


def _rounds(scene_name: str, activation: str, steps: int) -> int:
    """Activation rounds of the first ``steps`` Python steps of the scene."""
    scene = get_scene(scene_name)
    engine = create("default")
    model = build(scene, engine.run_settings(
        scene, RunSettings(options={"activation": activation})))
    state, rounds = model.state, 0
    for _ in range(steps):
        result = model.stepper.step(state)
        state = result.state
        rounds += result.statistics.activation_rounds
    return rounds
