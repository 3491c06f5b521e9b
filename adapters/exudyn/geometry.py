"""Scene contact pairs as Exudyn per-pair contact connectors (pure Python, no ``exudyn``).

Exudyn 1.13 has two per-pair connectors for rigid bodies: ``ObjectContactSphereSphere``
(optionally a sphere inside a hollow sphere) and ``ObjectContactSphereTriangle`` (a sphere
against a triangle, two-sided: the gap is the distance from the sphere's centre to the closest
point of the triangle, its edges included or not, minus the radius). ``CreateSphereQuadContact``
is two sphere-triangle connectors. Every scene pair is rebuilt from these:

================  =========================================================================
pair              connectors (gap = the scene's gap minus the pair's offset, see below)
================  =========================================================================
sphere-sphere     one sphere-sphere connector (A's radius grown by the offset)
sphere-plane      the sphere against one triangle covering ``plane_size`` x the largest length
sphere-rectangle  the sphere against the rectangle (edges excluded: bounded face)
sphere-disc       the sphere against a fan of ``disc_segments`` triangles (inscribed polygon)
sphere-box        the sphere against the box's 6 faces (edges included; a sphere at an edge
                  or corner is pushed by each face that reaches it: up to 2-3x the force)
box-face          8 corner spheres of radius rho = ``corner_sphere_radius`` x the smallest half
                  extent, centred ON the corners, against the face moved back by rho: the gap
                  is exactly the corner's height (a convex box touches a plane at corners)
ring-face         ``ring_spheres`` spheres per circle ON the ring (circle or arc, both ends
                  included), face moved back by their radius: exact at the sample points
cylinder-face     spheres of the cylinder's radius at both ends of its axis: exact for a
                  cylinder lying on the face (axis parallel), its rims rounded otherwise
ring-cylinder     internal full ring (journal in a bearing ring), ``ring_journal`` =
                  'hollow_sphere': a sphere of the journal's radius on its axis at the ring's
                  plane inside a hollow sphere of the ring's radius (exact in that plane;
                  an axial offset dz between them adds dz^2 / (2 c) near contact);
                  otherwise ring spheres against the cylinder as a prism of
                  ``journal_facets`` faces (apothem compensated; within ``facet_window`` of
                  each sphere's direction at t = 0)
ring-bore         full bore: each ring sphere inside a hollow sphere of the bore's radius on its
                  axis at the sphere's level ('in_plane'); a bore patch (angles < 2 pi): ring
                  spheres against its lining facets over its angles and length
cylinder-bore     ``journal_spheres`` spheres of the journal's radius along its axis against
                  the bore's lining facets
================  =========================================================================

Faces (planes, rectangles, discs, facets) are moved along their normal so that the connector's
gap (centre distance minus sphere radius) equals the scene's gap minus the offset. A facet
polygon is circumscribed (tangent at each facet's middle): the surface is exact at the middle
of each facet and off by R (1/cos(pi/M) - 1) at its corners (``facet_error``).
Other pairs (box-box, capsules, cylinder-cylinder, cylinder-sphere, ring-sphere, ...) have no
connector: :func:`pair_problem` says why.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from clearbench.adapters.exudyn.settings import ExudynSettings
from clearbench.adapters.primitive_pieces import polygon_corner_error
from clearbench.adapters.primitive_pieces import ring_chord_error as chord_sag
from clearbench.kernels.quaternion import quat_to_matrix
from clearbench.scenarios.bodies import Motion
from clearbench.scenarios.contacts import ContactPair
from clearbench.scenarios.scales import largest_length
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.shapes import Arc, Bore, Circle, Disc, Plane, Rectangle

FACE_KINDS = ("plane", "rectangle", "disc")
RING_KINDS = ("circle", "arc")
#: Exudyn includeEdges flags of a triangle: bit 0 edge p0-p1, bit 1 p1-p2, bit 2 p2-p0.
ALL_EDGES = 7


@dataclass(frozen=True)
class ConnectorPlan:
    """One Exudyn contact connector of a scene pair (positions in the body frames [L]).

    Attributes
    ----------
    kind : {'sphere_triangle', 'sphere_sphere'}
    sphere_body, sphere_point, sphere_radius
        Body, centre (3,) in its frame, radius of the sphere (Exudyn marker 0).
    other_body, other_point
        Body of the partner (marker 1) and the marker's position (3,) in its frame: the
        partner sphere's centre, or the body origin for a triangle.
    other_radius, hollow
        Partner sphere radius and whether it is hollow (sphere_sphere only).
    triangle : tuple of three (3,) tuples
        Triangle corners in the partner's body frame (sphere_triangle only).
    include_edges : int
        Exudyn ``includeEdges`` bit flags of the triangle.
    sphere_is_b : bool
        True when the sphere's body is the pair's body B (Exudyn's Force output is the force on
        the sphere: the force on B is +Force, else -Force).
    """

    kind: str
    sphere_body: str
    sphere_point: tuple
    sphere_radius: float
    other_body: str
    other_point: tuple = (0.0, 0.0, 0.0)
    other_radius: float = 0.0
    hollow: bool = False
    triangle: tuple = ()
    include_edges: int = ALL_EDGES
    sphere_is_b: bool = True


@dataclass
class PairPlan:
    """Connectors of one scene pair and how the pair was rebuilt."""

    contact: ContactPair
    connectors: list[ConnectorPlan] = field(default_factory=list)
    how: str = ""
    shape_error: float = 0.0  # largest surface error of the rebuild [L]
    #: How deep the scene's exact surfaces can overlap while the connectors only touch [L]:
    #: the sag between ring spheres, the corners of a bore's facet lining; 0 where the rebuild
    #: errs outward only (a journal's circumscribed prism) or is exact.
    overlap: float = 0.0


class UnsupportedPair(ValueError):
    """A pair Exudyn has no connector for (the message says why)."""


# ---------------------------------------------------------------------------- small helpers
def _shape_frame(shape) -> tuple[np.ndarray, np.ndarray]:
    """Position (3,) and rotation (3, 3) of a shape's frame in its body frame."""
    q = np.asarray(shape.orientation, dtype=float)
    return np.asarray(shape.position, dtype=float), quat_to_matrix(q / np.linalg.norm(q))


