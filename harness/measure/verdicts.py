"""Pass/fail criteria: of each expectation in the harness's results and report, which
expectation figure is a run's analytic error, and the one verdict of a run that the overview
matrix and the CLI show (:func:`run_verdict`, from the run's status and its expectations).
(The run's status, ok or diverged, is :func:`clearbench.harness.measure.figures.measure`'s.)

The verdict of a run (:data:`VERDICTS`: label -> symbol, colour, meaning):

===============  ======  ===============================================================
verdict          symbol  when
===============  ======  ===============================================================
pass             ✓       finished (status ok) and every expectation judged passed
physics failed   ✗       finished, but an expectation of the scene failed
no check         ○       finished, and the scene has no expectation that could be judged
diverged         ↯       NaN, energy gain, escape, tunnelling, a joint or driver broken
crashed          ☠       the engine or its worker died or raised
timed out        ⌛      the wall-clock limit was reached
unsupported      ∅       the engine cannot represent the scene (it says why)
===============  ======  ===============================================================

:func:`clearbench.harness.measure.expectation_figures.evaluate` states figures, not verdicts:
what is acceptable depends on the use. These are the harness's criteria (shown in the report), each
relative to a scale of the scene so that they hold in any unit system:

=========================  ============================================================
kind                        passes when
=========================  ============================================================
bounce_apex                 every resolved apex within 5 % of e^(2k) h0
incline_stick, sticks       displacement <= 1e-4 of the body's size
incline_slide               acceleration within 2 % of g (sin - mu cos)
sliding_stop                stop distance within 2 % of v0^2 / (2 mu g)
rolling_transition          final speed within 2 % of 5 v0 / 7
pendulum                    period within 1 % and energy drift <= 1 % of m g d
torque_free                 angular momentum drift <= 1 % of |L0|
slider_crank                slider position within 1 % of the crank length
rocking_ratio               first-impact ratio within 5 % of 1 - 1.5 sin^2(alpha)
approaches_ideal            clearance excess <= one radial clearance
energy_non_increasing       energy growth <= 1 % of the energy scale
energy_conserved            energy drift <= 1 % of the energy scale
no_penetration              penetration <= 1 % of the smallest contact feature (radius,
                            half-extent or radial clearance)
=========================  ============================================================

The headline error of a run where the scene has an analytic reference is the largest of
:data:`ANALYTIC_ERROR` over its expectations (a relative number).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from clearbench.scenarios.scales import body_size, smallest_contact_feature
from clearbench.scenarios.scene import Scene

#: kind -> figure of :mod:`.expectation_figures` that is the run's relative error against the
#: analytic solution (first one present is used), and the figure that normalises it if any.
ANALYTIC_ERROR: dict[str, tuple[tuple[str, str | None], ...]] = {
    "bounce_apex": (("apex_max_relative_error", None),),
    "incline_slide": (("acceleration_relative_error", None),),
    "sliding_stop": (("stop_distance_error", "expected_stop_distance"),),
    "rolling_transition": (("final_speed_relative_error", None),),
    "pendulum": (("period_relative_error", None), ("energy_drift", None)),
    "torque_free": (("angular_momentum_drift", None),),
    "slider_crank": (("slider_position_relative_error", None),),
    "rocking_ratio": (("ratio_relative_error", None),),
}


def analytic_error(kind: str, figures: dict) -> float:
    """|relative error| against the analytic solution, NaN when the kind has none or the
    figure is missing."""
    for name, normaliser in ANALYTIC_ERROR.get(kind, ()):
        value = figures.get(name)
        if value is None or not math.isfinite(value):
            continue
        if normaliser is not None:
            scale = figures.get(normaliser)
            if not scale:
                continue
            value = value / scale
        return abs(float(value))
    return math.nan


def _within(value, bound) -> bool | None:
    if value is None or not math.isfinite(value):
        return None
    return abs(value) <= bound


def judge(scene: Scene, kind: str, body: str | None, figures: dict) -> tuple[bool | None, str]:
    """(passed, criterion) of one expectation result; passed is None when the figures do not
    allow a verdict (no samples, event not reached)."""
    get = figures.get
    if kind == "bounce_apex":
        return _within(get("apex_max_relative_error"), 0.05), "apex within 5 %"
    if kind in ("incline_stick", "sticks"):
        bound = 1e-4 * body_size(scene.body(body))
        return _within(get("displacement"), bound), f"displacement <= {bound:.3g}"
    if kind == "incline_slide":
        return _within(get("acceleration_relative_error"), 0.02), "acceleration within 2 %"
    if kind == "sliding_stop":
        return _within(analytic_error(kind, figures), 0.02), "stop distance within 2 %"
    if kind == "rolling_transition":
        return _within(get("final_speed_relative_error"), 0.02), "final speed within 2 %"
    if kind == "pendulum":
        period = _within(get("period_relative_error"), 0.01)
        energy = _within(get("energy_drift"), 0.01)
        verdicts = [v for v in (period, energy) if v is not None]
        return (all(verdicts) if verdicts else None), "period within 1 %, energy drift <= 1 %"
    if kind == "torque_free":
        return _within(get("angular_momentum_drift"), 0.01), "momentum drift <= 1 %"
    if kind == "slider_crank":
        return _within(get("slider_position_relative_error"), 0.01), \
            "slider position within 1 % of the crank"
    if kind == "rocking_ratio":
        return _within(get("ratio_relative_error"), 0.05), "impact ratio within 5 %"
    if kind == "approaches_ideal":
        return _within(get("clearance_excess_relative"), 1.0), "excess <= one clearance"
    if kind == "energy_non_increasing":
        return _within(get("energy_growth_relative"), 0.01), "energy growth <= 1 %"
    if kind == "energy_conserved":
        return _within(get("energy_drift_relative"), 0.01), "energy drift <= 1 %"
    if kind == "no_penetration":
        bound = 0.01 * smallest_contact_feature(scene)
        return _within(get("penetration_max"), bound), f"penetration <= {bound:.3g}"
    return None, "no criterion"


@dataclass(frozen=True)
class VerdictStyle:
    """How a verdict is shown: a symbol (readable in print and without colour vision), a
    background colour, and what it means."""

    symbol: str
    colour: str
    meaning: str


#: Every verdict of :func:`run_verdict`, best first. Colours are light tints told apart by
#: lightness as well as hue; the symbol carries the verdict on its own.
VERDICTS: dict[str, VerdictStyle] = {
    "pass": VerdictStyle("✓", "#cde9d0", "finished; every expectation of the scene passed"),
    "physics failed": VerdictStyle("✗", "#ffd98a", "finished, but an expectation of the scene "
                                   "failed (wrong physics)"),
    "no check": VerdictStyle("○", "#f2f2f2", "finished; no expectation of the scene could be "
                             "judged"),
    "diverged": VerdictStyle("↯", "#f2a08f", "stopped or judged broken: NaN, energy gain, "
                             "escape, tunnelling, a joint or driver broken"),
    "crashed": VerdictStyle("☠", "#c9a3d9", "the engine or its worker died or raised"),
    "timed out": VerdictStyle("⌛", "#a9c8ec", "the wall-clock limit was reached"),
    "unsupported": VerdictStyle("∅", "#d6d6d6", "the engine cannot represent the scene"),
}

#: Run status (:class:`~clearbench.adapters.trajectory.RunStatus` value) -> verdict, for every
#: status but ok (whose verdict depends on the expectations).
_STATUS_VERDICTS = {"diverged": "diverged", "crashed": "crashed", "timed_out": "timed out",
                    "unsupported": "unsupported"}


def run_verdict(status: str, expectations_passed) -> str:
    """The verdict of a run (a key of :data:`VERDICTS`) from its stored status and its
    ``expectations_passed`` (1 all judged passed, 0 one failed, None or NaN none judged)."""
    if status != "ok":
        if status not in _STATUS_VERDICTS:
            raise ValueError(f"unknown run status {status!r}")
        return _STATUS_VERDICTS[status]
    if expectations_passed is None or (isinstance(expectations_passed, float)
                                       and math.isnan(expectations_passed)):
        return "no check"
    return "pass" if int(expectations_passed) else "physics failed"


def verdict_text(verdict: str) -> str:
    """Symbol and name of a verdict, e.g. ``"✗ physics failed"``."""
    return f"{VERDICTS[verdict].symbol} {verdict}"
