"""Scene shapes rebuilt from convex primitives, one set of pieces per side of each contact pair:
the one implementation for engines whose collision shapes are spheres, boxes, capsules,
cylinders and planes only (PyBullet, Drake's point contact).

Every SIDE of every contact pair gets pieces of its own, and side A's pieces carry the pair's
offset (the scene takes the offset on A's side):

=========  ==========================================================================
shape      pieces (side A grown by the pair's offset d)
=========  ==========================================================================
sphere     sphere r + d
box        box half extents + d (sharp corners where the offset surface is rounded)
capsule    capsule r + d (``half_length``: the segment between the centres)
cylinder   cylinder r + d, same length (its end caps collide too)
plane      plane on a fixed body (moved d along its normal); on a moving body a box whose top
           face is the plane
rectangle  box whose +z face is the rectangle (moved d), as thick as the shape's ``depth``
           (else ``face_thickness`` x its larger half extent); edges and sides collide too
disc       cylinder the same way
circle     ring of spheres of radius rho = max(d, ring_piece_radius R) centred on the circle
           (``ring_pieces`` per full circle), each moved by rho - d AWAY from the partner
           (direction at t = 0), so that the surface presented is the offset curve
arc        the spheres of that ring over the arc, both end points included
bore       capsules along the bore axis lining the hole (``bore_pieces`` per full circle),
           radius rho = bore_piece_radius R, axes on the circle of radius R - d + rho
=========  ==========================================================================

``settings`` is a :class:`PieceSettings` (the settings dataclass of each engine that builds
with pieces derives from it, and its option table includes :data:`PIECE_OPTIONS`). Pure Python.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from clearbench.adapters.options import integer, number
from clearbench.kernels.quaternion import (
    quat_from_matrix,
    quat_multiply,
    quat_normalize,
    quat_to_matrix,
)
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

__all__ = ["PIECE_OPTIONS", "Piece", "PieceSettings", "SideGeometry", "face_thickness",
           "journal_clearance_growth", "journal_of", "pair_clearance_growth", "ring_chord_error",
           "ring_sphere_radius", "ring_step",
           "side_geometry", "toward_partner"]

@dataclass(frozen=True)
class PieceSettings:
    """How rings, bores and bounded faces are built from primitives (the fields of every
    engine settings dataclass that derives from it).

    Attributes
    ----------
    ring_pieces : int
        Spheres per full circle of a ring (circle or arc shape).
    ring_piece_radius : float
        Least radius of a ring sphere relative to the ring radius (a pair's positive offset
        gives larger spheres); capped at half the radial clearance of a clearance joint.
    bore_pieces : int
        Capsules per full circle lining a bore.
    bore_piece_radius : float
        Radius of the bore capsules relative to the bore radius.
    face_thickness : float
        Thickness of the box (rectangle) or cylinder (disc) standing in for a bounded face
        without ``depth``, relative to its larger half extent (or radius).
    plane_box_size : float
        Half size of the box standing in for a plane on a moving body, relative to the scene's
        largest length.
    """

    ring_pieces: int = 64
    ring_piece_radius: float = 0.01
    bore_pieces: int = 64
    bore_piece_radius: float = 0.05
    face_thickness: float = 0.1
    plane_box_size: float = 100.0


#: Type and range of each field of :class:`PieceSettings`, for the engines' option tables.
PIECE_OPTIONS = (
    integer("ring_pieces", at_least=3),
    number("ring_piece_radius", above=0.0),
    integer("bore_pieces", at_least=3),
    number("bore_piece_radius", above=0.0),
    number("face_thickness", above=0.0),
    number("plane_box_size", above=0.0),
)


@dataclass(frozen=True)
class Piece:
    """One PyBullet primitive in the frame of its scene body.

    Attributes
    ----------
    kind : {'sphere', 'box', 'capsule', 'cylinder', 'plane'}
    size : tuple
        sphere (r,), box (hx, hy, hz), capsule and cylinder (r, half_length), plane () [L].
    position : (3,) tuple
        Piece frame origin in the body frame [L].
    orientation : (4,) tuple
        Piece frame orientation in the body frame, unit quaternion (w, x, y, z); the axis of
        capsules and cylinders and the normal of planes is the piece's z.
    """

    kind: str
    size: tuple
    position: tuple
    orientation: tuple


@dataclass(frozen=True)
class SideGeometry:
    """How one side of one contact pair is rebuilt.

    Attributes
    ----------
    body, shape : str
        Scene body and shape of this side.
    pieces : tuple of Piece
    note : str
        How the shape was rebuilt (for the capabilities).
    shape_error : float
        Largest distance between the scene's (offset) surface and the surface the pieces
        present to a large partner [L]; 0 when exact.
    """

    body: str
    shape: str
    pieces: tuple
    note: str
    shape_error: float = 0.0


def _unit_quat(q) -> np.ndarray:
    """``q`` as a float array of norm 1 (w, x, y, z)."""
    return quat_normalize(np.asarray(q, dtype=float))


# ---------------------------------------------------------------------------- ring sizes
def ring_sphere_radius(scene: Scene, shape: Shape, offset: float,
                       settings) -> float:
    """Radius of the spheres of a ring [L]: the side's offset when it is at least the least
    piece radius (``ring_piece_radius`` R, at most half the radial clearance of a clearance
    joint's ring), else that least radius."""
    least = settings.ring_piece_radius * shape.radius
    for joint in scene.clearance_joints:
        if shape.name.startswith(f"{joint.name}."):
            least = min(least, 0.5 * joint.radial_clearance)
    return max(offset, least)


def ring_step(shape: Circle | Arc | Bore, pieces_per_circle: int) -> tuple[float, float, int]:
    """(start angle, angle between pieces, number of intervals) of a ring or bore."""
    if isinstance(shape, Circle):
        return 0.0, 2.0 * math.pi / pieces_per_circle, pieces_per_circle
    span = shape.end_angle - shape.start_angle
    count = max(1, math.ceil(pieces_per_circle * span / (2.0 * math.pi) - 1e-9))
    return shape.start_angle, span / count, count


def ring_chord_error(radius: float, step: float) -> float:
    """Sag between two spheres on a circle of ``radius`` whose centres are ``step`` apart in
    angle, seen by a flat partner whose normal lies in the ring's plane [L]."""
    return radius * (1.0 - math.cos(0.5 * step))


def polygon_corner_error(radius: float, step: float) -> float:
    """How far the corners of the polygon circumscribed about a circle of ``radius`` (one
    side per ``step`` of angle [rad]) stand outside the circle [L]: R (1/cos(step/2) - 1)."""
    return radius * (1.0 / math.cos(0.5 * step) - 1.0)


def pair_overlap(sides) -> float:
    """How deep the scene's exact surfaces of one pair can overlap while the pieces of its two
    sides (:class:`SideGeometry`) only touch [L]: the sum of the sides' ``shape_error`` (the
    sag a flat partner sinks between two pieces of a ring or a bore's lining; 0 where exact).
    Against a curved partner the overlap is smaller: this is its upper bound."""
    return float(sum(side.shape_error for side in sides))


def journal_clearance_growth(ring_radius: float, journal_radius: float, sphere_radius: float,
                             centre_radius: float, step: float) -> float:
    """Extra eccentricity a coaxial journal gains between two ring spheres [L].

    Spheres of radius ``sphere_radius`` centred on a circle of ``centre_radius``, ``step``
    apart; the journal touches them when its centre is r + rho from theirs. Ideal limit: the
    eccentricity ``ring_radius - journal_radius`` (the offset ring's radial clearance).
    """
    half = 0.5 * step
    reach_sq = (journal_radius + sphere_radius) ** 2 - (centre_radius * math.sin(half)) ** 2
    if reach_sq <= 0.0:
        return math.inf
    reach = centre_radius * math.cos(half) - math.sqrt(reach_sq)
    return reach - (ring_radius - journal_radius)


# ---------------------------------------------------------------------------- partners
def _world_shape_frame(scene: Scene, body_name: str, shape: Shape):
    body = scene.expanded.body(body_name)
    q_body = _unit_quat(body.orientation)
    rotation_body = quat_to_matrix(q_body)
    position = np.asarray(body.position, dtype=float) + rotation_body @ np.asarray(
        shape.position, dtype=float)
    rotation = quat_to_matrix(_unit_quat(quat_multiply(q_body, _unit_quat(shape.orientation))))
    return position, rotation


def toward_partner(point: np.ndarray, partner: Shape, origin: np.ndarray,
                   rotation: np.ndarray, fallback: np.ndarray) -> np.ndarray:
    """Unit direction (world) from ``point`` toward the surface of the partner shape placed at
    ``origin`` with ``rotation`` (its frame's axes as columns); ``fallback`` where undefined."""
    local = rotation.T @ (point - origin)
    if isinstance(partner, Plane | Rectangle | Disc):
        direction = -np.array([0.0, 0.0, 1.0])
    elif isinstance(partner, Cylinder | Capsule):
        direction = -np.array([local[0], local[1], 0.0])
    elif isinstance(partner, Bore):
        direction = np.array([local[0], local[1], 0.0])
    elif isinstance(partner, Sphere):
        direction = -local
    elif isinstance(partner, Box):
        closest = np.clip(local, -np.asarray(partner.half_extents), partner.half_extents)
        direction = closest - local
    else:  # circle / arc partner: toward its nearest point
        planar = np.array([local[0], local[1], 0.0])
        norm = np.linalg.norm(planar)
        nearest = partner.radius * planar / norm if norm > 0 else np.array(
            [partner.radius, 0.0, 0.0])
        direction = nearest - local
    norm = np.linalg.norm(direction)
    if not norm > 1e-12:
        return fallback
    return rotation @ (direction / norm)


# ---------------------------------------------------------------------------- pieces
def side_geometry(scene: Scene, contact_index: int, side: str, settings,
                  length_scale: float) -> SideGeometry:
    """Pieces of side ``'a'`` or ``'b'`` of contact ``contact_index`` (``scene.all_contacts``),
    in the frame of that side's body, side A grown by the pair's offset."""
    expanded = scene.expanded
    contact = expanded.contacts[contact_index]
    body_name = contact.body_a if side == "a" else contact.body_b
    shape_name = contact.shape_a if side == "a" else contact.shape_b
    other_body = contact.body_b if side == "a" else contact.body_a
    other_name = contact.shape_b if side == "a" else contact.shape_a
    body = expanded.body(body_name)
    shape = body.shape(shape_name)
    offset = contact.offset if side == "a" else 0.0
    position = np.asarray(shape.position, dtype=float)
    orientation = _unit_quat(shape.orientation)
    rotation = quat_to_matrix(orientation)
    z_axis = rotation[:, 2]

    def piece(kind, size, pos=position, quat=orientation):
        return Piece(kind, tuple(float(x) for x in size), tuple(float(x) for x in pos),
                     tuple(float(x) for x in _unit_quat(quat)))

    def grown(value: float, what: str) -> float:
        if not value + offset > 0:
            raise ValueError(f"contact {contact.name!r}: offset {offset:g} makes the {what} of "
                             f"{body_name}/{shape_name} non-positive ({value + offset:g})")
        return value + offset

    grown_note = f", grown by the offset {offset:g}" if offset else ""
    if isinstance(shape, Sphere):
        return SideGeometry(body_name, shape_name, (piece("sphere", (grown(shape.radius,
                            "radius"),)),), "sphere" + grown_note)
    if isinstance(shape, Box):
        half = [grown(h, "half extent") for h in shape.half_extents]
        error = abs(offset) * (math.sqrt(3.0) - 1.0) if offset else 0.0
        return SideGeometry(body_name, shape_name, (piece("box", half),),
                            "box" + grown_note, error)
    if isinstance(shape, Capsule):
        return SideGeometry(body_name, shape_name, (piece("capsule", (
            grown(shape.radius, "radius"), shape.half_length)),), "capsule" + grown_note)
    if isinstance(shape, Cylinder):
        return SideGeometry(body_name, shape_name, (piece("cylinder", (
            grown(shape.radius, "radius"), shape.half_length)),),
            "cylinder (end caps collide too)" + grown_note)
    if isinstance(shape, Plane):
        if body.motion is Motion.FIXED:
            return SideGeometry(body_name, shape_name, (piece(
                "plane", (), position + offset * z_axis),), "static plane" + grown_note)
        half = settings.plane_box_size * length_scale
        centre = position + (offset - half) * z_axis
        return SideGeometry(body_name, shape_name, (piece("box", (half, half, half), centre),),
                            f"box of half size {half:.3g} whose +z face is the plane"
                            + grown_note)
    if isinstance(shape, Rectangle | Disc):
        thickness = face_thickness(shape, settings)
        centre = position + (offset - 0.5 * thickness) * z_axis
        if isinstance(shape, Rectangle):
            size = (*shape.half_extents, 0.5 * thickness)
            return SideGeometry(body_name, shape_name, (piece("box", size, centre),),
                                f"box {thickness:.3g} thick behind the face (edges collide)"
                                + grown_note)
        return SideGeometry(body_name, shape_name, (piece("cylinder", (
            shape.radius, 0.5 * thickness), centre),),
            f"cylinder {thickness:.3g} thick behind the face (rim collides)" + grown_note)
    if isinstance(shape, Bore):
        return _bore(body_name, shape, offset, settings, piece, position, rotation)
    if isinstance(shape, Circle | Arc):
        other = expanded.body(other_body)
        partner = other.shape(other_name)
        return _ring(scene, body_name, shape, offset, settings, piece, position, rotation,
                     (other_body, partner))
    raise TypeError(f"unhandled shape kind {shape.kind!r}")  # pragma: no cover


def face_thickness(shape: Rectangle | Disc, settings) -> float:
    """Thickness of the solid standing in for a bounded face [L]: its ``depth``, else
    ``face_thickness`` times its larger half extent (a disc: its radius)."""
    if shape.depth is not None:
        return float(shape.depth)
    size = max(shape.half_extents) if isinstance(shape, Rectangle) else shape.radius
    return settings.face_thickness * float(size)


def _bore(body_name, shape: Bore, offset, settings, piece, position, rotation) -> SideGeometry:
    """Capsules along the bore axis whose inner lines lie on the offset bore circle."""
    radius = shape.radius - offset
    if not radius > 0:
        raise ValueError(f"bore {body_name}/{shape.name}: offset {offset:g} >= its radius")
    rho = settings.bore_piece_radius * shape.radius
    start, step, count = ring_step(shape, settings.bore_pieces)
    full = isinstance(shape, Bore) and abs(shape.end_angle - shape.start_angle - 2 * math.pi) \
        < 1e-12
    pieces = []
    for k in range(count if full else count + 1):
        angle = start + k * step
        radial = np.array([math.cos(angle), math.sin(angle), 0.0])
        centre = position + rotation @ ((radius + rho) * radial)
        pieces.append(piece("capsule", (rho, shape.half_length), centre,
                            quat_from_matrix(rotation)))
    sag = (radius + rho) * (1.0 - math.cos(0.5 * step))
    note = (f"{len(pieces)} capsules of radius {rho:.3g} along the axis, inner lines on the "
            f"circle R - offset = {radius:.6g}; a flat partner sinks {sag:.3g} between two")
    return SideGeometry(body_name, shape.name, tuple(pieces), note, sag)


def _ring(scene, body_name, shape: Circle | Arc, offset, settings, piece, position, rotation,
          partner) -> SideGeometry:
    """Spheres on the circle, moved away from the partner so that their surface toward it
    lies on the offset curve."""
    rho = ring_sphere_radius(scene, shape, offset, settings)
    start, step, count = ring_step(shape, settings.ring_pieces)
    full = isinstance(shape, Circle)
    other_body, other_shape = partner
    other_origin, other_rotation = _world_shape_frame(scene, other_body, other_shape)
    body = scene.expanded.body(body_name)
    q_body = _unit_quat(body.orientation)
    body_rotation = quat_to_matrix(q_body)
    body_position = np.asarray(body.position, dtype=float)
    shift = rho - offset
    pieces = []
    for k in range(count if full else count + 1):
        angle = start + k * step
        local = position + rotation @ (shape.radius * np.array(
            [math.cos(angle), math.sin(angle), 0.0]))
        world = body_position + body_rotation @ local
        fallback = body_rotation @ rotation[:, 2]
        direction = toward_partner(world, other_shape, other_origin, other_rotation, fallback)
        centre = local - shift * (body_rotation.T @ direction)
        pieces.append(piece("sphere", (rho,), centre))
    chord = ring_chord_error(shape.radius, step)
    note = (f"{len(pieces)} spheres of radius {rho:.3g} on the circle R {shape.radius:.6g}, "
            f"moved {shift:.3g} away from the partner (its direction at t = 0); chord sag "
            f"{chord:.3g}")
    return SideGeometry(body_name, shape.name, tuple(pieces), note, chord)


def journal_of(scene: Scene, contact_index: int) -> tuple[float, float] | None:
    """(offset ring radius, journal radius) when contact ``contact_index`` is a ring or bore
    with a coaxial cylinder of smaller radius inside it (a journal), else None."""
    expanded = scene.expanded
    contact = expanded.contacts[contact_index]
    shape_a = expanded.body(contact.body_a).shape(contact.shape_a)
    shape_b = expanded.body(contact.body_b).shape(contact.shape_b)
    ring, journal, ring_body, journal_body, ring_side = shape_a, shape_b, contact.body_a, \
        contact.body_b, "a"
    if isinstance(shape_b, Circle | Arc | Bore):
        ring, journal, ring_body, journal_body, ring_side = shape_b, shape_a, contact.body_b, \
            contact.body_a, "b"
    if not (isinstance(ring, Circle | Arc | Bore) and isinstance(journal, Cylinder)):
        return None
    _, rotation_ring = _world_shape_frame(scene, ring_body, ring)
    _, rotation_journal = _world_shape_frame(scene, journal_body, journal)
    if abs(abs(float(rotation_ring[:, 2] @ rotation_journal[:, 2])) - 1.0) > 1e-6:
        return None
    ring_radius = ring.radius - (contact.offset if ring_side == "a" else 0.0)
    journal_radius = journal.radius + (contact.offset if ring_side == "b" else 0.0)
    if journal_radius >= ring_radius:
        return None
    return ring_radius, journal_radius


def pair_clearance_growth(scene: Scene, contact_index: int,
                          settings) -> tuple[float, float] | None:
    """(radial clearance, extra eccentricity between two pieces) [L] of a ring/bore-journal
    pair; None for other pairs."""
    found = journal_of(scene, contact_index)
    if found is None:
        return None
    ring_radius, journal_radius = found
    expanded = scene.expanded
    contact = expanded.contacts[contact_index]
    shapes = [expanded.body(contact.body_a).shape(contact.shape_a),
              expanded.body(contact.body_b).shape(contact.shape_b)]
    ring = next(s for s in shapes if isinstance(s, Circle | Arc | Bore))
    offset = contact.offset if ring is shapes[0] else 0.0
    if isinstance(ring, Bore):
        rho = settings.bore_piece_radius * ring.radius
        _, step, _ = ring_step(ring, settings.bore_pieces)
    else:
        rho = ring_sphere_radius(scene, ring, offset, settings)
        _, step, _ = ring_step(ring, settings.ring_pieces)
    growth = journal_clearance_growth(ring_radius, journal_radius, rho, ring_radius + rho, step)
    return ring_radius - journal_radius, growth
