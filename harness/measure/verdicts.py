"""Pass/fail criteria: of each expectation in the harness's results and report, which
expectation figure is a run's analytic error, and the one verdict of a run that the overview
matrix and the CLI show (:func:`run_verdict`, from the run's status and its expectations).
(The run's status, ok or diverged, is :func:`clearbench.harness.measure.figures.measure`'s.)

The verdict of a run (:data:`VERDICTS`: label -> symbol, colour, meaning):

==================  ======  ===============================================================
verdict             symbol  when
==================  ======  ===============================================================
pass                ✓       finished (status ok) and every expectation judged passed
physics failed      ✗       finished, but an expectation of the scene failed
unseen penetration  ◐       finished, but the geometry instrument witnesses a penetration the
                            kernel's figure misses (:mod:`.geometry_check`)
no check            ○       finished, and the scene has no expectation that could be judged
diverged            ↯       NaN, energy gain, escape, tunnelling, a joint or driver broken
crashed             ☠       the engine or its worker died or raised
timed out           ⌛      the wall-clock limit was reached
unsupported         ∅       the engine cannot represent the scene (it says why)
==================  ======  ===============================================================

:func:`clearbench.harness.measure.expectation_figures.evaluate` states figures, not verdicts:
what is acceptable depends on the use. The harness's criteria, each relative to a scale of the
scene so that they hold in any unit system, are one table, :data:`CRITERIA` (expectation kind
-> what passes, in words, and the rule that judges it); :func:`criteria_table` writes it for
the docs and the report.

The headline error of a run where the scene has an analytic reference is the largest of
:data:`ANALYTIC_ERROR` over its expectations (a relative number).
"""

from __future__ import annotations

import math
from collections.abc import Callable
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
    "rolling_incline": (("distance_relative_error", None),),
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


#: A failed physics verdict when the scene's energy balance can be computed and the energy
#: grows by more than this fraction of its scale (the ``energy_balance`` check, and the
#: criterion of the energy expectations). Restitution e <= 1, friction and dampers take
#: energy, never give it, so the scene allows no growth: the allowance is the engine's
#: numerical error plus the error of the contact-energy estimate of a compliant engine (half
#: its normal force times the penetration, docs/harness.md "Energy"). Measured, a correct run
#: stays 8 times below it (rigid engines: 1e-6 or less; the quick suite's compliant runs
#: at most 0.12 %; the elastic ball row 0.14 % in mujoco[default]) and the smallest gain it
#: must catch is 8 times above it (+8 % of PyBullet on the elastic row).
ENERGY_GROWTH_ALLOWANCE = 0.01
#: Criterion of the stick expectations, and of the stick after a ``sliding_stop``: the body
#: moves by at most this fraction of its size.
STICK_FRACTION = 1e-4
#: ``rolling_incline``: slip speed of the contact point at most this fraction of the
#: velocity scale (the analytic speed at the end). An exact engine has none (reference,
#: Siconos: 1e-15 m/s); a soft or regularised friction slips by its creep: measured on
#: ``rolling-incline`` (final speed 1.68 m/s, bound 16.8 mm/s) 3.4 mm/s in mujoco and
#: pybullet, 4.5 mm/s in exudyn, 10 mm/s in exudyn[tuned], which also rolls 2.6 % too far
#: (``clearbench run rolling-incline -e ENGINE``). A ball sliding without rolling slips at
#: its whole speed.
ROLLING_SLIP_FRACTION = 0.01


@dataclass(frozen=True)
class Judgement:
    """Verdict of one expectation: ``passed`` (None when the figures allow none), the
    ``criterion`` in words, and ``detail``: the measured figure against its bound, with
    units and the place (``"0.639 mm > 0.1 mm (ball1-ball2)"``)."""

    passed: bool | None
    criterion: str
    detail: str


def _number(value: float) -> str:
    return f"{value:.3g}"


def _percent(name: str, value, bound: float) -> tuple[bool | None, str]:
    """Relative figure ``value`` against ``bound``, both as fractions, worded in percent."""
    passed = _within(value, bound)
    if passed is None:
        return None, f"{name} not measured"
    sign = "<=" if passed else ">"
    return passed, f"{name} {_number(100 * abs(value))} % {sign} {_number(100 * bound)} %"


