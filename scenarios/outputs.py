"""Named outputs: measurements that functional conditions and error metrics are computed on."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar

from clearbench.scenarios.element import Element
from clearbench.scenarios.joints import check_unit_axis
from clearbench.scenarios.validation import (
    DIMENSIONLESS,
    FORCE,
    LENGTH,
    SceneError,
    check_finite_vector,
    check_name,
    dim,
    dimensionless,
)

POINT_COMPONENTS = ("x", "y", "z", "norm")


@dataclass(frozen=True)
class Output(Element):
    """Base of the named outputs; ``dimension`` is the physical dimension of the value."""

    collection = "outputs"
    kind: ClassVar[str] = ""
    dimension: ClassVar[tuple[int, int, int]] = DIMENSIONLESS


def _check_component(component: str) -> None:
    if component not in POINT_COMPONENTS:
        raise SceneError("component", component, f"must be one of {POINT_COMPONENTS}")


@dataclass(frozen=True)
class PointPosition(Output):
    """World coordinate (``x``, ``y``, ``z``) or distance from the origin (``norm``) of
    ``point`` (body frame [L]) of ``body`` [L]."""

    kind: ClassVar[str] = "point_position"
    dimension: ClassVar[tuple[int, int, int]] = LENGTH
    body: str = ""
    point: tuple = field(default=(0.0, 0.0, 0.0), metadata=dim(LENGTH))
    component: str = "z"

    def _validate(self) -> None:
        check_name("body", self.body)
        self._set("point", check_finite_vector("point", self.point, 3))
        _check_component(self.component)


@dataclass(frozen=True)
class PointDistance(Output):
    """Component (world axes) or norm of p_b - p_a between ``point_b`` of ``body_b`` and
    ``point_a`` of ``body_a`` [L] (the C-60 functional-condition measurements)."""

    kind: ClassVar[str] = "point_distance"
    dimension: ClassVar[tuple[int, int, int]] = LENGTH
    body_a: str = ""
    point_a: tuple = field(default=(0.0, 0.0, 0.0), metadata=dim(LENGTH))
    body_b: str = ""
    point_b: tuple = field(default=(0.0, 0.0, 0.0), metadata=dim(LENGTH))
    component: str = "norm"

    def _validate(self) -> None:
        check_name("body_a", self.body_a)
        check_name("body_b", self.body_b)
        self._set("point_a", check_finite_vector("point_a", self.point_a, 3))
        self._set("point_b", check_finite_vector("point_b", self.point_b, 3))
        _check_component(self.component)


@dataclass(frozen=True)
class BodyAngle(Output):
    """Rotation of ``body`` since t = 0 about the world ``axis`` [rad] (signed, unwrapped)."""

    kind: ClassVar[str] = "body_angle"
    body: str = ""
    axis: tuple = field(default=(0.0, 0.0, 1.0), metadata=dimensionless())

    def _validate(self) -> None:
        check_name("body", self.body)
        self._set("axis", check_unit_axis("axis", self.axis))


@dataclass(frozen=True)
class ContactForce(Output):
    """Force [F] transmitted by the contact pair ``contact`` (summed over its contact points):
    ``normal`` or ``tangential`` magnitude."""

    kind: ClassVar[str] = "contact_force"
    dimension: ClassVar[tuple[int, int, int]] = FORCE
    contact: str = ""
    component: str = "normal"

    def _validate(self) -> None:
        check_name("contact", self.contact)
        if self.component not in ("normal", "tangential"):
            raise SceneError("component", self.component, "must be 'normal' or 'tangential'")


OUTPUT_TYPES: dict[str, type[Output]] = {
    cls.kind: cls for cls in (PointPosition, PointDistance, BodyAngle, ContactForce)
}