def _to_body(shape, local) -> np.ndarray:
    """Points (..., 3) of a shape's frame in its body frame."""
    position, rotation = _shape_frame(shape)
    return np.asarray(local, dtype=float) @ rotation.T + position


def _body_pose(scene: Scene, name: str) -> tuple[np.ndarray, np.ndarray]:
    body = scene.expanded.body(name)
    q = np.asarray(body.orientation, dtype=float)
    return np.asarray(body.position, dtype=float), quat_to_matrix(q / np.linalg.norm(q))


def _world(scene: Scene, body: str, points) -> np.ndarray:
    position, rotation = _body_pose(scene, body)
    return np.asarray(points, dtype=float) @ rotation.T + position


def _local(scene: Scene, body: str, points) -> np.ndarray:
    position, rotation = _body_pose(scene, body)
    return (np.asarray(points, dtype=float) - position) @ rotation


def _t(v) -> tuple:
    return tuple(float(x) for x in v)


def ring_points(shape: Circle | Arc, settings: ExudynSettings) -> np.ndarray:
    """(N, 3) sample points of a circle or arc in its own frame: ``ring_spheres`` per full
    circle, both ends of an arc included."""
    if isinstance(shape, Circle):
        angles = np.arange(settings.ring_spheres) * 2.0 * math.pi / settings.ring_spheres
    else:
        span = shape.end_angle - shape.start_angle
        count = max(2, int(math.ceil(span / (2.0 * math.pi) * settings.ring_spheres)) + 1)
        angles = np.linspace(shape.start_angle, shape.end_angle, count)
    return shape.radius * np.column_stack([np.cos(angles), np.sin(angles), 0.0 * angles])