def _bounded(name: str, value, bound: float, unit: str) -> tuple[bool | None, str]:
    """Figure ``value`` [unit] against ``bound`` [unit]."""
    passed = _within(value, bound)
    if passed is None:
        return None, f"{name} not measured"
    unit = f" {unit}" if unit else ""
    sign = "<=" if passed else ">"
    return passed, f"{name} {_number(abs(value))}{unit} {sign} {_number(bound)}{unit}"


def _all(parts: list[tuple[bool | None, str]]) -> tuple[bool | None, str]:
    """Every part must pass; a part not measured leaves the verdict to the others."""
    verdicts = [p for p, _ in parts if p is not None]
    passed = (all(verdicts) if verdicts else None)
    return passed, "; ".join(text for _, text in parts)


def judge(scene: Scene, kind: str, body: str | None, figures: dict) -> tuple[bool | None, str]:
    """(passed, criterion) of one expectation result; passed is None when the figures do not
    allow a verdict (no samples, event not reached). :func:`judgement` adds the detail."""
    result = judgement(scene, kind, body, figures)
    return result.passed, result.criterion


def unit_text(scene: Scene, dimension: tuple[int, int, int]) -> str:
    """The scene's unit of a (length, mass, time) dimension, e.g. ``mm``, ``m/s``, ``N``,
    ``kg m^2/s^2``; empty for a dimensionless value."""
    if tuple(dimension) == (0, 0, 0):
        return ""
    if tuple(dimension) == (1, 1, -2):
        return scene.units.force_unit()
    names = (scene.units.length, scene.units.mass, scene.units.time)
    up = [name if p == 1 else f"{name}^{p}" for name, p in zip(names, dimension, strict=True)
          if p > 0]
    down = [name if p == -1 else f"{name}^{-p}" for name, p in
            zip(names, dimension, strict=True) if p < 0]
    return " ".join(up or ["1"]) + ("/" + " ".join(down) if down else "")


@dataclass(frozen=True)
class _Case:
    """What a criterion judges: the scene, the expectation's body, its figures and the
    scene's :class:`~clearbench.scenarios.expectations.Expectation` (None when implied)."""

    scene: Scene
    body: str | None
    figures: dict
    expectation: object = None

    def get(self, name: str, default=None):
        return self.figures.get(name, default)

    @property
    def length(self) -> str:
        return self.scene.units.length

    def stick_bound(self) -> float:
        """:data:`STICK_FRACTION` of the body's size [L]."""
        return STICK_FRACTION * body_size(self.scene.body(self.body))


#: (passed or None, detail, criterion) of one judged expectation.
Judged = tuple


def _bounce_apex(case: _Case) -> Judged:
    return (*_percent("apex error", case.get("apex_max_relative_error"), 0.05),
            "apex within 5 %")


def _sticks(case: _Case) -> Judged:
    bound = case.stick_bound()
    return (*_bounded("displacement", case.get("displacement"), bound, case.length),
            f"displacement <= {bound:.3g}")


def _incline_slide(case: _Case) -> Judged:
    return (*_percent("acceleration error", case.get("acceleration_relative_error"), 0.02),
            "acceleration within 2 %")


def _sliding_stop(case: _Case) -> Judged:
    bound = case.stick_bound()
    stop = case.get("stop_time")
    parts = [_percent("stop distance error", analytic_error("sliding_stop", case.figures),
                      0.02)]
    if stop is None or not math.isfinite(stop):
        parts.append((False, "never stopped"))
    else:
        parts.append(_bounded(f"slid after the stop at {_number(stop)} "
                              f"{case.scene.units.time}", case.get("slide_after_stop"), bound,
                              case.length))
    return (*_all(parts), f"stop distance within 2 %, then sticks (slides <= {bound:.3g})")


def _rolling_transition(case: _Case) -> Judged:
    return (*_percent("final speed error", case.get("final_speed_relative_error"), 0.02),
            "final speed within 2 %")


