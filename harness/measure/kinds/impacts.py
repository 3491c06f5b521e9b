"""Kinds about impacts: the bouncing ball's apex heights (``bounce_apex``) and Housner's
rocking block (``rocking_ratio``)."""

from __future__ import annotations

import math

import numpy as np

from clearbench.harness.measure.criteria import Case, Criterion, Judged, percent
from clearbench.harness.measure.kinds.common import height
from clearbench.harness.measure.kinds.registry import MeasuredKind, TableColumn, register
from clearbench.harness.measure.quantities import COUNT, PURE, L, T, of
from clearbench.kernels.quaternion import quat_normalize_batch, quat_rotate_batch
from clearbench.scenarios import analytic
from clearbench.scenarios.expectation_kinds import BOUNCE_APEX, ROCKING_RATIO


def _apexes(heights, times):
    """Apex heights: the maximum of each flight between two impacts (local minima of the
    height where the vertical motion reverses)."""
    velocity = np.gradient(heights, times)
    rising = velocity > 0
    starts = np.nonzero(~rising[:-1] & rising[1:])[0]  # impacts: falling -> rising
    apexes = []
    if not len(starts):
        return np.array(apexes)
    for a, b in zip(starts, list(starts[1:]) + [len(heights) - 1], strict=True):
        if b - a >= 3:
            apexes.append(heights[a:b + 1].max())
    return np.array(apexes)


def bounce_figures(scene, trajectory, exp):
    p = exp.parameters
    h0, e, g = p["drop_height"], p["restitution"], p["gravity"]
    # Height of the lowest point above the plane: h0 at t = 0 by the scene's definition.
    centre = height(scene, trajectory, exp.body)
    z = centre - centre[0] + h0
    apex = _apexes(z, trajectory.times)
    figures = {}
    errors = []
    if e > 0:
        # Bounce k = 1, 2, ... while the expected apex is at least 1e-3 h0 (below, the apex is
        # within a few steps' worth of motion). The headline maximum covers the bounces whose
        # apex is at least 0.1 h0: an event-capturing scheme's apex error is of order v h / apex,
        # so the low bounces measure the step size more than the engine.
        for k, measured in enumerate(apex, start=1):
            expected = e ** (2 * k) * h0
            if expected < 1e-3 * h0:
                break
            figures[f"apex_{k}_relative_error"] = (measured - expected) / expected
            if expected >= 0.1 * h0:
                errors.append(figures[f"apex_{k}_relative_error"])
    figures["apex_max_relative_error"] = max(np.abs(errors)) if errors else 0.0
    rest = analytic.bouncing_ball_rest_time(h0, g, e) if e < 1 else math.inf
    figures["rest_time"] = rest
    after = trajectory.times >= rest + 0.02 * rest + 10 * trajectory.time_step
    figures["height_after_rest"] = float(np.max(np.abs(z[after]))) if after.any() else math.nan
    return (figures, "apex_max_relative_error",
            "lowest-point height; rest checked 2% + 10 steps after t_inf")


def _bounce_judge(case: Case) -> Judged:
    return (*percent("apex error", case.get("apex_max_relative_error"), 0.05),
            "apex within 5 %")


BOUNCE = register(MeasuredKind(
    "bounce_apex", bounce_figures,
    units={"apex_max_relative_error": of("the expected apex"),
           "apex_*_relative_error": of("the expected apex"), "rest_time": T,
           "height_after_rest": L},
    criterion=Criterion("every resolved apex within 5 % of e^(2k) h0", _bounce_judge),
    declaration=BOUNCE_APEX,
    analytic_error=(("apex_max_relative_error", None),),
    table=(TableColumn("apex_1_relative_error", "1st apex height, relative error", 100, "%",
                       shown=lambda p: p.get("restitution", 1.0) != 0),
           TableColumn("apex_max_relative_error", "worst apex height, relative error", 100,
                       "%", shown=lambda p: p.get("restitution", 1.0) != 0),
           TableColumn("height_after_rest", "height after t_inf", 1e3, "mm",
                       shown=lambda p: p.get("restitution", 0.0) <= 0)),
))


def rocking_figures(scene, trajectory, exp):
    p = exp.parameters
    alpha = analytic.rocking_block_slenderness(p["half_width"], p["half_height"])
    expected = analytic.rocking_block_velocity_ratio(alpha)
    b = scene.body_index(exp.body)
    q = quat_normalize_batch(trajectory.orientations[:, b])
    omega = quat_rotate_batch(q, trajectory.angular_velocities[:, b])
    # Tilt from upright about world y (the scene rocks the block in the xz-plane); an impact
    # is the step where the tilt changes sign: the block lands on its other corner and keeps
    # rotating the same way, slower by the ratio.
    tilt = 2.0 * np.arctan2(q[:, 2], q[:, 0])
    impacts = np.nonzero(np.sign(tilt[:-1]) * np.sign(tilt[1:]) < 0)[0]
    figures = {"expected_ratio": expected, "impacts": float(len(impacts))}
    ratios = [abs(omega[i + 1, 1] / omega[i, 1]) for i in impacts[:3] if omega[i, 1] != 0]
    if ratios:
        figures["ratio_first_impact"] = ratios[0]
        figures["ratio_relative_error"] = (ratios[0] - expected) / expected
    return figures, "ratio_relative_error", "rate in the recorded samples around the impact step"


def _rocking_judge(case: Case) -> Judged:
    return (*percent("impact ratio error", case.get("ratio_relative_error"), 0.05),
            "impact ratio within 5 %")


ROCKING = register(MeasuredKind(
    "rocking_ratio", rocking_figures,
    units={"expected_ratio": PURE, "impacts": COUNT, "ratio_first_impact": PURE,
           "ratio_relative_error": of("the expected ratio")},
    criterion=Criterion("first-impact ratio within 5 % of 1 - 1.5 sin^2(alpha)",
                        _rocking_judge),
    declaration=ROCKING_RATIO,
    analytic_error=(("ratio_relative_error", None),),
    table=(TableColumn("ratio_relative_error", "impact velocity ratio, relative error", 100,
                       "%"),),
))