def ring_chord_error(radius: float, spheres_per_circle: int) -> float:
    """Largest distance between a ring and the chord of two neighbouring samples [L]:
    R (1 - cos(pi / N)); a partner spanning two samples sees the ring that much lower."""
    return chord_sag(radius, 2.0 * math.pi / spheres_per_circle)


def facet_error(radius: float, facets_per_circle: int) -> float:
    """Largest distance between a circle and its circumscribed polygon [L]:
    R (1 / cos(pi / M) - 1), at the polygon's corners."""
    return polygon_corner_error(radius, 2.0 * math.pi / facets_per_circle)


def ring_sphere_radius(shape, partner_room: float, settings: ExudynSettings) -> float:
    """Radius of a ring's sample spheres: ``ring_sphere_radius`` x the ring radius, at most
    0.9 x ``partner_room`` (how far the partner's surface may be moved back)."""
    value = settings.ring_sphere_radius * shape.radius
    if partner_room > 0:
        value = min(value, 0.9 * partner_room)
    return value


# ---------------------------------------------------------------------------- faces
def _face_triangles(scene: Scene, body: str, shape, shift: float,
                    settings: ExudynSettings) -> tuple[list[tuple], int, str]:
    """Triangles (body frame) of a plane, rectangle or disc moved by ``shift`` along its
    normal; their includeEdges flags; and a description."""
    if isinstance(shape, Plane):
        # One triangle covering the square |x|, |y| <= half (every connector costs, even
        # when it is not in contact).
        half = settings.plane_size * largest_length(scene)
        points = _to_body(shape, [(-half, -half, shift), (3 * half, -half, shift),
                                  (-half, 3 * half, shift)])
        return ([(_t(points[0]), _t(points[1]), _t(points[2]))], 0,
                f"one triangle covering a square of half size {half:.3g}")
    if isinstance(shape, Rectangle):
        hx, hy = shape.half_extents
        corners = [(-hx, -hy), (hx, -hy), (hx, hy), (-hx, hy)]
        how = "the rectangle (no edge contact)"
    elif isinstance(shape, Disc):
        n = settings.disc_segments
        angles = np.arange(n) * 2.0 * math.pi / n
        rim = _to_body(shape, np.column_stack([shape.radius * np.cos(angles),
                                               shape.radius * np.sin(angles),
                                               np.full(n, shift)]))
        centre = _to_body(shape, [0.0, 0.0, shift])
        triangles = [(_t(centre), _t(rim[i]), _t(rim[(i + 1) % n])) for i in range(n)]
        return triangles, 0, f"fan of {n} triangles (inscribed polygon, no edge contact)"
    else:  # pragma: no cover - callers pass faces only
        raise TypeError(shape.kind)
    points = _to_body(shape, [(x, y, shift) for x, y in corners])
    triangles = [(_t(points[0]), _t(points[1]), _t(points[3])),
                 (_t(points[1]), _t(points[2]), _t(points[3]))]
    return triangles, 0, how


def _spheres_against_faces(contact: ContactPair, sphere_body: str, centres: np.ndarray,
                           radius: float, face_body: str, triangles: list[tuple],
                           edges: int) -> list[ConnectorPlan]:
    return [ConnectorPlan("sphere_triangle", sphere_body, _t(c), radius, face_body,
                          triangle=triangle, include_edges=edges,
                          sphere_is_b=sphere_body == contact.body_b)
            for c in centres for triangle in triangles]