def _rolling_incline(case: _Case) -> Judged:
    speed = case.get("expected_final_speed")
    bound = ROLLING_SLIP_FRACTION * speed if speed is not None else math.nan
    passed, detail = _all([
        _percent("distance error", case.get("distance_relative_error"), 0.02),
        _bounded("slip speed", case.get("slip_speed_max"), bound,
                 f"{case.length}/{case.scene.units.time}")])
    return passed, detail, (f"distance within 2 % of a t^2 / 2, slip <= "
                            f"{_number(100 * ROLLING_SLIP_FRACTION)} % of the final speed")


def _pendulum(case: _Case) -> Judged:
    return (*_all([_percent("period error", case.get("period_relative_error"), 0.01),
                   _percent("energy drift", case.get("energy_drift"), 0.01)]),
            "period within 1 %, energy drift <= 1 %")


def _torque_free(case: _Case) -> Judged:
    return (*_percent("momentum drift", case.get("angular_momentum_drift"), 0.01),
            "momentum drift <= 1 %")


def _slider_crank(case: _Case) -> Judged:
    return (*_percent("slider error", case.get("slider_position_relative_error"), 0.01),
            "slider position within 1 % of the crank")


def _rocking_ratio(case: _Case) -> Judged:
    return (*_percent("impact ratio error", case.get("ratio_relative_error"), 0.05),
            "impact ratio within 5 %")


def _approaches_ideal(case: _Case) -> Judged:
    return (*_bounded("clearance excess", case.get("clearance_excess_relative"), 1.0,
                      "clearances"), "excess <= one clearance")


def _energy_growth(case: _Case) -> Judged:
    return (*_percent("energy growth", case.get("energy_growth_relative"),
                      ENERGY_GROWTH_ALLOWANCE),
            f"energy growth <= {_number(100 * ENERGY_GROWTH_ALLOWANCE)} %")


def _energy_conserved(case: _Case) -> Judged:
    return (*_percent("energy drift", case.get("energy_drift_relative"),
                      ENERGY_GROWTH_ALLOWANCE),
            f"energy drift <= {_number(100 * ENERGY_GROWTH_ALLOWANCE)} %")


def _no_penetration(case: _Case) -> Judged:
    bound = 0.01 * smallest_contact_feature(case.scene)
    return (*_bounded("penetration", case.get("penetration_max"), bound, case.length),
            f"penetration <= {bound:.3g}")


def _output_value(case: _Case) -> Judged:
    expectation = case.expectation
    parameters = dict(expectation.parameters)
    output = next(o for o in case.scene.outputs if o.name == expectation.output)
    unit = unit_text(case.scene, output.dimension)
    passed, detail = _bounded(f"{output.name} off by", case.get("deviation"),
                              case.get("tolerance", math.nan), unit)
    if case.get("value") is not None:
        detail += (f": {_number(case.get('value'))} against {_number(case.get('expected'))}"
                   f"{' ' + unit if unit else ''}")
    tolerances = []
    if "absolute_tolerance" in parameters:
        tolerances.append(f"{_number(parameters['absolute_tolerance'])}"
                          f"{' ' + unit if unit else ''}")
    if "relative_tolerance" in parameters:
        tolerances.append(f"{_number(100 * parameters['relative_tolerance'])} % of the "
                          "expected value")
    return passed, detail, f"{output.name} within {' + '.join(tolerances)}"


@dataclass(frozen=True)
class Criterion:
    """The pass/fail rule of one expectation kind: what passes, in words (the table of the
    docs and the report), and ``judge(case) -> (passed or None, detail, criterion)``."""

    passes_when: str
    judge: Callable[[_Case], Judged]


_STICKS = Criterion("displacement <= 1e-4 of the body's size", _sticks)
_ENERGY_GROWTH = Criterion("energy growth <= 1 % of the energy scale", _energy_growth)

