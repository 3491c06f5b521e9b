"""The kind about a named output of the scene: ``output_value`` (an output equals a value at a
time, within a tolerance)."""

from __future__ import annotations

import math

import numpy as np

from clearbench.harness.measure import series as metrics
from clearbench.harness.measure.criteria import Case, Criterion, Judged, bounded, number, unit_text
from clearbench.harness.measure.kinds.registry import MeasuredKind, register
from clearbench.harness.measure.quantities import T
from clearbench.scenarios.expectation_kinds import OUTPUT_VALUE

#: Figures of an ``output_value`` expectation in the unit of its output (not in ``units``:
#: that unit is the output's, :func:`clearbench.harness.measure.units.figure_unit`).
OUTPUT_VALUE_FIGURES = ("value", "expected", "deviation", "tolerance")


def output_value_figures(scene, trajectory, exp):
    """The named output at ``time`` (interpolated between samples; the last sample without
    it) against ``value``: tolerance = absolute + relative x |value|."""
    p = exp.parameters
    values = metrics.output_values(scene, trajectory)[exp.output]
    times = trajectory.times
    at = p.get("time", float(times[-1]))
    if not times[0] <= at <= times[-1] * (1.0 + 1e-12):
        return {"expected": p["value"], "time": at}, "deviation", "time outside the run"
    value = float(np.interp(at, times, values))
    tolerance = p.get("absolute_tolerance", 0.0) + p.get("relative_tolerance", 0.0) * abs(
        p["value"])
    return ({"value": value, "expected": p["value"], "deviation": abs(value - p["value"]),
             "tolerance": tolerance, "time": at, "where": f"at t = {at:.4g} {scene.units.time}"},
            "deviation", "")


def _output_value_judge(case: Case) -> Judged:
    expectation = case.expectation
    parameters = dict(expectation.parameters)
    output = next(o for o in case.scene.outputs if o.name == expectation.output)
    unit = unit_text(case.scene, output.dimension)
    passed, detail = bounded(f"{output.name} off by", case.get("deviation"),
                             case.get("tolerance", math.nan), unit)
    if case.get("value") is not None:
        detail += (f": {number(case.get('value'))} against {number(case.get('expected'))}"
                   f"{' ' + unit if unit else ''}")
    tolerances = []
    if "absolute_tolerance" in parameters:
        tolerances.append(f"{number(parameters['absolute_tolerance'])}"
                          f"{' ' + unit if unit else ''}")
    if "relative_tolerance" in parameters:
        tolerances.append(f"{number(100 * parameters['relative_tolerance'])} % of the "
                          "expected value")
    return passed, detail, f"{output.name} within {' + '.join(tolerances)}"


OUTPUT_VALUE_KIND = register(MeasuredKind(
    "output_value", output_value_figures, units={"time": T},
    criterion=Criterion("|y - expected| <= absolute + relative x |expected| tolerance",
                        _output_value_judge),
    declaration=OUTPUT_VALUE,
))