# ---------------------------------------------------------------------------- prisms
def _prism_triangles(shape, apothem: float, half_length: float, facets: int,
                     start: float, end: float) -> list[tuple[tuple, int, float]]:
    """Facets of a cylinder or of a bore's lining in the shape's frame:
    (triangle, includeEdges, facet angle) for each half of each facet.

    The facets are tangent to the circle of radius ``apothem`` at their middle, spaced
    2 pi / ``facets`` over [start, end]. Only the edges between neighbouring facets are contact
    edges (once each): no contact beyond the ends of the prism or the angles of a patch.
    """
    span = end - start
    count = max(1, int(math.ceil(span / (2.0 * math.pi) * facets - 1e-9)))
    step = span / count
    corner = apothem / math.cos(0.5 * step)
    out = []
    for i in range(count):
        a0, a1 = start + i * step, start + (i + 1) * step
        p0 = (corner * math.cos(a0), corner * math.sin(a0))
        p1 = (corner * math.cos(a1), corner * math.sin(a1))
        quad = [(p0[0], p0[1], -half_length), (p1[0], p1[1], -half_length),
                (p1[0], p1[1], half_length), (p0[0], p0[1], half_length)]
        # Quad split [0, 1, 3] + [1, 2, 3]; edges of a triangle: bit 0 = t0-t1, bit 1 =
        # t1-t2, bit 2 = t2-t0. Triangle A has the bottom edge, the diagonal and the side at
        # a0 (bit 2); triangle B the side at a1, the top and the diagonal. Only the side at a0
        # is a contact edge (each polygon corner once; not at the start of a partial span):
        # the ends and the diagonal are not.
        full = span >= 2.0 * math.pi - 1e-12
        edges_a, edges_b = (4 if (i > 0 or full) else 0), 0
        middle = 0.5 * (a0 + a1)
        out.append(((quad[0], quad[1], quad[3]), edges_a, middle))
        out.append(((quad[1], quad[2], quad[3]), edges_b, middle))
    return [(tuple(_t(p) for p in _to_body(shape, tri)), edges, angle)
            for tri, edges, angle in out]


def _angle_difference(a: float, b: float) -> float:
    return abs(math.remainder(a - b, 2.0 * math.pi))


# ---------------------------------------------------------------------------- pair handlers
def _sphere_sphere(scene, contact, a, b, settings) -> PairPlan:
    centre_a = _to_body(a, [0.0, 0.0, 0.0])
    centre_b = _to_body(b, [0.0, 0.0, 0.0])
    radius_a = a.radius + contact.offset
    if not radius_a > 0:
        raise UnsupportedPair(f"offset {contact.offset} exceeds sphere radius {a.radius}")
    plan = ConnectorPlan("sphere_sphere", contact.body_a, _t(centre_a), radius_a,
                         contact.body_b, _t(centre_b), b.radius, sphere_is_b=False)
    return PairPlan(contact, [plan], "sphere-sphere connector (exact)")


def _sphere_face(scene, contact, sphere_side, face_side, settings) -> PairPlan:
    (sphere_body, sphere), (face_body, face) = sphere_side, face_side
    triangles, edges, how = _face_triangles(scene, face_body, face, contact.offset, settings)
    centre = _to_body(sphere, [[0.0, 0.0, 0.0]])
    plan = PairPlan(contact, _spheres_against_faces(contact, sphere_body, centre, sphere.radius,
                                                    face_body, triangles, edges),
                    f"sphere against {how}")
    if isinstance(face, Disc):
        plan.shape_error = ring_chord_error(face.radius, settings.disc_segments)
    return plan


def _sphere_box(scene, contact, sphere_side, box_side, settings) -> PairPlan:
    (sphere_body, sphere), (box_body, box) = sphere_side, box_side
    h = np.asarray(box.half_extents, dtype=float) + contact.offset
    triangles = []
    for axis in range(3):
        u, v = (axis + 1) % 3, (axis + 2) % 3
        for sign in (-1.0, 1.0):
            corners = []
            for su, sv in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
                p = np.zeros(3)
                p[axis], p[u], p[v] = sign * h[axis], su * h[u], sv * h[v]
                corners.append(p)
            points = _to_body(box, corners)
            triangles += [(_t(points[0]), _t(points[1]), _t(points[3])),
                          (_t(points[1]), _t(points[2]), _t(points[3]))]
    centre = _to_body(sphere, [[0.0, 0.0, 0.0]])
    connectors = _spheres_against_faces(contact, sphere_body, centre, sphere.radius, box_body,
                                        triangles, ALL_EDGES)
    return PairPlan(contact, connectors, "sphere against the 12 triangles of the box's faces "
                    "(edges included: at an edge or corner 2-3 faces push)")