#: Expectation kind -> its criterion: the one table of the harness's pass/fail rules.
CRITERIA: dict[str, Criterion] = {
    "bounce_apex": Criterion("every resolved apex within 5 % of e^(2k) h0", _bounce_apex),
    "incline_stick": _STICKS,
    "sticks": _STICKS,
    "incline_slide": Criterion("acceleration within 2 % of g (sin - mu cos)", _incline_slide),
    "sliding_stop": Criterion("stop distance within 2 % of v0^2 / (2 mu g); stopped (speed "
                              "<= 1e-3 v0) and slides <= 1e-4 of its size after the stop",
                              _sliding_stop),
    "rolling_incline": Criterion("distance within 2 % of a t^2 / 2, a = g sin / (1 + "
                                 "I/(m r^2)); slip speed <= 1 % of the final speed a T",
                                 _rolling_incline),
    "rolling_transition": Criterion("final speed within 2 % of 5 v0 / 7", _rolling_transition),
    "pendulum": Criterion("period within 1 % and energy drift <= 1 % of m g d", _pendulum),
    "torque_free": Criterion("angular momentum drift <= 1 % of |L0|", _torque_free),
    "slider_crank": Criterion("slider position within 1 % of the crank length", _slider_crank),
    "rocking_ratio": Criterion("first-impact ratio within 5 % of 1 - 1.5 sin^2(alpha)",
                               _rocking_ratio),
    "approaches_ideal": Criterion("clearance excess <= one radial clearance",
                                  _approaches_ideal),
    "energy_non_increasing": _ENERGY_GROWTH,
    "energy_balance": Criterion("energy growth <= 1 % of the energy scale, on every run whose "
                                "scene's energy balance is computed (no driver, point force, "
                                "moment or law load): implied, not listed", _energy_growth),
    "output_value": Criterion("|y - expected| <= absolute + relative x |expected| tolerance",
                              _output_value),
    "energy_conserved": Criterion("energy drift <= 1 % of the energy scale", _energy_conserved),
    "no_penetration": Criterion("penetration <= 1 % of the smallest contact feature (radius, "
                                "half-extent or radial clearance)", _no_penetration),
}


def criteria_table() -> str:
    """:data:`CRITERIA` as a Markdown table (kinds with the same criterion on one row)."""
    rows: dict[str, list[str]] = {}
    for kind, criterion in CRITERIA.items():
        rows.setdefault(criterion.passes_when, []).append(kind)
    lines = ["| expectation | passes when |", "|---|---|"]
    lines += [f"| {', '.join(f'`{k}`' for k in kinds)} | {text.replace('|', chr(92) + '|')} |"
              for text, kinds in rows.items()]
    return "\n".join(lines)


def judgement(scene: Scene, kind: str, body: str | None, figures: dict,
              where: str = "", expectation=None) -> Judgement:
    """Pass/fail, criterion and detail of one expectation result of ``kind`` about ``body``
    with ``figures`` (:mod:`.expectation_figures`), by its :data:`CRITERIA` rule; ``where``
    names the place of the judged figure (a contact pair, a body) for the detail;
    ``expectation`` (the scene's
    :class:`~clearbench.scenarios.expectations.Expectation`, if any) gives its parameters."""
    criterion = CRITERIA.get(kind)
    if criterion is None:
        return Judgement(None, "no criterion", "no criterion")
    passed, detail, words = criterion.judge(_Case(scene, body, figures, expectation))
    if where and passed is not None:
        detail += f" ({where})"
    return Judgement(passed, words, detail)


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
    "unseen penetration": VerdictStyle("◐", "#f7c6a3", "finished, but the independent geometry "
                                       "instrument witnesses a penetration the kernel's figure "
                                       "does not show (harness/measure/geometry_check.py)"),
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


def run_verdict(status: str, expectations_passed, figures: dict | None = None) -> str:
    """The verdict of a run (a key of :data:`VERDICTS`) from its stored status and its
    ``expectations_passed`` (1 all judged passed, 0 one failed, None or NaN none judged);
    ``figures`` (the run's stored figures): an ok run with an ``unseen_penetration`` > 0 is
    "unseen penetration" (the run-wide geometry check)."""
    if status != "ok":
        if status not in _STATUS_VERDICTS:
            raise ValueError(f"unknown run status {status!r}")
        return _STATUS_VERDICTS[status]
    if figures and (figures.get("unseen_penetration") or 0.0) > 0.0:
        return "unseen penetration"
    if expectations_passed is None or (isinstance(expectations_passed, float)
                                       and math.isnan(expectations_passed)):
        return "no check"
    return "pass" if int(expectations_passed) else "physics failed"


def verdict_text(verdict: str) -> str:
    """Symbol and name of a verdict, e.g. ``"✗ physics failed"``."""
    return f"{VERDICTS[verdict].symbol} {verdict}"
