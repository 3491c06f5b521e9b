"""An expectation kind declared outside the library, in this one module: ``free_fall`` (a body
released in free flight follows z0 + vz0 t - g t^2 / 2).

It shows that adding a kind touches one module: its scene side (parameters with dimensions and
domains), its figure handler, its criterion and words, its analytic-error figure, the units
of its figures and its table column are declared here and registered with one call
(:func:`clearbench.harness.measure.kinds.register`, or ``registered`` for a while, as the tests
do), and the harness measures, judges, tables and reports it with no other edit
(tests/test_expectation_kind_example.py).
"""

from __future__ import annotations

import numpy as np

from clearbench.harness.measure.criteria import Case, Criterion, Judged, percent
from clearbench.harness.measure.kinds import MeasuredKind, TableColumn
from clearbench.harness.measure.kinds.common import height
from clearbench.harness.measure.quantities import L, of
from clearbench.scenarios.expectation_kinds import (
    POSITIVE,
    ExpectationKind,
    Parameter,
    gravity_is_the_scenes,
)
from clearbench.scenarios.validation import ACCELERATION

#: The criterion's bound: the height error over the fall height. Symplectic Euler (the fake
#: engine) is off by g t h / 2 at time t, 0.35 % of the 0.44 m fall after 0.3 s at h = 1 ms,
#: a third of this bound; a body that does not fall at all is off by 100 %.
HEIGHT_TOLERANCE = 0.01

FREE_FALL_DECLARATION = ExpectationKind(
    "free_fall",
    "the body's centre of mass follows z0 + vz0 t - g t^2 / 2 (no contact, no joint)",
    {"gravity": Parameter(ACCELERATION, POSITIVE, meaning="magnitude of gravity")},
    scene_checks=(gravity_is_the_scenes,),
)


def free_fall_figures(scene, trajectory, expectation):
    """Largest error of the centre's height against the parabola [L], and relative to the
    fall height over the run."""
    g = expectation.parameters["gravity"]
    t = trajectory.times - trajectory.times[0]
    z = height(scene, trajectory, expectation.body)
    body = scene.body(expectation.body)
    up = -np.asarray(scene.gravity, dtype=float) / g
    expected = z[0] + float(np.asarray(body.velocity) @ up) * t - 0.5 * g * t**2
    error = float(np.max(np.abs(z - expected)))
    fall = float(np.max(np.abs(expected - expected[0]))) or 1.0
    return ({"height_max_error": error, "height_relative_error": error / fall},
            "height_relative_error", "centre of mass against the parabola")


def _judge(case: Case) -> Judged:
    return (*percent("height error", case.get("height_relative_error"), HEIGHT_TOLERANCE),
            "height within 1 % of the fall")


FREE_FALL = MeasuredKind(
    "free_fall", free_fall_figures,
    units={"height_max_error": L, "height_relative_error": of("the fall height")},
    criterion=Criterion("height within 1 % of the fall height of z0 + vz0 t - g t^2 / 2",
                        _judge),
    declaration=FREE_FALL_DECLARATION,
    analytic_error=(("height_relative_error", None),),
    table=(TableColumn("height_max_error", "free-fall height error", 1e3, "mm"),),
)