def _box_face(scene, contact, box_side, face_side, settings) -> PairPlan:
    (box_body, box), (face_body, face) = box_side, face_side
    rho = settings.corner_sphere_radius * min(box.half_extents)
    h = np.asarray(box.half_extents, dtype=float)
    corners = _to_body(box, [[sx * h[0], sy * h[1], sz * h[2]] for sx in (-1, 1)
                             for sy in (-1, 1) for sz in (-1, 1)])
    triangles, edges, how = _face_triangles(scene, face_body, face, contact.offset - rho,
                                            settings)
    connectors = _spheres_against_faces(contact, box_body, corners, rho, face_body, triangles,
                                        edges)
    return PairPlan(contact, connectors, f"8 corner spheres (radius {rho:.3g}) against {how} "
                    "moved back by the radius (exact corner heights)")


def _ring_face(scene, contact, ring_side, face_side, settings) -> PairPlan:
    (ring_body, ring), (face_body, face) = ring_side, face_side
    depth = getattr(face, "depth", None)
    room = depth if depth is not None else 0.0
    rho = ring_sphere_radius(ring, room, settings)
    centres = _to_body(ring, ring_points(ring, settings))
    triangles, edges, how = _face_triangles(scene, face_body, face, contact.offset - rho,
                                            settings)
    plan = PairPlan(contact, _spheres_against_faces(contact, ring_body, centres, rho, face_body,
                                                    triangles, edges),
                    f"{len(centres)} spheres (radius {rho:.3g}) on the {ring.kind} against "
                    f"{how} moved back by the radius")
    plan.shape_error = plan.overlap = ring_chord_error(ring.radius, settings.ring_spheres)
    return plan


def _cylinder_face(scene, contact, cylinder_side, face_side, settings) -> PairPlan:
    (cylinder_body, cylinder), (face_body, face) = cylinder_side, face_side
    ends = _to_body(cylinder, [[0.0, 0.0, -cylinder.half_length],
                               [0.0, 0.0, cylinder.half_length]])
    triangles, edges, how = _face_triangles(scene, face_body, face, contact.offset, settings)
    return PairPlan(contact, _spheres_against_faces(contact, cylinder_body, ends,
                                                    cylinder.radius, face_body, triangles,
                                                    edges),
                    f"2 spheres of the cylinder's radius at its axis ends against {how} (exact "
                    "for the axis parallel to the face; rims rounded otherwise)")


def _is_internal(scene, ring_body, ring, cylinder_body, cylinder) -> bool:
    """True when the cylinder's axis passes inside the ring at t = 0 (a journal in a ring)."""
    centre = _world(scene, ring_body, _to_body(ring, [0.0, 0.0, 0.0]))
    normal = _world(scene, ring_body, _to_body(ring, [0.0, 0.0, 1.0])) - centre
    origin = _world(scene, cylinder_body, _to_body(cylinder, [0.0, 0.0, 0.0]))
    axis = _world(scene, cylinder_body, _to_body(cylinder, [0.0, 0.0, 1.0])) - origin
    along = float(axis @ normal)
    if abs(along) < 1e-9:
        return False
    hit = origin + axis * float((centre - origin) @ normal) / along
    return float(np.linalg.norm(hit - centre)) < ring.radius


