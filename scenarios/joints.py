"""Ideal (bilateral) joints and clearance revolute joints.

Ideal joints are given in world coordinates at the initial configuration: an ``anchor`` point
[L] and, for revolute and prismatic joints, a unit ``axis``. Engines compute each body's local
joint frame from the initial poses, so the joint holds exactly at t = 0.

A clearance revolute joint is the C-60 study's 3D revolute joint with clearance, rebuilt as
contacts: a journal cylinder on ``journal_body``, a bearing ring (circle) at each end of the bore
on ``bearing_body`` (radial clearance), and a flange plane on the journal body facing each end
face of the bearing (axial clearance). :meth:`ClearanceRevoluteJoint.expand` returns those shapes
and contact pairs, so engines that work with contacts need nothing else.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from clearbench.scenarios.contacts import ContactPair
from clearbench.scenarios.element import Element
from clearbench.scenarios.shapes import Arc, Circle, Cylinder, Plane, Shape
from clearbench.scenarios.validation import (
    LENGTH,
    SceneError,
    check_finite_vector,
    check_in_range,
    check_name,
    check_non_negative,
    check_positive,
    dim,
    dimensionless,
)

#: Quarter arcs per thrust face of a clearance joint (see ClearanceRevoluteJoint.expand).
THRUST_ARCS = 4


def check_unit_axis(field: str, value: object, tolerance: float = 1e-6) -> tuple:
    """A 3-vector of norm 1 within ``tolerance`` (stored as given)."""
    axis = check_finite_vector(field, value, 3)
    norm = math.sqrt(sum(c * c for c in axis))
    if abs(norm - 1.0) > tolerance:
        raise SceneError(field, value, f"must be a unit vector (norm {norm:.9g})")
    return axis


@dataclass(frozen=True)
class Joint(Element):
    """Base of the ideal joints between ``body_a`` and ``body_b``."""

    collection = "joints"
    kind: ClassVar[str] = ""
    body_a: str = ""
    body_b: str = ""
    anchor: tuple = field(default=(0.0, 0.0, 0.0), metadata=dim(LENGTH))

    def _validate(self) -> None:
        check_name("body_a", self.body_a)
        check_name("body_b", self.body_b)
        if self.body_a == self.body_b:
            raise SceneError("body_b", self.body_b, "a joint needs two different bodies")
        self._set("anchor", check_finite_vector("anchor", self.anchor, 3))

    @property
    def constrained_dofs(self) -> int:
        """Number of relative degrees of freedom removed."""
        raise NotImplementedError


@dataclass(frozen=True)
class RevoluteJoint(Joint):
    """Rotation about ``axis`` (world, initial configuration) through ``anchor``."""

    kind: ClassVar[str] = "revolute"
    axis: tuple = field(default=(0.0, 0.0, 1.0), metadata=dimensionless())

    def _validate(self) -> None:
        super()._validate()
        self._set("axis", check_unit_axis("axis", self.axis))

    constrained_dofs = 5


@dataclass(frozen=True)
class SphericalJoint(Joint):
    """Rotation about ``anchor``."""

    kind: ClassVar[str] = "spherical"
    constrained_dofs = 3


@dataclass(frozen=True)
class PrismaticJoint(Joint):
    """Translation along ``axis``, no relative rotation."""

    kind: ClassVar[str] = "prismatic"
    axis: tuple = field(default=(1.0, 0.0, 0.0), metadata=dimensionless())

    def _validate(self) -> None:
        super()._validate()
        self._set("axis", check_unit_axis("axis", self.axis))

    constrained_dofs = 5


@dataclass(frozen=True)
class FixedJoint(Joint):
    """No relative motion."""

    kind: ClassVar[str] = "fixed"
    constrained_dofs = 6


JOINT_TYPES: dict[str, type[Joint]] = {
    cls.kind: cls for cls in (RevoluteJoint, SphericalJoint, PrismaticJoint, FixedJoint)
}


@dataclass(frozen=True)
class ClearanceRevoluteJoint(Element):
    """A 3D revolute joint with radial and axial clearance, built from contacts.

    Parameters
    ----------
    journal_body, bearing_body : str
        The body carrying the journal (pin) and the body carrying the bore.
    anchor : (3,) tuple
        Centre of the bore on its axis, world, initial configuration [L].
    axis : (3,) tuple
        Unit direction of the bore axis, world, initial configuration.
    journal_radius : float
        Radius of the journal cylinder [L].
    radial_clearance : float
        Bore radius minus journal radius [L], > 0.
    bearing_length : float
        Length of the bore; a bearing ring sits at each end [L].
    axial_clearance : float
        Total axial play of the bearing between the two flanges [L], > 0, split equally on
        both sides at t = 0.
    thrust_radius : float
        Radius of the ring of the bearing's end faces that meets the flanges [L]; at least the
        bore radius.
    friction, restitution : float
        Coulomb coefficient (>= 0) and Newton coefficient (in [0, 1]) of all its contacts.
    """

    collection = "clearance_joints"
    journal_body: str = ""
    bearing_body: str = ""
    anchor: tuple = field(default=(0.0, 0.0, 0.0), metadata=dim(LENGTH))
    axis: tuple = field(default=(0.0, 0.0, 1.0), metadata=dimensionless())
    journal_radius: float = field(default=0.01, metadata=dim(LENGTH))
    radial_clearance: float = field(default=1e-4, metadata=dim(LENGTH))
    bearing_length: float = field(default=0.01, metadata=dim(LENGTH))
    axial_clearance: float = field(default=1e-4, metadata=dim(LENGTH))
    thrust_radius: float = field(default=0.015, metadata=dim(LENGTH))
    friction: float = field(default=0.0, metadata=dimensionless())
    restitution: float = field(default=0.0, metadata=dimensionless())

    def _validate(self) -> None:
        check_name("journal_body", self.journal_body)
        check_name("bearing_body", self.bearing_body)
        if self.journal_body == self.bearing_body:
            raise SceneError("bearing_body", self.bearing_body, "must differ from journal_body")
        self._set("anchor", check_finite_vector("anchor", self.anchor, 3))
        self._set("axis", check_unit_axis("axis", self.axis))
        check_positive("journal_radius", self.journal_radius)
        check_positive("radial_clearance", self.radial_clearance)
        check_positive("bearing_length", self.bearing_length)
        check_positive("axial_clearance", self.axial_clearance)
        check_positive("thrust_radius", self.thrust_radius)
        if self.thrust_radius < self.bore_radius:
            raise SceneError(
                "thrust_radius",
                self.thrust_radius,
                f"must be at least the bore radius {self.bore_radius}",
            )
        check_non_negative("friction", self.friction)
        check_in_range("restitution", self.restitution, 0.0, 1.0)

    @property
    def bore_radius(self) -> float:
        """Journal radius plus radial clearance [L]."""
        return self.journal_radius + self.radial_clearance

    def expand(
        self, journal_pose: tuple, bearing_pose: tuple
    ) -> tuple[list[Shape], list[Shape], list[ContactPair]]:
        """Shapes and contact pairs that rebuild this joint.

        Parameters
        ----------
        journal_pose, bearing_pose : (position (3,), quaternion (4,))
            Initial world pose of each body frame.

        Returns
        -------
        journal_shapes, bearing_shapes : list of Shape
            Shapes to add to each body, expressed in that body's frame; their names start
            with the joint's name.
        contacts : list of ContactPair
            ``<name>.ring_bottom`` / ``<name>.ring_top`` (rings against the journal) and
            ``<name>.flange_bottom_k`` / ``<name>.flange_top_k``, k = 0..3 (the quarters of
            each end-face ring against its flange).

        Each end face meets its flange through four quarter arcs rather than one circle: when
        the faces are parallel a circle touches at one arbitrary point, whose off-axis force
        would tilt the bearing; four quarters let the axial force act on the axis, as the
        distributed contact of a real thrust face does.
        """
        axis = np.asarray(self.axis, dtype=float)
        anchor = np.asarray(self.anchor, dtype=float)
        half = 0.5 * self.bearing_length
        flange_distance = half + 0.5 * self.axial_clearance
        # The journal runs past both flanges so that the rings stay on its lateral surface.
        journal_half_length = flange_distance + self.bearing_length

        def local(pose, point, direction):
            position, quaternion = pose
            rotation = _rotation_matrix(quaternion)
            p_local = rotation.T @ (np.asarray(point, dtype=float) - np.asarray(position))
            z_local = rotation.T @ np.asarray(direction, dtype=float)
            return tuple(float(x) for x in p_local), _quaternion_z_to(z_local)

        n = self.name
        journal_shapes: list[Shape] = []
        bearing_shapes: list[Shape] = []
        position, orientation = local(journal_pose, anchor, axis)
        journal_shapes.append(
            Cylinder(
                f"{n}.journal",
                position=position,
                orientation=orientation,
                radius=self.journal_radius,
                half_length=journal_half_length,
            )
        )
        contacts = []
        for side, sign in (("bottom", -1.0), ("top", 1.0)):
            centre = anchor + sign * half * axis
            position, orientation = local(bearing_pose, centre, axis)
            bearing_shapes.append(
                Circle(f"{n}.ring_{side}", position=position, orientation=orientation,
                       radius=self.bore_radius)
            )
            for quarter in range(THRUST_ARCS):
                start = 2.0 * math.pi * quarter / THRUST_ARCS
                bearing_shapes.append(
                    Arc(f"{n}.thrust_{side}_{quarter}", position=position,
                        orientation=orientation, radius=self.thrust_radius, start_angle=start,
                        end_angle=start + 2.0 * math.pi / THRUST_ARCS)
                )
            # Flange plane: material on the far side, normal pointing back toward the bearing.
            flange_point = anchor + sign * flange_distance * axis
            position, orientation = local(journal_pose, flange_point, -sign * axis)
            journal_shapes.append(
                Plane(f"{n}.flange_{side}", position=position, orientation=orientation)
            )
            common = dict(friction=self.friction, restitution=self.restitution)
            contacts.append(
                ContactPair(f"{n}.ring_{side}", body_a=self.bearing_body,
                            shape_a=f"{n}.ring_{side}", body_b=self.journal_body,
                            shape_b=f"{n}.journal", **common)
            )
            for quarter in range(THRUST_ARCS):
                contacts.append(
                    ContactPair(f"{n}.flange_{side}_{quarter}", body_a=self.bearing_body,
                                shape_a=f"{n}.thrust_{side}_{quarter}",
                                body_b=self.journal_body, shape_b=f"{n}.flange_{side}",
                                **common)
                )
        return journal_shapes, bearing_shapes, contacts


def _rotation_matrix(quaternion) -> np.ndarray:
    w, x, y, z = (float(c) for c in quaternion)
    norm = math.sqrt(w * w + x * x + y * y + z * z)
    w, x, y, z = w / norm, x / norm, y / norm, z / norm
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def _quaternion_z_to(direction) -> tuple:
    """Unit quaternion of the shortest rotation taking +z to ``direction``."""
    d = np.asarray(direction, dtype=float)
    d = d / np.linalg.norm(d)
    if d[2] < -1.0 + 1e-12:
        return (0.0, 1.0, 0.0, 0.0)
    w = math.sqrt(0.5 * (1.0 + d[2]))
    return (w, -d[1] / (2.0 * w), d[0] / (2.0 * w), 0.0)
