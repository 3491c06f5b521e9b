"""The scene side of the expectation kinds: what a scene writer writes, and what it means.

An :class:`ExpectationKind` declares the parameters an expectation of that kind takes, each
with its physical dimension and its domain (:class:`Parameter`, :class:`Domain`), the
relations between them and with the scene that its meaning requires (:class:`Relation`,
``scene_checks``), and the statement it makes. An expectation is validated against its kind
when it is built and again, for the scene relations, when its scene is built, so a parameter
that makes no sense (a negative initial speed, a stick window that ends before it starts) is
refused naming the field and the value before any engine runs.

This is the half of a kind that the scene layer needs (validation, rescaling, the energy
guard). The measuring half (the figures, the criterion and its words, the analytic-error
figure, the table columns) is declared with it in one object of the harness
(:mod:`clearbench.harness.measure.kinds`), which refers to the declaration here; a kind kept
outside the library declares both halves in one module and registers them together
(:func:`clearbench.harness.measure.kinds.register`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from types import MappingProxyType

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
class Domain:
    """The values a parameter may take: a finite number in an interval, bounds open or closed,
    zero excluded when ``nonzero``."""

    low: float = -math.inf
    high: float = math.inf
    low_open: bool = False
    high_open: bool = False
    nonzero: bool = False

    def contains(self, value: float) -> bool:
        above = value > self.low if self.low_open else value >= self.low
        below = value < self.high if self.high_open else value <= self.high
        return above and below and not (self.nonzero and value == 0.0)

    def text(self) -> str:
        """The domain in words: ``> 0``, ``in [0, 1]``, ``in (-3.14, 3.14), not 0``."""
        if self.low == -math.inf and self.high == math.inf:
            words = "finite"
        elif self.high == math.inf:
            words = f"{'>' if self.low_open else '>='} {self.low:g}"
        elif self.low == -math.inf:
            words = f"{'<' if self.high_open else '<='} {self.high:g}"
        else:
            words = (f"in {'(' if self.low_open else '['}{self.low:.6g}, {self.high:.6g}"
                     f"{')' if self.high_open else ']'}")
        return words + (", not 0" if self.nonzero else "")


ANY = Domain()
POSITIVE = Domain(0.0, low_open=True)
NON_NEGATIVE = Domain(0.0)
UNIT_INTERVAL = Domain(0.0, 1.0)
#: An incline's angle [rad]: between flat (excluded) and vertical (excluded).
INCLINE_ANGLE = Domain(0.0, 0.5 * math.pi, low_open=True, high_open=True)


@dataclass(frozen=True)
class Parameter:
    """One parameter of a kind: its dimension (exponents of length, mass, time, or
    :data:`OUTPUT_DIMENSION`), its domain, whether it may be left out, and what it is."""

    dimension: tuple | str
    domain: Domain = ANY
    optional: bool = False
    meaning: str = ""


@dataclass(frozen=True)
class Relation:
    """A condition between parameters that the kind's meaning needs: ``holds(values)`` is
    False when it is broken (it sees only the parameters given), and then ``field`` (a
    parameter) is named with ``reason``."""

    field: str
    holds: Callable[[Mapping[str, float]], bool]
    reason: str


#: ``(scene, expectation) -> (field, value, reason)`` of a broken relation with the scene,
#: or None: run when the scene is built.
SceneCheck = Callable[[object, object], tuple | None]


@dataclass(frozen=True)
class ExpectationKind:
    """The scene side of an expectation kind.

    Parameters
    ----------
    name : str
        The ``kind`` a scene writes.
    statement : str
        What physics says must happen, in words.
    parameters : mapping name -> Parameter
    needs_body : bool
        The expectation names the ``body`` it is about.
    needs_output : bool
        The expectation names an ``[[outputs]]`` entry (``output``).
    one_of : tuple of tuples
        Groups of optional parameters of which at least one must be given.
    relations : tuple of Relation
        Conditions between the parameters.
    scene_checks : tuple of SceneCheck
        Conditions between the parameters and the scene (its gravity, its horizon).
    energy_may_not_grow : bool
        The expectation says the scene's mechanical energy may not grow (the engines' energy
        guard and the harness's energy verdict read it).
    energy_conserved : bool
        The expectation says the energy is conserved: it judges a loss as well as a gain (the
        harness's implied conservation check then leaves the scene to it).
    body_stays : bool
        The expectation says its body must not move (between ``start_time`` and ``end_time``
        when it has them): the run's stiction figures are measured on it.
    """

    name: str
    statement: str
    parameters: Mapping[str, Parameter] = field(default_factory=dict)
    needs_body: bool = True
    needs_output: bool = False
    one_of: tuple = ()
    relations: tuple[Relation, ...] = ()
    scene_checks: tuple = ()
    energy_may_not_grow: bool = False
    energy_conserved: bool = False
    body_stays: bool = False

    def __post_init__(self) -> None:
        object.__setattr__(self, "parameters", MappingProxyType(dict(self.parameters)))
        for group in self.one_of:
            unknown = set(group) - set(self.parameters)
            if unknown:
                raise ValueError(f"kind {self.name!r}: one_of names unknown {sorted(unknown)}")
        for relation in self.relations:
            if relation.field not in self.parameters:
                raise ValueError(f"kind {self.name!r}: relation on unknown {relation.field!r}")

    @property
    def required(self) -> frozenset:
        return frozenset(k for k, p in self.parameters.items() if not p.optional)

    def check_parameters(self, given: Mapping) -> dict[str, float]:
        """The parameters ``given`` as floats, in declaration order; SceneError naming the
        first one missing, unknown, outside its domain or breaking a relation."""
        missing = sorted(self.required - set(given))
        unknown = sorted(set(given) - set(self.parameters))
        if missing:
            raise SceneError("parameters", dict(given), f"missing {missing} for {self.name!r}")
        if unknown:
            raise SceneError("parameters", dict(given), f"unknown {unknown} for {self.name!r}")
        for group in self.one_of:
            if not set(group) & set(given):
                raise SceneError("parameters", dict(given),
                                 f"{self.name!r} needs at least one of {list(group)}")
        values = {}
        for key, parameter in self.parameters.items():
            if key not in given:
                continue
            value = check_finite(f"parameters.{key}", given[key])
            if not parameter.domain.contains(value):
                what = f" ({parameter.meaning})" if parameter.meaning else ""
                raise SceneError(f"parameters.{key}", given[key],
                                 f"must be {parameter.domain.text()}{what}")
            values[key] = value
        for relation in self.relations:
            if not relation.holds(values):
                raise SceneError(f"parameters.{relation.field}", values.get(relation.field),
                                 relation.reason)
        return values

    def check_in_scene(self, scene, expectation) -> None:
        """SceneError naming the parameter of ``expectation`` that contradicts ``scene``."""
        for check in self.scene_checks:
            broken = check(scene, expectation)
            if broken is not None:
                key, value, reason = broken
                raise SceneError(f"expectations[{expectation.name!r}].parameters.{key}", value,
                                 reason)


#: Every expectation kind a scene may write, by name.
EXPECTATION_KINDS: dict[str, ExpectationKind] = {}


def declare_kind(kind: ExpectationKind) -> ExpectationKind:
    """Add ``kind`` to :data:`EXPECTATION_KINDS` (the same declaration twice is harmless; another
    one under a taken name is refused)."""
    known = EXPECTATION_KINDS.get(kind.name)
    if known is not None and known is not kind:
        raise ValueError(f"expectation kind {kind.name!r} declared twice")
    EXPECTATION_KINDS[kind.name] = kind
    return kind


def withdraw_kind(name: str) -> None:
    """Remove the kind ``name`` (a kind declared for a while, by a test)."""
    EXPECTATION_KINDS.pop(name, None)


def energy_may_not_grow(kind: str) -> bool:
    """Whether an expectation of ``kind`` says the scene's energy may not grow."""
    declared = EXPECTATION_KINDS.get(kind)
    return declared is not None and declared.energy_may_not_grow


def judges_energy_loss(kind: str) -> bool:
    """Whether an expectation of ``kind`` says the scene's energy is conserved (a loss fails
    it)."""
    declared = EXPECTATION_KINDS.get(kind)
    return declared is not None and declared.energy_conserved


def body_stays(kind: str) -> bool:
    """Whether an expectation of ``kind`` says its body must not move."""
    declared = EXPECTATION_KINDS.get(kind)
    return declared is not None and declared.body_stays


# ------------------------------------------------------------------ relations shared by kinds
def gravity_is_the_scenes(scene, expectation) -> tuple | None:
    """The ``gravity`` parameter is the magnitude of the scene's gravity (1e-6 relative: the
    same number written with fewer digits is a different physics, not round-off)."""
    value = expectation.parameters.get("gravity")
    if value is None:
        return None
    magnitude = math.sqrt(sum(g * g for g in scene.gravity))
    if abs(value - magnitude) > 1e-6 * magnitude:
        return ("gravity", value, f"must be the magnitude of the scene's gravity "
                f"{magnitude:.6g} (the closed form is that of the scene's physics)")
    return None


def window_starts_within_the_horizon(scene, expectation) -> tuple | None:
    """A time window (``start_time``) starts before the scene's horizon: a window after the
    run's end judges nothing."""
    start = expectation.parameters.get("start_time")
    if start is not None and start >= scene.horizon:
        return ("start_time", start, f"must be before the scene's horizon {scene.horizon:g}")
    return None


def time_within_the_horizon(scene, expectation) -> tuple | None:
    """An instant (``time``) lies within the scene's horizon."""
    time = expectation.parameters.get("time")
    if time is not None and time > scene.horizon:
        return ("time", time, f"must be within the scene's horizon {scene.horizon:g}")
    return None


def _given(values, *keys) -> bool:
    return all(k in values for k in keys)


def _within_friction_cone(values) -> bool:
    return math.tan(values["angle"]) <= values["friction"]


# ------------------------------------------------------------------ the library's kinds
_G = Parameter(ACCELERATION, POSITIVE, meaning="magnitude of gravity")
_FRICTION = Parameter(DIMENSIONLESS, NON_NEGATIVE, meaning="Coulomb coefficient mu")
_SLIDING_FRICTION = Parameter(DIMENSIONLESS, POSITIVE,
                              meaning="Coulomb coefficient mu: without friction nothing stops")
_V0 = Parameter(VELOCITY, POSITIVE, meaning="initial speed, a magnitude")

BOUNCE_APEX = declare_kind(ExpectationKind(
    "bounce_apex",
    "apex heights e^(2k) h0 of the lowest point; at rest from t_inf = (v0/g)(1+e)/(1-e)",
    {"drop_height": Parameter(LENGTH, POSITIVE, meaning="height of the lowest point at rest"),
     "restitution": Parameter(DIMENSIONLESS, UNIT_INTERVAL, meaning="Newton's e"),
     "gravity": _G},
    scene_checks=(gravity_is_the_scenes,),
))
INCLINE_STICK = declare_kind(ExpectationKind(
    "incline_stick",
    "tan(angle) <= mu: the body must not move (exact stick)",
    {"angle": Parameter(DIMENSIONLESS, Domain(0.0, 0.5 * math.pi, high_open=True),
                        meaning="incline angle [rad]"),
     "friction": _FRICTION},
    relations=(Relation("angle", _within_friction_cone,
                        "tan(angle) must be <= friction for the body to stick"),),
    body_stays=True,
))
INCLINE_SLIDE = declare_kind(ExpectationKind(
    "incline_slide",
    "tan(angle) > mu: slides down with acceleration g (sin - mu cos)",
    {"angle": Parameter(DIMENSIONLESS, INCLINE_ANGLE, meaning="incline angle [rad]"),
     "friction": _FRICTION, "gravity": _G},
    relations=(Relation("angle", lambda v: not _within_friction_cone(v),
                        "tan(angle) must be > friction for the body to slide"),),
    scene_checks=(gravity_is_the_scenes,),
))
SLIDING_STOP = declare_kind(ExpectationKind(
    "sliding_stop",
    "stops after v0/(mu g), at distance v0^2/(2 mu g), then sticks",
    {"initial_speed": _V0, "friction": _SLIDING_FRICTION, "gravity": _G},
    scene_checks=(gravity_is_the_scenes,),
))
ROLLING_INCLINE = declare_kind(ExpectationKind(
    "rolling_incline",
    "rolls down the incline without slipping: distance a t^2 / 2 with "
    "a = g sin(angle) / (1 + I/(m r^2)) (I about the rolling axis), contact point at rest",
    {"angle": Parameter(DIMENSIONLESS, INCLINE_ANGLE, meaning="incline angle [rad]"),
     "gravity": _G, "radius": Parameter(LENGTH, POSITIVE, meaning="rolling radius")},
    scene_checks=(gravity_is_the_scenes,),
))
ROLLING_TRANSITION = declare_kind(ExpectationKind(
    "rolling_transition",
    "rolls without slip from t = 2 v0/(7 mu g) at speed 5 v0/7",
    {"initial_speed": _V0, "friction": _SLIDING_FRICTION, "gravity": _G,
     "radius": Parameter(LENGTH, POSITIVE, meaning="sphere radius")},
    scene_checks=(gravity_is_the_scenes,),
))
PENDULUM = declare_kind(ExpectationKind(
    "pendulum",
    "energy conserved; period 4 sqrt(I_p/(m g d)) K(sin(theta0/2))",
    {"mass": Parameter(MASS, POSITIVE),
     "pivot_distance": Parameter(LENGTH, POSITIVE, meaning="pivot to centre of mass"),
     "pivot_inertia": Parameter(INERTIA, POSITIVE, meaning="inertia about the pivot axis"),
     "gravity": _G,
     "initial_angle": Parameter(DIMENSIONLESS, Domain(-math.pi, math.pi, True, True, True),
                                meaning="release angle from the bottom [rad]: at 0 it does "
                                "not swing, at +-pi the period is infinite")},
    relations=(Relation(
        "pivot_inertia",
        lambda v: not _given(v, "mass", "pivot_distance", "pivot_inertia")
        or v["pivot_inertia"] >= v["mass"] * v["pivot_distance"] ** 2 * (1 - 1e-12),
        "must be >= mass pivot_distance^2 (parallel axes: the inertia about the centre of "
        "mass is not negative)"),),
    scene_checks=(gravity_is_the_scenes,),
))
TORQUE_FREE = declare_kind(ExpectationKind(
    "torque_free",
    "kinetic energy and angular momentum conserved; rotation near the intermediate axis "
    "flips periodically",
))
SLIDER_CRANK = declare_kind(ExpectationKind(
    "slider_crank",
    "slider position x = l1 cos(theta) + sqrt(l2^2 - (l1 sin(theta) - offset)^2)",
    {"crank_length": Parameter(LENGTH, POSITIVE), "rod_length": Parameter(LENGTH, POSITIVE),
     "crank_speed": Parameter(ANGULAR_VELOCITY, ANY), "offset": Parameter(LENGTH, ANY)},
    relations=(Relation(
        "rod_length",
        lambda v: v["rod_length"] >= v["crank_length"] + abs(v["offset"]),
        "must be >= crank_length + |offset| for the crank to turn a full revolution"),),
))
APPROACHES_IDEAL = declare_kind(ExpectationKind(
    "approaches_ideal",
    "the motion approaches the ideal-joint motion as the clearance goes to zero",
    {"radial_clearance": Parameter(LENGTH, POSITIVE)},
))
ROCKING_RATIO = declare_kind(ExpectationKind(
    "rocking_ratio",
    "angular-velocity ratio 1 - 1.5 sin^2(alpha) at each impact, alpha = atan(b/h)",
    {"half_width": Parameter(LENGTH, POSITIVE), "half_height": Parameter(LENGTH, POSITIVE),
     "gravity": _G},
    relations=(Relation(
        "half_width",
        lambda v: 1.0 - 1.5 * math.sin(math.atan2(v["half_width"], v["half_height"])) ** 2 > 0,
        "the block is too squat to rock: 1 - 1.5 sin^2(atan(b/h)) must be > 0 "
        "(b/h < 1.41)"),),
    scene_checks=(gravity_is_the_scenes,),
))
HOOP_OVER_EDGE = declare_kind(ExpectationKind(
    "hoop_over_edge",
    "a hoop sliding without friction and spin at v0 toward a straight edge (its lowest point "
    "edge_distance before it) pivots about the edge, its centre on the circle of radius r, "
    "leaves it where cos(theta) = (2 + v0^2/(g r))/3, then flies: the centre's path",
    {"initial_speed": _V0, "radius": Parameter(LENGTH, POSITIVE, meaning="hoop radius"),
     "gravity": _G,
     "edge_distance": Parameter(LENGTH, NON_NEGATIVE,
                                meaning="lowest point to the edge at t = 0, along the motion")},
    scene_checks=(gravity_is_the_scenes,),
))
STICKS = declare_kind(ExpectationKind(
    "sticks",
    "the body must not move between start_time and end_time",
    {"start_time": Parameter(TIME, NON_NEGATIVE), "end_time": Parameter(TIME, POSITIVE)},
    relations=(Relation("end_time", lambda v: v["end_time"] > v["start_time"],
                        "must be after start_time (an empty window judges nothing)"),),
    scene_checks=(window_starts_within_the_horizon,),
    body_stays=True,
))
ENERGY_NON_INCREASING = declare_kind(ExpectationKind(
    "energy_non_increasing", "total mechanical energy never grows", needs_body=False,
    energy_may_not_grow=True,
))
ENERGY_CONSERVED = declare_kind(ExpectationKind(
    "energy_conserved", "total mechanical energy is conserved", needs_body=False,
    energy_may_not_grow=True, energy_conserved=True,
))
NO_PENETRATION = declare_kind(ExpectationKind(
    "no_penetration", "no contact gap below zero", needs_body=False,
))
OUTPUT_VALUE = declare_kind(ExpectationKind(
    "output_value",
    "the named output equals value at time (the end if no time) within absolute_tolerance"
    " + relative_tolerance x |value| (either or both; value and absolute_tolerance in the "
    "output's unit)",
    {"value": Parameter(OUTPUT_DIMENSION),
     "absolute_tolerance": Parameter(OUTPUT_DIMENSION, NON_NEGATIVE, optional=True),
     "relative_tolerance": Parameter(DIMENSIONLESS, NON_NEGATIVE, optional=True),
     "time": Parameter(TIME, NON_NEGATIVE, optional=True)},
    needs_body=False, needs_output=True,
    one_of=(("absolute_tolerance", "relative_tolerance"),),
    relations=(Relation(
        "absolute_tolerance",
        lambda v: v.get("absolute_tolerance", 0.0) + v.get("relative_tolerance", 0.0)
        * abs(v["value"]) > 0,
        "the tolerance absolute + relative x |value| must be > 0 (a zero tolerance judges "
        "round-off)"),),
    scene_checks=(time_within_the_horizon,),
))


def parameters_table() -> str:
    """Every kind a scene may write with its parameters (dimension, domain) as a Markdown
    table: the list of docs/scene-format.md."""
    lines = ["| kind | body / output | parameters (dimension; allowed values) |",
             "|---|---|---|"]
    for kind in EXPECTATION_KINDS.values():
        parts = []
        for key, parameter in kind.parameters.items():
            dimension = ("output's unit" if parameter.dimension == OUTPUT_DIMENSION
                         else _dimension_words(parameter.dimension))
            optional = ", optional" if parameter.optional else ""
            parts.append(f"`{key}` ({dimension}; {parameter.domain.text()}{optional})")
        parts += [f"{relation.field}: {relation.reason}" for relation in kind.relations]
        subject = "output" if kind.needs_output else ("body" if kind.needs_body else "-")
        cell = "; ".join(parts).replace("|", "\\|") or "-"
        lines.append(f"| `{kind.name}` | {subject} | {cell} |")
    return "\n".join(lines)


def _dimension_words(dimension: tuple) -> str:
    """``(1, 0, -2)`` -> ``L/T^2``; ``-`` when dimensionless."""
    up = [f"{s}{'' if p == 1 else '^' + str(p)}" for s, p in zip("LMT", dimension, strict=True)
          if p > 0]
    down = [f"{s}{'' if p == -1 else '^' + str(-p)}" for s, p in
            zip("LMT", dimension, strict=True) if p < 0]
    if not up and not down:
        return "-"
    return (" ".join(up) or "1") + ("/" + " ".join(down) if down else "")
