"""Scene shapes as MuJoCo geoms, and the scene's contact pairs as MuJoCo ``<pair>`` elements.

=========  ==========================================================================
shape      MuJoCo geoms
=========  ==========================================================================
sphere     sphere
box        box
capsule    capsule
cylinder   cylinder (MuJoCo's cylinder also collides on its end caps)
plane      plane on a fixed body; on a moving body (MuJoCo planes must be static) a cube
           whose top face is the plane
circle     ring of N small spheres centred on the circle (default), or of N capsules /
           boxes whose inner surface is the circumscribed N-gon
arc        the pieces of that ring that cover the arc (spheres: both end points)
rectangle  box whose +z face is the rectangle, as deep as the shape's ``depth`` (else
           ``face_thickness`` x its larger half extent); its edges and sides collide too
disc       cylinder the same way (its rim collides too)
bore       N boxes lining the hole (MuJoCo geoms are convex): their inner faces form the
           circumscribed N-gon of the bore (apothem R), over the bore's angles and length
=========  ==========================================================================

A sphere of radius rho on the circle stands rho proud of it toward every partner; the pair
compensates with a negative MuJoCo pair margin (a contact acts when the distance is below the
margin). This is exact because MuJoCo collides spheres analytically with every other geom;
in its convex (GJK) collisions mujoco 4.0 counts a negative margin twice, so capsule and box
pieces are instead placed with their inner surface on the polygon (bores: partners inside
the ring), and compensated only against planes (analytic). The pair margin also carries the
pair's offset. Pure Python.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from clearbench.adapters.mujoco.settings import MujocoSettings, ring_chord_error
from clearbench.adapters.primitive_pieces import polygon_corner_error
from clearbench.kernels.quaternion import quat_from_matrix, quat_normalize, quat_to_matrix
from clearbench.scenarios.bodies import Motion
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.shapes import (
    Arc,
    Bore,
    Box,
    Capsule,
    Circle,
    Cylinder,
    Disc,
    Plane,
    Rectangle,
    Shape,
    Sphere,
)


@dataclass(frozen=True)
class GeomSpec:
    """One MuJoCo geom: ``kind`` in MuJoCo terms, ``size`` (3,), pose in the body frame."""

    name: str
    body: str
    shape: str
    kind: str
    size: tuple
    position: tuple
    orientation: tuple  # (w, x, y, z)
    compensation: float = 0.0  # surface offset of a ring piece, every partner [L]
    plane_compensation: float = 0.0  # ... against plane partners only [L]

    def offset_against(self, partner_shape_kind: str) -> float:
        """How far this geom's surface stands proud of the scene shape, toward a partner of
        that kind [L] (subtracted from the pair margin)."""
        if partner_shape_kind == "plane":
            return self.compensation + self.plane_compensation
        return self.compensation


@dataclass(frozen=True)
class RingInfo:
    """How a circle/arc shape was rebuilt: pieces, piece radius and chord error [L]; for a
    bore: boxes, their radial half thickness and the polygon's radius error [L]. ``overlap``:
    how deep a partner's exact surface can reach into the shape while it only touches the
    pieces [L] (spheres: the chord sag; a bore's boxes: their corners; 0 for the circumscribed
    polygon of capsules or boxes round a ring, which errs outward)."""

    body: str
    shape: str
    radius: float
    pieces: int
    piece_radius: float
    chord_error: float
    overlap: float = 0.0


def ring_piece_radius(scene: Scene, body: str, shape: Shape, settings: MujocoSettings) -> float:
    """Piece radius of a ring: ``ring_piece_radius`` times its radius, at most half the radial
    clearance of the clearance joint it belongs to."""
    value = settings.ring_piece_radius * shape.radius
    for joint in scene.clearance_joints:
        if shape.name.startswith(f"{joint.name}."):
            value = min(value, 0.5 * joint.radial_clearance)
    return value


def shape_geoms(scene: Scene, body_name: str, shape: Shape, settings: MujocoSettings,
                length_scale: float) -> tuple[list[GeomSpec], RingInfo | None]:
    """Geoms standing in for ``shape`` of ``body_name`` (in the body frame)."""
    prefix = f"{body_name}/{shape.name}"
    position = np.asarray(shape.position, dtype=float)
    orientation = quat_normalize(np.asarray(shape.orientation, dtype=float))

    def geom(kind, size, name=prefix, pos=position, quat=orientation, compensation=0.0,
             plane_compensation=0.0):
        size = tuple(float(x) for x in size) + (0.0,) * (3 - len(size))
        return GeomSpec(name, body_name, shape.name, kind, size,
                        tuple(float(x) for x in pos), tuple(float(x) for x in quat),
                        compensation, plane_compensation)

    if isinstance(shape, Sphere):
        return [geom("sphere", (shape.radius,))], None
    if isinstance(shape, Box):
        return [geom("box", shape.half_extents)], None
    if isinstance(shape, Capsule):
        return [geom("capsule", (shape.radius, shape.half_length))], None
    if isinstance(shape, Cylinder):
        return [geom("cylinder", (shape.radius, shape.half_length))], None
    if isinstance(shape, Plane):
        body = scene.expanded.body(body_name)  # clearance-joint flanges live in .expanded
        if body.motion is Motion.FIXED:
            return [geom("plane", (0.0, 0.0, 1.0))], None
        half = settings.plane_box_size * length_scale
        centre = position + quat_to_matrix(orientation) @ np.array([0.0, 0.0, -half])
        return [geom("box", (half, half, half), pos=centre)], None
    if isinstance(shape, Rectangle | Disc):
        thickness = face_thickness(shape, settings)
        centre = position + quat_to_matrix(orientation) @ np.array([0.0, 0.0, -0.5 * thickness])
        if isinstance(shape, Rectangle):
            size = (*shape.half_extents, 0.5 * thickness)
            return [geom("box", size, pos=centre)], None
        return [geom("cylinder", (shape.radius, 0.5 * thickness), pos=centre)], None
    if isinstance(shape, Bore):
        return _bore_geoms(body_name, shape, settings, geom, position, orientation)
    if isinstance(shape, Circle | Arc):
        return _ring_geoms(scene, body_name, shape, settings, geom, position, orientation)
    raise TypeError(f"unhandled shape kind {shape.kind!r}")  # pragma: no cover


def _ring_geoms(scene: Scene, body_name: str, shape: Circle | Arc, settings: MujocoSettings,
                geom, position, orientation) -> tuple[list[GeomSpec], RingInfo]:
    """Spheres on the circle (compensated by the pair margin), or capsules / boxes whose
    inner surface is the circumscribed polygon (compensated against planes only)."""
    full = isinstance(shape, Circle)
    start, end = (0.0, 2.0 * math.pi) if full else (shape.start_angle, shape.end_angle)
    pieces = max(1, math.ceil(settings.ring_pieces * (end - start) / (2.0 * math.pi) - 1e-9))
    step = (end - start) / pieces
    rho = ring_piece_radius(scene, body_name, shape, settings)
    rotation = quat_to_matrix(orientation)
    prefix = f"{body_name}/{shape.name}"
    out = []
    if settings.ring_piece == "sphere":
        count = pieces if full else pieces + 1  # an arc keeps both end points
        for k in range(count):
            angle = start + k * step
            centre = position + rotation @ (shape.radius * np.array(
                [math.cos(angle), math.sin(angle), 0.0]))
            out.append(geom("sphere", (rho,), name=f"{prefix}#{k}", pos=centre,
                            compensation=rho))
    else:
        apothem = shape.radius + rho  # inner surface on the polygon of apothem R
        half_chord = apothem * math.tan(0.5 * step)
        for k in range(pieces):
            angle = start + (k + 0.5) * step
            radial = np.array([math.cos(angle), math.sin(angle), 0.0])
            tangent = np.array([-math.sin(angle), math.cos(angle), 0.0])
            # Piece axes: x radial, y = -ring axis, z along the chord (right-handed).
            local = np.column_stack([radial, [0.0, 0.0, -1.0], tangent])
            centre = position + rotation @ (apothem * radial)
            quat = quat_from_matrix(rotation @ local)
            kind, size = ("capsule", (rho, half_chord)) if settings.ring_piece == "capsule" \
                else ("box", (rho, rho, half_chord))
            out.append(geom(kind, size, name=f"{prefix}#{k}", pos=centre, quat=quat,
                            plane_compensation=rho))
    full_circle_pieces = round(2.0 * math.pi / step)
    chord = ring_chord_error(shape.radius, full_circle_pieces, settings.ring_piece)
    return out, RingInfo(body_name, shape.name, shape.radius, len(out), rho, chord,
                         chord if settings.ring_piece == "sphere" else 0.0)


def face_thickness(shape: Rectangle | Disc, settings: MujocoSettings) -> float:
    """Thickness of the solid standing in for a bounded plane face [L]: its ``depth``, else
    ``face_thickness`` times its larger half extent (a disc: its radius)."""
    if shape.depth is not None:
        return float(shape.depth)
    size = max(shape.half_extents) if isinstance(shape, Rectangle) else shape.radius
    return settings.face_thickness * float(size)


def bore_piece_count(shape: Bore, settings: MujocoSettings) -> int:
    """Boxes lining ``shape``: ``bore_pieces`` per full circle, rounded up over its angles."""
    fraction = (shape.end_angle - shape.start_angle) / (2.0 * math.pi)
    return max(1, math.ceil(settings.bore_pieces * fraction - 1e-9))


def bore_radius_error(shape: Bore, settings: MujocoSettings) -> float:
    """Largest distance between the bore's circle and its polygon of boxes [L]: the inner faces
    are tangent to the circle (apothem R), the corners stand R (1/cos(step/2) - 1) outside it,
    step the angle one box spans (at most 2 pi / bore_pieces)."""
    step = (shape.end_angle - shape.start_angle) / bore_piece_count(shape, settings)
    return polygon_corner_error(shape.radius, step)


def _bore_geoms(body_name: str, shape: Bore, settings: MujocoSettings, geom, position,
                orientation) -> tuple[list[GeomSpec], RingInfo]:
    """Boxes whose inner faces are the circumscribed polygon of the bore (apothem R): box k
    spans the angles start + k step .. start + (k + 1) step, the bore's length axially and
    2 ``bore_wall`` R radially; its chord is the polygon edge extended to the outer face, so
    neighbours meet there and leave no gap (the extensions lie in the neighbour's material,
    outside the polygon)."""
    pieces = bore_piece_count(shape, settings)
    step = (shape.end_angle - shape.start_angle) / pieces
    wall = settings.bore_wall * shape.radius  # radial half thickness
    half_chord = (shape.radius + 2.0 * wall) * math.tan(0.5 * step)
    rotation = quat_to_matrix(orientation)
    prefix = f"{body_name}/{shape.name}"
    out = []
    for k in range(pieces):
        angle = shape.start_angle + (k + 0.5) * step
        radial = np.array([math.cos(angle), math.sin(angle), 0.0])
        tangent = np.array([-math.sin(angle), math.cos(angle), 0.0])
        # Box axes: x radial (outward), y = -bore axis, z along the chord (right-handed).
        local = np.column_stack([radial, [0.0, 0.0, -1.0], tangent])
        centre = position + rotation @ ((shape.radius + wall) * radial)
        out.append(geom("box", (wall, shape.half_length, half_chord), name=f"{prefix}#{k}",
                        pos=centre, quat=quat_from_matrix(rotation @ local)))
    error = bore_radius_error(shape, settings)
    return out, RingInfo(body_name, shape.name, shape.radius, pieces, wall, error, error)


def pair_overlaps(scene: Scene, rings) -> dict[str, float]:
    """Per contact pair of ``scene`` (expanded), the sum of its two sides' ring
    ``overlap`` [L] (:class:`RingInfo`; a side without a ring is exact)."""
    overlap = {(ring.body, ring.shape): ring.overlap for ring in rings}
    return {contact.name: overlap.get((contact.body_a, contact.shape_a), 0.0)
            + overlap.get((contact.body_b, contact.shape_b), 0.0)
            for contact in scene.expanded.contacts}


@dataclass(frozen=True)
class PairSpec:
    """One MuJoCo ``<pair>``: geoms, scene contact index, and its ``margin`` = offset -
    compensations: the contact acts when the geoms' distance is below it (MuJoCo accepts a
    negative pair margin; the pair ``gap`` of mujoco 4.0 does not move the activation
    distance, so it stays 0)."""

    geom_a: str
    geom_b: str
    contact: int
    margin: float
