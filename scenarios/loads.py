"""Applied loads: spring-dampers (linear and torsional, with preload), point forces and moments.

Gravity is a scene-level vector (see :class:`.scene.Scene`). Forces and moments may be switched
on at ``start_time`` and off at ``end_time`` (``None``: never switched off).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar

from .element import Element
from .joints import check_unit_axis
from .validation import (
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


LOAD_TYPES: dict[str, type[Load]] = {
    cls.kind: cls for cls in (LinearSpringDamper, TorsionalSpringDamper, PointForce, Moment)
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