def _in_plane(scene, contact, ring_side, partner_side, settings, hollow: bool) -> PairPlan:
    """Ring spheres, each against a sphere centred on the partner's axis at the ring sphere's
    axial level (t = 0, fixed in the partner): the distance to the axis exactly while the
    motion stays in the plane normal to the axis (planar mechanisms); an axial offset dz adds
    dz^2 / (2 R). A cylinder is a solid sphere, a bore a hollow one (its angles and length
    are not bounded)."""
    (ring_body, ring), (partner_body, partner) = ring_side, partner_side
    origin = _world(scene, partner_body, _to_body(partner, [0.0, 0.0, 0.0]))
    axis = _world(scene, partner_body, _to_body(partner, [0.0, 0.0, 1.0])) - origin
    if hollow:
        rho = ring_sphere_radius(ring, 0.0, settings)
        partner_radius = partner.radius - contact.offset + rho
    else:
        room = partner.radius + contact.offset
        if not room > 0:
            raise UnsupportedPair(f"offset {contact.offset} exceeds the cylinder radius")
        rho = ring_sphere_radius(ring, 0.5 * room / 0.9, settings)
        partner_radius = room - rho
    connectors = []
    for centre in _to_body(ring, ring_points(ring, settings)):
        world = _world(scene, ring_body, centre)
        foot = origin + axis * float((world - origin) @ axis)
        connectors.append(ConnectorPlan(
            "sphere_sphere", ring_body, _t(centre), rho, partner_body,
            _t(_local(scene, partner_body, foot)), partner_radius, hollow=hollow,
            sphere_is_b=ring_body == contact.body_b))
    what = "inside a hollow sphere of the bore's radius" if hollow else \
        "against a sphere of the cylinder's radius"
    plan = PairPlan(contact, connectors,
                    f"{len(connectors)} spheres (radius {rho:.3g}) on the {ring.kind}, each "
                    f"{what} on the axis at its level (exact for motion normal to the axis)")
    plan.shape_error = plan.overlap = ring_chord_error(ring.radius, settings.ring_spheres)
    return plan


def _ring_cylinder(scene, contact, ring_side, cylinder_side, settings) -> PairPlan:
    (ring_body, ring), (cylinder_body, cylinder) = ring_side, cylinder_side
    internal = _is_internal(scene, ring_body, ring, cylinder_body, cylinder)
    if internal and isinstance(ring, Circle) and settings.ring_journal == "hollow_sphere":
        centre_world = _world(scene, ring_body, _to_body(ring, [0.0, 0.0, 0.0]))
        # The journal's axis point nearest the ring centre at t = 0, fixed in the journal.
        origin = _world(scene, cylinder_body, _to_body(cylinder, [0.0, 0.0, 0.0]))
        axis = _world(scene, cylinder_body, _to_body(cylinder, [0.0, 0.0, 1.0])) - origin
        foot = origin + axis * float((centre_world - origin) @ axis)
        journal_radius = cylinder.radius + contact.offset
        if not 0 < journal_radius < ring.radius:
            raise UnsupportedPair(f"journal radius + offset {journal_radius:.6g} is not inside "
                                  f"the ring radius {ring.radius:.6g}")
        plan = ConnectorPlan("sphere_sphere", cylinder_body,
                             _t(_local(scene, cylinder_body, foot)), journal_radius, ring_body,
                             _t(_to_body(ring, [0.0, 0.0, 0.0])), ring.radius, hollow=True,
                             sphere_is_b=cylinder_body == contact.body_b)
        return PairPlan(contact, [plan], "journal sphere (its radius + offset) on the axis "
                        "inside a hollow sphere of the ring's radius: exact in the ring's "
                        "plane; an axial offset dz adds dz^2/(2c) near contact")
    if settings.ring_journal != "facets":
        return _in_plane(scene, contact, ring_side, cylinder_side, settings, hollow=False)
    room = cylinder.radius + contact.offset
    rho = ring_sphere_radius(ring, room, settings)
    apothem = room - rho
    facets = _prism_triangles(cylinder, apothem, cylinder.half_length + ring.radius,
                              settings.journal_facets, 0.0, 2.0 * math.pi)
    centres = _to_body(ring, ring_points(ring, settings))
    connectors = []
    # Facet angle in the cylinder frame that faces each ring sphere at t = 0.
    cylinder_position, cylinder_rotation = _shape_frame(cylinder)
    for centre in centres:
        in_cylinder = _local(scene, cylinder_body, _world(scene, ring_body, centre))
        local = (in_cylinder - cylinder_position) @ cylinder_rotation
        facing = math.atan2(local[1], local[0])
        for triangle, edges, angle in facets:
            if _angle_difference(angle, facing) <= settings.facet_window + 1e-12:
                connectors.append(ConnectorPlan(
                    "sphere_triangle", ring_body, _t(centre), rho, cylinder_body,
                    triangle=triangle, include_edges=edges,
                    sphere_is_b=ring_body == contact.body_b))
    plan = PairPlan(contact, connectors,
                    f"{len(centres)} spheres (radius {rho:.3g}) on the {ring.kind} against the "
                    f"cylinder as a prism of {settings.journal_facets} facets per circle "
                    f"(within {math.degrees(settings.facet_window):.0f} deg of each sphere), "
                    + ("internal" if internal else "external"))
    plan.overlap = ring_chord_error(ring.radius, settings.ring_spheres)
    plan.shape_error = facet_error(apothem + rho, settings.journal_facets) + plan.overlap
    return plan


