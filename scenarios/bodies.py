"""Rigid bodies of the scene description."""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import Enum

from clearbench.scenarios.element import Element
from clearbench.scenarios.shapes import IDENTITY_QUATERNION, ORIGIN, Shape
from clearbench.scenarios.validation import (
    ANGULAR_VELOCITY,
    INERTIA,
    LENGTH,
    MASS,
    VELOCITY,
    SceneError,
    check_finite_vector,
    check_inertia,
    check_positive,
    check_unit_quaternion,
    dim,
    dimensionless,
)

UNIT_INERTIA = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))


class Motion(Enum):
    """How a body moves: under the dynamics, not at all, or with prescribed components."""

    FREE = "free"
    FIXED = "fixed"
    DRIVEN = "driven"


@dataclass(frozen=True)
class Body(Element):
    """A rigid body.

    Parameters
    ----------
    name : str
        Unique name in the scene.
    mass : float
        Mass [M], > 0.
    inertia : (3, 3) tuple
        Inertia tensor about the centre of mass in body axes [M L^2]: symmetric, positive
        definite, principal moments satisfying the triangle inequality.
    center_of_mass : (3,) tuple
        Centre of mass in the body frame [L].
    position : (3,) tuple
        Initial position of the body-frame origin in world axes [L].
    orientation : (4,) tuple
        Initial orientation, unit quaternion (w, x, y, z) rotating body axes to world axes.
    velocity : (3,) tuple
        Initial velocity of the centre of mass, world axes [L/T].
    angular_velocity : (3,) tuple
        Initial angular velocity in body axes [1/T].
    motion : Motion
        ``free``, ``fixed`` (never moves; mass and inertia unused) or ``driven`` (some velocity
        components prescribed by drivers, the others free).
    shapes : tuple of Shape
        Geometry in the body frame, names unique within the body.
    """

    collection = "bodies"
    mass: float = field(default=1.0, metadata=dim(MASS))
    inertia: tuple = field(default=UNIT_INERTIA, metadata=dim(INERTIA))
    center_of_mass: tuple = field(default=ORIGIN, metadata=dim(LENGTH))
    position: tuple = field(default=ORIGIN, metadata=dim(LENGTH))
    orientation: tuple = field(default=IDENTITY_QUATERNION, metadata=dimensionless())
    velocity: tuple = field(default=ORIGIN, metadata=dim(VELOCITY))
    angular_velocity: tuple = field(default=ORIGIN, metadata=dim(ANGULAR_VELOCITY))
    motion: Motion = Motion.FREE
    shapes: tuple[Shape, ...] = ()

    def _validate(self) -> None:
        check_positive("mass", self.mass)
        self._set("inertia", _inertia_as_given(self.inertia))
        for name in ("center_of_mass", "position", "velocity", "angular_velocity"):
            self._set(name, check_finite_vector(name, getattr(self, name), 3))
        check_unit_quaternion("orientation", self.orientation)
        self._set("orientation", check_finite_vector("orientation", self.orientation, 4))
        if not isinstance(self.motion, Motion):
            try:
                self._set("motion", Motion(self.motion))
            except ValueError:
                raise SceneError(
                    "motion", self.motion, f"must be one of {[m.value for m in Motion]}"
                ) from None
        shapes = tuple(self.shapes)
        seen: set[str] = set()
        for index, shape in enumerate(shapes):
            if not isinstance(shape, Shape):
                raise SceneError(f"shapes[{index}]", shape, "must be a Shape")
            if shape.name in seen:
                raise SceneError(f"shapes[{index}].name", shape.name, "duplicate shape name")
            seen.add(shape.name)
        self._set("shapes", shapes)

    def shape(self, name: str) -> Shape:
        """The shape called ``name``; KeyError naming the body otherwise."""
        for shape in self.shapes:
            if shape.name == name:
                return shape
        raise KeyError(f"body {self.name!r} has no shape {name!r}")


def _inertia_as_given(value) -> tuple:
    """Check the inertia tensor and return it as nested tuples, values unchanged."""
    check_inertia("inertia", value)
    return tuple(tuple(float(x) for x in row) for row in value)
