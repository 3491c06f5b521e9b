"""Applied loads: spring-dampers (linear and torsional, with preload), point forces and moments,
and law loads (a scalar law of angles or of a distance, applied through listed forces and
moments).

Gravity is a scene-level vector (see :class:`.scene.Scene`). Forces and moments may be switched
on at ``start_time`` and off at ``end_time`` (``None``: never switched off).

Law loads express springs that a model applies as equivalent forces rather than as a spring
between two points, as the C-60 source does: a torsion spring whose moment is applied as a force
on a lever along a body axis, a distance spring pushing along a body axis instead of along its
own line, a relative-angle torsion applied as forces and a moment. A law computes one scalar
``s`` from the configuration; each :class:`LoadApplication` turns ``s`` into a force at a body
point or a moment on a body. Such loads are in general NOT conservative (the applied forces are
not the gradient of a potential of ``s``): energy metrics leave them out, and they do work that
an energy balance must not expect back.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import Any, ClassVar

from clearbench.scenarios.element import Element
from clearbench.scenarios.joints import check_unit_axis
from clearbench.scenarios.validation import (
    FORCE,
    LENGTH,
    LINEAR_DAMPING,
    LINEAR_STIFFNESS,
    MOMENT,
    TIME,
    TORSIONAL_DAMPING,
    TORSIONAL_STIFFNESS,
    SceneError,
    check_finite,
    check_finite_vector,
    check_name,
    check_non_negative,
    check_positive,
    dim,
    dimensionless,
)

FRAMES = ("world", "body")


@dataclass(frozen=True)
class Load(Element):
    """Base of every load."""

    collection = "loads"
    kind: ClassVar[str] = ""

    @property
    def bodies(self) -> tuple[str, ...]:
        """Names of the bodies the load acts on."""
        raise NotImplementedError


@dataclass(frozen=True)
class LinearSpringDamper(Load):
    """Spring-damper between ``point_a`` of ``body_a`` and ``point_b`` of ``body_b``.

    Tension T = preload + stiffness (L - rest_length) + damping dL/dt along the line of the two
    points (T > 0 pulls them together), L the current distance [L].
    Points are in each body's frame [L].
    """

    kind: ClassVar[str] = "linear_spring"
    body_a: str = ""
    point_a: tuple = field(default=(0.0, 0.0, 0.0), metadata=dim(LENGTH))
    body_b: str = ""
    point_b: tuple = field(default=(0.0, 0.0, 0.0), metadata=dim(LENGTH))
    stiffness: float = field(default=0.0, metadata=dim(LINEAR_STIFFNESS))
    damping: float = field(default=0.0, metadata=dim(LINEAR_DAMPING))
    rest_length: float = field(default=0.0, metadata=dim(LENGTH))
    preload: float = field(default=0.0, metadata=dim(FORCE))

    def _validate(self) -> None:
        _check_two_bodies(self.body_a, self.body_b)
        self._set("point_a", check_finite_vector("point_a", self.point_a, 3))
        self._set("point_b", check_finite_vector("point_b", self.point_b, 3))
        check_non_negative("stiffness", self.stiffness)
        check_non_negative("damping", self.damping)
        check_non_negative("rest_length", self.rest_length)
        check_finite("preload", self.preload)

    @property
    def bodies(self) -> tuple[str, ...]:
        return (self.body_a, self.body_b)


@dataclass(frozen=True)
class TorsionalSpringDamper(Load):
    """Torsional spring-damper between two bodies about ``axis`` (world, initial configuration).

    Moment on ``body_b`` about the axis: M = -(preload + stiffness (phi - rest_angle) +
    damping dphi/dt), where phi is the rotation of B relative to A about the axis since t = 0
    [rad]; the opposite moment acts on A.
    """

    kind: ClassVar[str] = "torsional_spring"
    body_a: str = ""
    body_b: str = ""
    axis: tuple = field(default=(0.0, 0.0, 1.0), metadata=dimensionless())
    stiffness: float = field(default=0.0, metadata=dim(TORSIONAL_STIFFNESS))
    damping: float = field(default=0.0, metadata=dim(TORSIONAL_DAMPING))
    rest_angle: float = field(default=0.0, metadata=dimensionless())
    preload: float = field(default=0.0, metadata=dim(MOMENT))

    def _validate(self) -> None:
        _check_two_bodies(self.body_a, self.body_b)
        self._set("axis", check_unit_axis("axis", self.axis))
        check_non_negative("stiffness", self.stiffness)
        check_non_negative("damping", self.damping)
        check_finite("rest_angle", self.rest_angle)
        check_finite("preload", self.preload)

    @property
    def bodies(self) -> tuple[str, ...]:
        return (self.body_a, self.body_b)


@dataclass(frozen=True)
class PointForce(Load):
    """Constant force ``force`` [F] at ``point`` (body frame [L]) of ``body``, in ``frame``
    axes ('world' or 'body'), active for start_time <= t < end_time."""

    kind: ClassVar[str] = "point_force"
    body: str = ""
    point: tuple = field(default=(0.0, 0.0, 0.0), metadata=dim(LENGTH))
    force: tuple = field(default=(0.0, 0.0, 0.0), metadata=dim(FORCE))
    frame: str = "world"
    start_time: float = field(default=0.0, metadata=dim(TIME))
    end_time: float | None = field(default=None, metadata=dim(TIME))

    def _validate(self) -> None:
        check_name("body", self.body)
        self._set("point", check_finite_vector("point", self.point, 3))
        self._set("force", check_finite_vector("force", self.force, 3))
        _check_frame(self.frame)
        _check_window(self.start_time, self.end_time)

    @property
    def bodies(self) -> tuple[str, ...]:
        return (self.body,)


@dataclass(frozen=True)
class Moment(Load):
    """Constant moment ``moment`` [F L] on ``body`` in ``frame`` axes, active for
    start_time <= t < end_time (a time-switched moment)."""

    kind: ClassVar[str] = "moment"
    body: str = ""
    moment: tuple = field(default=(0.0, 0.0, 0.0), metadata=dim(MOMENT))
    frame: str = "world"
    start_time: float = field(default=0.0, metadata=dim(TIME))
    end_time: float | None = field(default=None, metadata=dim(TIME))

    def _validate(self) -> None:
        check_name("body", self.body)
        self._set("moment", check_finite_vector("moment", self.moment, 3))
        _check_frame(self.frame)
        _check_window(self.start_time, self.end_time)

    @property
    def bodies(self) -> tuple[str, ...]:
        return (self.body,)


ACTIONS = ("force", "moment")


@dataclass(frozen=True)
class LoadApplication:
    """How the scalar ``s`` of a law load acts on one body.

    Parameters
    ----------
    body : str
        The body acted on.
    action : str
        ``force``: a force ``value * d`` at ``point``; ``moment``: a moment ``value * d``.
    direction : (3,) tuple
        Any non-zero vector (normalised when applied) ``d``, in ``frame`` axes.
    frame : str
        ``body`` (the direction turns with the body) or ``world``.
    point : (3,) tuple
        Point of application of a force, body frame from the body origin [L]; must stay at the
        origin for a moment.
    coefficient : float
        Dimensionless factor.
    lever : float or None
        Arm [L] converting between the law's scalar and the action, where their dimensions
        differ: an angle law (s is a moment) applies a force ``coefficient * s / lever``; a
        distance law (s is a force) applies a moment ``coefficient * s * lever``. ``None`` where
        the dimensions agree (``value = coefficient * s``).
    """

    body: str = ""
    action: str = "force"
    direction: tuple = field(default=(1.0, 0.0, 0.0), metadata=dimensionless())
    frame: str = "body"
    point: tuple = field(default=(0.0, 0.0, 0.0), metadata=dim(LENGTH))
    coefficient: float = field(default=1.0, metadata=dimensionless())
    lever: float | None = field(default=None, metadata=dim(LENGTH))

    def __post_init__(self) -> None:
        check_name("body", self.body)
        if self.action not in ACTIONS:
            raise SceneError("action", self.action, f"must be one of {ACTIONS}")
        direction = check_finite_vector("direction", self.direction, 3)
        if not any(direction):
            raise SceneError("direction", self.direction, "must be a non-zero vector")
        object.__setattr__(self, "direction", direction)
        _check_frame(self.frame)
        object.__setattr__(self, "point", check_finite_vector("point", self.point, 3))
        if self.action == "moment" and any(self.point):
            raise SceneError("point", self.point, "a moment has no point of application "
                             "(leave it at the origin)")
        check_finite("coefficient", self.coefficient)
        if self.lever is not None:
            check_positive("lever", self.lever)

    def unit_direction(self) -> tuple[float, float, float]:
        """``direction`` normalised (in ``frame`` axes)."""
        norm = math.sqrt(sum(c * c for c in self.direction))
        return tuple(c / norm for c in self.direction)  # type: ignore[return-value]

    def gain(self, scalar_is_moment: bool) -> float:
        """Factor from the law's scalar to this application's force [F] or moment [F L]."""
        if self.lever is None:
            return self.coefficient
        if scalar_is_moment:
            return self.coefficient / self.lever
        return self.coefficient * self.lever


def _applications(value: Any, scalar_is_moment: bool) -> tuple[LoadApplication, ...]:
    """Check (and build from plain dicts) the applications of a law load."""
    if isinstance(value, str | dict) or not hasattr(value, "__iter__"):
        raise SceneError("applications", value, "must be a list of applications")
    items = list(value)
    if not items:
        raise SceneError("applications", value, "a law load needs at least one application")
    out = []
    names = [f.name for f in dataclasses.fields(LoadApplication)]
    for index, item in enumerate(items):
        path = f"applications[{index}]"
        try:
            if isinstance(item, dict):
                unknown = sorted(set(item) - set(names))
                if unknown:
                    raise SceneError(unknown[0], item[unknown[0]],
                                     f"unknown field of an application (fields: {names})")
                item = LoadApplication(**item)
            if not isinstance(item, LoadApplication):
                raise SceneError("", item, "must be a LoadApplication or a table")
            converts = (item.action == "force") == scalar_is_moment
            if converts and item.lever is None:
                law = "an angle law (a moment)" if scalar_is_moment else "a distance law (a force)"
                raise SceneError("lever", None, f"a {item.action} driven by {law} needs a lever")
            if not converts and item.lever is not None:
                raise SceneError("lever", item.lever, f"a {item.action} of this law takes no "
                                 "lever (the dimensions already agree)")
        except SceneError as error:
            raise error.within(path) from None
        out.append(item)
    return tuple(out)


@dataclass(frozen=True)
class AngleLawLoad(Load):
    """A law of body angles about a world axis, applied through ``applications``.

    ``s = stiffness * (offset + sum_i angle_coefficients[i] * theta(bodies[i]))`` [F L], where
    theta(b) is the ABSOLUTE rotation of body b about the world ``axis``: the twist angle
    2 atan2(q . axis, q_w) of its orientation quaternion q (q_w >= 0), i.e. its rotation from
    the body frame's reference orientation (1, 0, 0, 0), in (-pi, pi] at t = 0 and continuous
    after (engines add the whole turns a body makes: a body turning through pi does not make
    the law jump by 2 pi). The offset carries the law's reference (a rest angle, a preload).
    Each application turns ``s`` into a force (``coefficient * s /
    lever``) or a moment (``coefficient * s``); see :class:`LoadApplication`.
    """

    kind: ClassVar[str] = "angle_law"
    axis: tuple = field(default=(0.0, 0.0, 1.0), metadata=dimensionless())
    stiffness: float = field(default=0.0, metadata=dim(TORSIONAL_STIFFNESS))
    offset: float = field(default=0.0, metadata=dimensionless())
    angle_bodies: tuple = ()
    angle_coefficients: tuple = field(default=(), metadata=dimensionless())
    applications: tuple = ()

    def _validate(self) -> None:
        self._set("axis", check_unit_axis("axis", self.axis))
        check_non_negative("stiffness", self.stiffness)
        check_finite("offset", self.offset)
        bodies = tuple(self.angle_bodies) if not isinstance(self.angle_bodies, str) else None
        if not bodies:
            raise SceneError("angle_bodies", self.angle_bodies, "must list at least one body")
        for index, body in enumerate(bodies):
            check_name(f"angle_bodies[{index}]", body)
        if len(set(bodies)) != len(bodies):
            raise SceneError("angle_bodies", self.angle_bodies, "a body is listed twice")
        self._set("angle_bodies", bodies)
        self._set("angle_coefficients", check_finite_vector(
            "angle_coefficients", self.angle_coefficients, len(bodies)))
        self._set("applications", _applications(self.applications, scalar_is_moment=True))

    @property
    def bodies(self) -> tuple[str, ...]:
        names = list(self.angle_bodies)
        names += [a.body for a in self.applications if a.body not in names]
        return tuple(names)


@dataclass(frozen=True)
class DistanceLawLoad(Load):
    """A law of the distance L between ``point_a`` of ``body_a`` and ``point_b`` of ``body_b``
    (body frames [L]), applied through ``applications``.

    ``s = stiffness * (rest_length - L)`` [F]: positive when the points are closer than the rest
    length (a compressed spring pushes). Each application turns ``s`` into a force
    (``coefficient * s``, in any direction: not necessarily along the line of the points) or a
    moment (``coefficient * s * lever``); see :class:`LoadApplication`.
    """

    kind: ClassVar[str] = "distance_law"
    body_a: str = ""
    point_a: tuple = field(default=(0.0, 0.0, 0.0), metadata=dim(LENGTH))
    body_b: str = ""
    point_b: tuple = field(default=(0.0, 0.0, 0.0), metadata=dim(LENGTH))
    stiffness: float = field(default=0.0, metadata=dim(LINEAR_STIFFNESS))
    rest_length: float = field(default=0.0, metadata=dim(LENGTH))
    applications: tuple = ()

    def _validate(self) -> None:
        _check_two_bodies(self.body_a, self.body_b)
        self._set("point_a", check_finite_vector("point_a", self.point_a, 3))
        self._set("point_b", check_finite_vector("point_b", self.point_b, 3))
        check_non_negative("stiffness", self.stiffness)
        check_non_negative("rest_length", self.rest_length)
        self._set("applications", _applications(self.applications, scalar_is_moment=False))

    @property
    def bodies(self) -> tuple[str, ...]:
        names = [self.body_a, self.body_b]
        names += [a.body for a in self.applications if a.body not in names]
        return tuple(names)


LOAD_TYPES: dict[str, type[Load]] = {
    cls.kind: cls for cls in (LinearSpringDamper, TorsionalSpringDamper, PointForce, Moment,
                              AngleLawLoad, DistanceLawLoad)
}


def _check_two_bodies(body_a: str, body_b: str) -> None:
    check_name("body_a", body_a)
    check_name("body_b", body_b)
    if body_a == body_b:
        raise SceneError("body_b", body_b, "must differ from body_a")


def _check_frame(frame: str) -> None:
    if frame not in FRAMES:
        raise SceneError("frame", frame, f"must be one of {FRAMES}")


def _check_window(start_time: float, end_time: float | None) -> None:
    check_finite("start_time", start_time)
    if end_time is not None:
        check_finite("end_time", end_time)
        if end_time <= start_time:
            raise SceneError("end_time", end_time, f"must be > start_time ({start_time})")
