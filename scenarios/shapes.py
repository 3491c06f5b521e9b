"""Shapes of the scene description, each placed in its body frame.

Every shape has a ``name`` (unique within its body), a ``position`` (3,) of its own frame origin in
the body frame and an ``orientation`` (4,) unit quaternion (w, x, y, z) of its own frame relative to
the body frame. The parameters below are given in the shape's own frame, in the scene's length
unit:

========  =====================================================================================
Sphere    centre at the origin, ``radius``.
Box       centred at the origin, ``half_extents`` (3,) along the shape's x, y, z axes.
Capsule   segment from (0, 0, -half_length) to (0, 0, +half_length), swept by ``radius``.
Cylinder  axis along z, centred, ``radius``, ``half_length``; contact on its lateral surface.
Plane     the half-space z <= 0 of the shape frame: the material is below, the normal is +z.
Circle    the circle of ``radius`` in the shape's xy-plane, centred at the origin (a bearing
          ring edge, as the C-60 CAD draws rings).
Arc       the part of that circle between angles ``start_angle`` and ``end_angle`` (radians,
          measured from +x about +z, ``start_angle < end_angle <= start_angle + 2 pi``).
Rectangle a bounded plane face (a CAD plane face), material below z = 0: its solid is the slab
          |x| <= ``half_extents[0]``, |y| <= ``half_extents[1]``, -``depth`` <= z <= 0 (no
          depth: unbounded below); a partner past the face's bound meets its edge.
Disc      the same bounded by the circle x^2 + y^2 <= ``radius``^2 (a round plane face).
Bore      a concave cylindrical surface (a hole: material OUTSIDE the radius), axis along z,
          ``radius``, bounded to |z| <= ``half_length`` and to the angles ``start_angle`` ..
          ``end_angle`` about +z from +x (a full bore by default; a concave CAD patch else).
========  =====================================================================================

Validation of the numbers (finite, positive) happens at construction; every error names the field
and the offending value.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import ClassVar

from clearbench.scenarios.validation import (
    LENGTH,
    SceneError,
    check_finite_vector,
    check_name,
    check_positive,
    check_unit_quaternion,
    dim,
    dimensionless,
)

IDENTITY_QUATERNION = (1.0, 0.0, 0.0, 0.0)
ORIGIN = (0.0, 0.0, 0.0)


@dataclass(frozen=True)
class Shape:
    """Base of every shape: name and placement in the body frame."""

    kind: ClassVar[str] = ""
    name: str
    position: tuple[float, float, float] = field(default=ORIGIN, metadata=dim(LENGTH))
    orientation: tuple[float, float, float, float] = field(
        default=IDENTITY_QUATERNION, metadata=dimensionless()
    )

    def __post_init__(self) -> None:
        check_name("name", self.name)
        object.__setattr__(self, "position", check_finite_vector("position", self.position, 3))
        check_unit_quaternion("orientation", self.orientation)
        # Stored as given (norm within 1e-6 of 1); engines normalise where they use it.
        object.__setattr__(
            self, "orientation", check_finite_vector("orientation", self.orientation, 4)
        )
        self._check_parameters()

    def _check_parameters(self) -> None:
        """Validate the kind-specific parameters (overridden by each shape)."""


@dataclass(frozen=True)
class Sphere(Shape):
    kind: ClassVar[str] = "sphere"
    radius: float = field(default=1.0, metadata=dim(LENGTH))

    def _check_parameters(self) -> None:
        object.__setattr__(self, "radius", check_positive("radius", self.radius))


@dataclass(frozen=True)
class Box(Shape):
    kind: ClassVar[str] = "box"
    half_extents: tuple[float, float, float] = field(default=(0.5, 0.5, 0.5), metadata=dim(LENGTH))

    def _check_parameters(self) -> None:
        values = check_finite_vector("half_extents", self.half_extents, 3)
        for axis, value in zip("xyz", values, strict=True):
            check_positive(f"half_extents.{axis}", value)
        object.__setattr__(self, "half_extents", values)


@dataclass(frozen=True)
class Capsule(Shape):
    kind: ClassVar[str] = "capsule"
    radius: float = field(default=0.1, metadata=dim(LENGTH))
    half_length: float = field(default=0.5, metadata=dim(LENGTH))

    def _check_parameters(self) -> None:
        object.__setattr__(self, "radius", check_positive("radius", self.radius))
        object.__setattr__(self, "half_length", check_positive("half_length", self.half_length))


@dataclass(frozen=True)
class Cylinder(Shape):
    kind: ClassVar[str] = "cylinder"
    radius: float = field(default=0.1, metadata=dim(LENGTH))
    half_length: float = field(default=0.5, metadata=dim(LENGTH))

    def _check_parameters(self) -> None:
        object.__setattr__(self, "radius", check_positive("radius", self.radius))
        object.__setattr__(self, "half_length", check_positive("half_length", self.half_length))


@dataclass(frozen=True)
class Plane(Shape):
    kind: ClassVar[str] = "plane"


@dataclass(frozen=True)
class Circle(Shape):
    kind: ClassVar[str] = "circle"
    radius: float = field(default=0.1, metadata=dim(LENGTH))

    def _check_parameters(self) -> None:
        object.__setattr__(self, "radius", check_positive("radius", self.radius))


@dataclass(frozen=True)
class Arc(Shape):
    kind: ClassVar[str] = "arc"
    radius: float = field(default=0.1, metadata=dim(LENGTH))
    start_angle: float = field(default=0.0, metadata=dimensionless())
    end_angle: float = field(default=math.pi, metadata=dimensionless())

    def _check_parameters(self) -> None:
        object.__setattr__(self, "radius", check_positive("radius", self.radius))
        _check_angle_range(self)


def _check_angle_range(shape: Shape) -> None:
    start = check_finite_vector("start_angle", (shape.start_angle,), 1)[0]
    end = check_finite_vector("end_angle", (shape.end_angle,), 1)[0]
    if not start < end <= start + 2.0 * math.pi:
        raise SceneError(
            "end_angle",
            end,
            "must satisfy start_angle < end_angle <= start_angle + 2 pi "
            f"(start_angle = {start})",
        )
    object.__setattr__(shape, "start_angle", start)
    object.__setattr__(shape, "end_angle", end)


@dataclass(frozen=True)
class Rectangle(Shape):
    """A bounded plane face: |x| <= half_x, |y| <= half_y in its frame, material below z = 0.

    ``depth`` [L] is how far the solid reaches behind the face: a partner that went round
    behind the solid (a part that turned all the way round) meets its back, not its face.
    None: the solid reaches down without end. Past the face's bound a partner meets its edge
    (docs/contact-geometry.md).
    """

    kind: ClassVar[str] = "rectangle"
    half_extents: tuple[float, float] = field(default=(0.5, 0.5), metadata=dim(LENGTH))
    depth: float | None = field(default=None, metadata=dim(LENGTH))

    def _check_parameters(self) -> None:
        values = check_finite_vector("half_extents", self.half_extents, 2)
        for axis, value in zip("xy", values, strict=True):
            check_positive(f"half_extents.{axis}", value)
        object.__setattr__(self, "half_extents", values)
        if self.depth is not None:
            object.__setattr__(self, "depth", check_positive("depth", self.depth))


@dataclass(frozen=True)
class Disc(Shape):
    """A round plane face of ``radius`` [L] about its frame's z axis, material below z = 0;
    ``depth`` [L] as for :class:`Rectangle`."""

    kind: ClassVar[str] = "disc"
    radius: float = field(default=0.5, metadata=dim(LENGTH))
    depth: float | None = field(default=None, metadata=dim(LENGTH))

    def _check_parameters(self) -> None:
        object.__setattr__(self, "radius", check_positive("radius", self.radius))
        if self.depth is not None:
            object.__setattr__(self, "depth", check_positive("depth", self.depth))


@dataclass(frozen=True)
class Bore(Shape):
    """A concave cylinder about its frame's z axis, |z| <= half_length, between
    ``start_angle`` and ``end_angle`` [rad] from +x: a hole that rings, arcs and journals sit
    inside, the material outside the radius.

    ``depth`` [L] is how far the solid reaches behind the surface, as for :class:`Rectangle`:
    a partner more than that outside the radius has gone round behind the part (a partial
    bore, a concave patch, can be left that way), it is not in it, and no contact is reported.
    None: no bound.
    """

    kind: ClassVar[str] = "bore"
    radius: float = field(default=0.1, metadata=dim(LENGTH))
    half_length: float = field(default=0.5, metadata=dim(LENGTH))
    start_angle: float = field(default=0.0, metadata=dimensionless())
    end_angle: float = field(default=2.0 * math.pi, metadata=dimensionless())
    depth: float | None = field(default=None, metadata=dim(LENGTH))

    def _check_parameters(self) -> None:
        object.__setattr__(self, "radius", check_positive("radius", self.radius))
        object.__setattr__(self, "half_length", check_positive("half_length", self.half_length))
        _check_angle_range(self)
        if self.depth is not None:
            object.__setattr__(self, "depth", check_positive("depth", self.depth))


#: Every shape class by its ``kind`` string (the ``kind`` key of the dict/TOML form).
SHAPE_TYPES: dict[str, type[Shape]] = {
    cls.kind: cls
    for cls in (Sphere, Box, Capsule, Cylinder, Plane, Circle, Arc, Rectangle, Disc, Bore)
}
