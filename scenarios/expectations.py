"""Physics expectations: what a scene must do, when physics says so.

Each expectation has a ``kind`` from :data:`EXPECTATION_KINDS`, which fixes the parameters it
takes and their physical dimensions, and what the harness checks (the analytic formulas live in
:mod:`.analytic`). ``body`` names the body it is about, where one is.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from types import MappingProxyType

from clearbench.scenarios.element import Element
from clearbench.scenarios.validation import (
    ACCELERATION,
    ANGULAR_VELOCITY,
    DIMENSIONLESS,
    INERTIA,
    LENGTH,
    MASS,
    TIME,
    VELOCITY,
    SceneError,
    check_finite,
)

#: Marks a parameter whose dimension is that of the expectation's output
#: (``output_value``): the scene converts it with the output's unit (Scene.rescaled).
OUTPUT_DIMENSION = "output"


@dataclass(frozen=True)
class ExpectationKind:
    """Parameters (name -> dimension, or :data:`OUTPUT_DIMENSION`) and the statement
    checked; ``optional`` parameters may be left out, and at least one of each group in
    ``one_of`` must be given."""

    parameters: MappingProxyType
    statement: str
    needs_body: bool = True
    optional: frozenset = frozenset()
    one_of: tuple = ()
    needs_output: bool = False


def _kind(statement: str, needs_body: bool = True, optional=(), one_of=(),
          needs_output: bool = False, **parameters) -> ExpectationKind:
    return ExpectationKind(MappingProxyType(parameters), statement, needs_body,
                           frozenset(optional), tuple(one_of), needs_output)


EXPECTATION_KINDS: dict[str, ExpectationKind] = {
    "bounce_apex": _kind(
        "apex heights e^(2k) h0 of the lowest point; at rest from t_inf = (v0/g)(1+e)/(1-e)",
        drop_height=LENGTH, restitution=DIMENSIONLESS, gravity=ACCELERATION,
    ),
    "incline_stick": _kind(
        "tan(angle) <= mu: the body must not move (exact stick)",
        angle=DIMENSIONLESS, friction=DIMENSIONLESS,
    ),
    "incline_slide": _kind(
        "tan(angle) > mu: slides down with acceleration g (sin - mu cos)",
        angle=DIMENSIONLESS, friction=DIMENSIONLESS, gravity=ACCELERATION,
    ),
    "sliding_stop": _kind(
        "stops after v0/(mu g), at distance v0^2/(2 mu g), then sticks",
        initial_speed=VELOCITY, friction=DIMENSIONLESS, gravity=ACCELERATION,
    ),
    "rolling_incline": _kind(
        "rolls down the incline without slipping: distance a t^2 / 2 with "
        "a = g sin(angle) / (1 + I/(m r^2)) (I about the rolling axis), contact point at rest",
        angle=DIMENSIONLESS, gravity=ACCELERATION, radius=LENGTH,
    ),
    "rolling_transition": _kind(
        "rolls without slip from t = 2 v0/(7 mu g) at speed 5 v0/7",
        initial_speed=VELOCITY, friction=DIMENSIONLESS, gravity=ACCELERATION, radius=LENGTH,
    ),
    "pendulum": _kind(
        "energy conserved; period 4 sqrt(I_p/(m g d)) K(sin(theta0/2))",
        mass=MASS, pivot_distance=LENGTH, pivot_inertia=INERTIA, gravity=ACCELERATION,
        initial_angle=DIMENSIONLESS,
    ),
    "torque_free": _kind(
        "kinetic energy and angular momentum conserved; rotation near the intermediate axis "
        "flips periodically",
    ),
    "slider_crank": _kind(
        "slider position x = l1 cos(theta) + sqrt(l2^2 - (l1 sin(theta) - offset)^2)",
        crank_length=LENGTH, rod_length=LENGTH, crank_speed=ANGULAR_VELOCITY, offset=LENGTH,
    ),
    "approaches_ideal": _kind(
        "the motion approaches the ideal-joint motion as the clearance goes to zero",
        radial_clearance=LENGTH,
    ),
    "rocking_ratio": _kind(
        "angular-velocity ratio 1 - 1.5 sin^2(alpha) at each impact, alpha = atan(b/h)",
        half_width=LENGTH, half_height=LENGTH, gravity=ACCELERATION,
    ),
    "sticks": _kind(
        "the body must not move between start_time and end_time",
        start_time=TIME, end_time=TIME,
    ),
    "energy_non_increasing": _kind("total mechanical energy never grows", needs_body=False),
    "energy_conserved": _kind("total mechanical energy is conserved", needs_body=False),
    "no_penetration": _kind("no contact gap below zero", needs_body=False),
    "output_value": _kind(
        "the named output equals value at time (the end if no time) within absolute_tolerance"
        " + relative_tolerance x |value| (either or both; value and absolute_tolerance in the "
        "output's unit)",
        needs_body=False, needs_output=True,
        optional=("time", "absolute_tolerance", "relative_tolerance"),
        one_of=(("absolute_tolerance", "relative_tolerance"),),
        value=OUTPUT_DIMENSION, absolute_tolerance=OUTPUT_DIMENSION,
        relative_tolerance=DIMENSIONLESS, time=TIME,
    ),
}


@dataclass(frozen=True)
class Expectation(Element):
    """An expectation of ``kind`` about ``body`` (or the named ``output``, for
    ``output_value``) with ``parameters`` (name -> value, in the scene's units; dimensions
    fixed by the kind)."""

    collection = "expectations"
    kind: str = ""
    body: str | None = None
    parameters: MappingProxyType = field(default_factory=lambda: MappingProxyType({}))
    output: str | None = None

    def _validate(self) -> None:
        if self.kind not in EXPECTATION_KINDS:
            raise SceneError("kind", self.kind, f"must be one of {sorted(EXPECTATION_KINDS)}")
        spec = EXPECTATION_KINDS[self.kind]
        if spec.needs_body and not self.body:
            raise SceneError("body", self.body, f"expectation {self.kind!r} needs a body")
        if spec.needs_output and not self.output:
            raise SceneError("output", self.output,
                             f"expectation {self.kind!r} needs the name of an [[outputs]] entry")
        if self.output is not None and not spec.needs_output:
            raise SceneError("output", self.output, f"expectation {self.kind!r} takes no output")
        given = dict(self.parameters)
        missing = sorted(set(spec.parameters) - spec.optional - set(given))
        unknown = sorted(set(given) - set(spec.parameters))
        if missing:
            raise SceneError("parameters", given, f"missing {missing} for {self.kind!r}")
        if unknown:
            raise SceneError("parameters", given, f"unknown {unknown} for {self.kind!r}")
        for group in spec.one_of:
            if not set(group) & set(given):
                raise SceneError("parameters", given,
                                 f"{self.kind!r} needs at least one of {list(group)}")
        for key, value in given.items():
            check_finite(f"parameters.{key}", value)
            if key.endswith("tolerance") and float(value) < 0:
                raise SceneError(f"parameters.{key}", value, "must be >= 0")
        self._set("parameters", MappingProxyType({k: float(given[k]) for k in spec.parameters
                                                  if k in given}))

    @property
    def statement(self) -> str:
        return EXPECTATION_KINDS[self.kind].statement

    def field_dimension(self, name: str) -> dict | None:
        """Dimensions of the entries of ``parameters``."""
        if name == "parameters":
            # Parameters in the output's unit are converted by the scene (Scene.rescaled),
            # which knows the output: here they are left as they are.
            return {key: (DIMENSIONLESS if dimension == OUTPUT_DIMENSION else dimension)
                    for key, dimension in EXPECTATION_KINDS[self.kind].parameters.items()
                    if key in self.parameters}
        return None

    def __hash__(self) -> int:
        return hash((self.name, self.kind, self.body, tuple(self.parameters.items()),
                     self.output))