def _bore_facets(bore: Bore, apothem: float, settings: ExudynSettings):
    return _prism_triangles(bore, apothem, bore.half_length, settings.journal_facets,
                            bore.start_angle, bore.end_angle)


def _ring_bore(scene, contact, ring_side, bore_side, settings) -> PairPlan:
    (ring_body, ring), (bore_body, bore) = ring_side, bore_side
    full = bore.end_angle - bore.start_angle >= 2.0 * math.pi - 1e-12
    if settings.ring_journal != "facets" and full:
        return _in_plane(scene, contact, ring_side, bore_side, settings, hollow=True)
    # A bore patch (a concave CAD face) is bounded by its angles: a hollow sphere would hold
    # ring points that left the patch, so it gets facets over its angles.
    rho = ring_sphere_radius(ring, 0.0, settings)
    facets = _bore_facets(bore, bore.radius + rho - contact.offset, settings)
    centres = _to_body(ring, ring_points(ring, settings))
    bore_position, bore_rotation = _shape_frame(bore)
    connectors = []
    for centre in centres:
        local = (_local(scene, bore_body, _world(scene, ring_body, centre)) - bore_position) \
            @ bore_rotation
        facing = math.atan2(local[1], local[0])
        for triangle, edges, angle in facets:
            if _angle_difference(angle, facing) <= settings.facet_window + 1e-12:
                connectors.append(ConnectorPlan(
                    "sphere_triangle", ring_body, _t(centre), rho, bore_body,
                    triangle=triangle, include_edges=edges,
                    sphere_is_b=ring_body == contact.body_b))
    plan = PairPlan(contact, connectors,
                    f"{len(centres)} spheres (radius {rho:.3g}) on the {ring.kind} against the "
                    f"bore's lining of {settings.journal_facets} facets per circle")
    plan.shape_error = plan.overlap = facet_error(bore.radius, settings.journal_facets)
    return plan


def _cylinder_bore(scene, contact, cylinder_side, bore_side, settings) -> PairPlan:
    (cylinder_body, cylinder), (bore_body, bore) = cylinder_side, bore_side
    radius = cylinder.radius + contact.offset
    z = np.linspace(-cylinder.half_length, cylinder.half_length, settings.journal_spheres)
    centres = _to_body(cylinder, np.column_stack([0 * z, 0 * z, z]))
    facets = _bore_facets(bore, bore.radius, settings)
    connectors = [ConnectorPlan("sphere_triangle", cylinder_body, _t(c), radius, bore_body,
                                triangle=triangle, include_edges=edges,
                                sphere_is_b=cylinder_body == contact.body_b)
                  for c in centres for triangle, edges, _ in facets]
    plan = PairPlan(contact, connectors,
                    f"{len(centres)} spheres of the journal's radius along its axis against "
                    f"the bore's lining of {settings.journal_facets} facets per circle")
    plan.shape_error = plan.overlap = facet_error(bore.radius, settings.journal_facets)
    return plan


#: (kind of side 1, kind of side 2) -> handler(scene, contact, side1, side2, settings)
HANDLERS = {
    **{("sphere", face): _sphere_face for face in FACE_KINDS},
    ("sphere", "box"): _sphere_box,
    **{("box", face): _box_face for face in FACE_KINDS},
    **{(ring, face): _ring_face for ring in RING_KINDS for face in FACE_KINDS},
    **{("cylinder", face): _cylinder_face for face in FACE_KINDS},
    **{(ring, "cylinder"): _ring_cylinder for ring in RING_KINDS},
    **{(ring, "bore"): _ring_bore for ring in RING_KINDS},
    ("cylinder", "bore"): _cylinder_bore,
}

#: Why the other pairs have no connector.
NO_CONNECTOR = {
    ("box", "box"): "Exudyn has no box-box connector (corner spheres against the other box's "
                    "faces would miss edge-edge contact)",
    ("cylinder", "sphere"): "Exudyn has no sphere-cylinder connector",
    ("cylinder", "cylinder"): "Exudyn has no cylinder-cylinder connector",
    ("box", "cylinder"): "Exudyn has no box-cylinder connector",
}


def pair_problem(kind_a: str, kind_b: str) -> str | None:
    """Why a pair of shape kinds cannot be rebuilt (None when it can)."""
    if (kind_a, kind_b) in HANDLERS or (kind_b, kind_a) in HANDLERS:
        return None
    if kind_a == kind_b == "sphere":
        return None
    key = tuple(sorted((kind_a, kind_b)))
    if "capsule" in key:
        return "capsules are not mapped by the Exudyn prototype (no capsule connector)"
    return NO_CONNECTOR.get(key, f"Exudyn has no connector for {key[0]}-{key[1]}")


def plan_pair(scene: Scene, contact: ContactPair, settings: ExudynSettings) -> PairPlan:
    """Connectors of one (expanded) scene pair; UnsupportedPair when Exudyn has none."""
    expanded = scene.expanded
    a = (contact.body_a, expanded.body(contact.body_a).shape(contact.shape_a))
    b = (contact.body_b, expanded.body(contact.body_b).shape(contact.shape_b))
    if a[1].kind == b[1].kind == "sphere":
        return _sphere_sphere(scene, contact, a[1], b[1], settings)
    if (a[1].kind, b[1].kind) in HANDLERS:
        return HANDLERS[(a[1].kind, b[1].kind)](scene, contact, a, b, settings)
    if (b[1].kind, a[1].kind) in HANDLERS:
        return HANDLERS[(b[1].kind, a[1].kind)](scene, contact, b, a, settings)
    raise UnsupportedPair(pair_problem(a[1].kind, b[1].kind))


def plan_contacts(scene: Scene, settings: ExudynSettings) -> list[PairPlan]:
    """Connector plans of every pair of ``scene.all_contacts`` (UnsupportedPair on the
    first pair that has none)."""
    return [plan_pair(scene, contact, settings) for contact in scene.all_contacts]


def reduced_mass(scene: Scene, contact: ContactPair) -> float:
    """Reduced mass of a pair's bodies [M] (a fixed body counts as infinitely heavy)."""
    masses = [scene.body(name).mass for name in (contact.body_a, contact.body_b)
              if scene.body(name).motion is not Motion.FIXED]
    if len(masses) == 1:
        return masses[0]
    return masses[0] * masses[1] / (masses[0] + masses[1])
