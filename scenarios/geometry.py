"""Contact geometry shared by the reference solver, every engine adapter and the metrics.

Pure functions on shape kinds, packed parameters and world placements: no scene dataclass is
needed by the compiled kernels, so ``ref_solver`` may import this module.

Conventions (kept exactly by every pair)
----------------------------------------
- For a pair (shape A on body A, shape B on body B), the normal ``n`` is the unit vector
  pointing FROM A TOWARD B. ``p_A`` is the contact point on A's surface, ``p_B`` on B's surface
  (world coordinates), and the signed gap is ``g = (p_B - p_A) . n``: ``g > 0`` separated,
  ``g = 0`` touching, ``g < 0`` penetrating (then ``-g`` is the penetration depth). Every kernel
  returns ``p_B - p_A = g n`` (to round-off).
- Where ``p_B`` is the closest point of B to a material point of A (or the reverse), the gap
  is a signed distance whose gradient with respect to a translation of B is ``n`` and with
  respect to a translation of A is ``-n``. This holds for every pair except box-box points
  created by clipping, and a bare ring's deepest point inside a face's solid where two of its
  faces are equally near (see below).
- Swapping A and B gives the same gaps, swapped points and the opposite normals (exactly: the
  kernels run one canonical order and mirror it; same-kind pairs pick their order from the
  data, not from the argument order).
- Contact frame: rows ``(n, t1, t2)``, right-handed orthonormal (``t1 x t2 = n``), a function
  of ``n`` alone (:func:`contact_frame`). It is smooth everywhere except at the single normal
  direction :data:`FRAME_SINGULAR_DIRECTION` = -(2, 3, 6)/7, where it is still defined and
  orthonormal (see :mod:`clearbench.kernels.frames`).
- Offsets: the scene's contact offset is NOT applied here; callers subtract it from the gap.
- Candidates: pairs with several candidate points (box corners, cylinder rims) return all of
  them with their gaps, including separated ones; the caller keeps those below its activation
  threshold.
- Units: lengths in the scene's unit, angles in rad, everything float64.

Pairs (both orders of each are supported; K = number of candidates returned)
---------------------------------------------------------------------------
================  ===  ==========================================================================
sphere-plane       1   centre height minus radius.
sphere-sphere      1   centre distance minus radii (concentric: n = +z).
sphere-box         1   closest point of the solid box; centre inside: nearest face.
sphere-capsule     1   closest point of the axis segment.
sphere-cylinder    1   closest point of the SOLID finite cylinder (lateral surface and flat ends).
box-plane          8   every corner with its height above the plane.
box-box           1-8  separating-axis test over the 6 face axes and 9 edge-edge axes picks the
                       contact feature (faces preferred on near-ties). Face: the incident face of
                       the other box (most opposed to the reference face normal) is clipped
                       against the reference face rectangle (Sutherland-Hodgman); each clipped
                       vertex is a candidate with its depth along the reference normal. Edge-edge:
                       one contact at the closest points of the two supporting edges (separated:
                       their distance; penetrating: the depth along the axis). Limits:
                       clipped (non-corner) points are not closest points, so their gap
                       derivative is not exactly the normal when the faces are not parallel; a
                       face whose rectangle does not overlap the incident face's projection gives
                       0 candidates (boxes side by side diagonally); deep penetrations (more than
                       about half a box) can pick a wrong feature. Good for resting stacks,
                       sliding and tipping boxes; not a general polyhedron test.
capsule-plane      2   the two end spheres.
capsule-capsule   1-2  closest points of the axes; exactly parallel axes (|a x b| < 1e-6): the two
                       ends of the overlap (a line contact needs two points).
cylinder-plane     8   on each end rim: the lowest point and the points 90, 180, 270 degrees round
                       (indices 0 and 1 are the two lowest rim points, the support of a lying
                       cylinder; a standing cylinder gets 4 points on its bottom rim). The lowest
                       point of the solid is always one of indices 0, 1. Rim parallel to the
                       plane: the rim points start from the cylinder's own x axis.
circle-plane       8   a ring against a face's solid (below, with rectangle-X and disc-X).
arc-plane          8
circle-cylinder    1   bearing ring against a journal, or ring against a pin (below).
arc-cylinder       1   the same, restricted to the arc's angles (else the better arc end).
rectangle-X       1-8  X = sphere (1), cylinder (8), circle (8), arc (8). A face has a solid
disc-X                 behind it: the slab |x| <= half_x, |y| <= half_y (or x^2 + y^2 <= r^2),
                       -depth <= z <= 0 (no depth: unbounded below); a plane's is z <= 0. Every
                       candidate's gap is its signed distance to that solid: over the face the
                       plane's gap and normal, beyond the bound the distance to the face's edge
                       (or corner) along the direction from it, behind a slab its back face; so
                       gap and normal are continuous while a partner crosses the bound. A
                       sphere: its centre's distance minus its radius. A cylinder: its 8 rim
                       points of cylinder-plane (chosen with respect to the face's normal); its
                       lateral surface across the face's edge is NOT a candidate. A ring or arc
                       (kernels/gaps/ring_faces.py): slots 0-5 six support points (a circle's
                       60 degrees apart from the face's x axis in the ring's plane, whatever the
                       ring's own x axis; an arc's spread over it, ends included), slots 6-7 the
                       two lowest local minima over the ring angle of its distance to the
                       solid (its lowest point over the face, its nearest point to the edge
                       beyond it, the two crossings of a ring lying across the edge), found on
                       24 samples per turn and refined by Brent's method to 1e-9 rad; a slot
                       without a minimum takes the ring's highest sample that is not a support
                       point. Inside the solid a bare ring's deepest point takes the normal of
                       the nearest face (no gradient where two are equally near); a contact
                       offset d makes the gap that of the tube of radius d about the ring, whose
                       normal stays continuous while the penetration is below d.
circle-bore       0-1  ring INSIDE a bore: g = R_bore - (largest distance of a ring point from
arc-bore               the bore axis), n radially outward from that ring point (parallel axes at
                       eccentricity e: g = R_bore - R_ring - e). Kept only if the point on the
                       bore lies in its angles and |z| <= half_length (a concave CAD patch),
                       and its gap is not below -depth (behind the solid, as for faces).
cylinder-bore     0-2  journal INSIDE a bore: one candidate at each end of the axial overlap
                       (the radial gap is concave along the axis, so these are its minima): the
                       journal's end rim when it is inside the bore, else the bore's end rim
                       against the journal's lateral surface. No overlap: none.
================  ===  ==========================================================================

Ring (circle or arc) against cylinder. The cylinder is the journal: its lateral surface is
taken as INFINITELY LONG (the half_length is ignored; axial motion is limited by the flange
contacts of the clearance joint, and ``point_b`` may lie beyond the journal's ends). The gap is
the signed distance from the ring point nearest the cylinder axis to the lateral surface:
``g = min_theta dist(c(theta), axis) - R_cyl``, with ``n`` perpendicular to the axis, from the
ring point toward the axis. The one formula covers both cases:

- INTERNAL (the axis passes inside the ring: a journal in the bore). With parallel axes at
  eccentricity ``e``: ``g = R_ring - R_cyl - e`` exactly (the radial clearance minus the
  eccentricity); the contact is on the side toward which the journal is displaced.
- EXTERNAL (the axis outside the ring: a ring against a pin): ``g = e - R_ring - R_cyl`` for
  parallel axes.

Tilted axes (3D, any tilt; accurate to round-off, tested against dense sampling up to 10
degrees and beyond): the squared axis distance of the ring point is a trigonometric polynomial
of degree 2 in the ring angle. The parallel-axis closed form (the angle of the projected
eccentricity) is polished by bracketed Newton steps whenever the tilt term is small against the
eccentricity term (then the minimum is unique and the function convex around it); otherwise
(small eccentricity, large tilt: two minima possible) all stationary angles are found from a
quartic and the best one kept. The gap is meaningful for penetrations smaller than the journal
radius.

Python side
-----------
:func:`contacts_between` takes ``scenarios.shapes`` objects and body poses and returns a
:class:`PairContacts`. :func:`pack_shape_parameters`, :func:`shape_code` and
:func:`supported_pair` / :func:`check_supported_pair` prepare calls of the compiled
:func:`pair_contacts` from other compiled code.

Compiled callers
----------------
``pair_contacts(kind_a, params_a, position_a, rotation_a, kind_b, params_b, position_b,
rotation_b, out_gap, out_point_a, out_point_b, out_frame) -> count`` is ``njit(inline=
"always")`` (a thin wrapper that turns its inputs into tuples, so the kernels below it run
without reference counting). Outputs have K >= MAX_CONTACTS_PER_PAIR rows; ``out_point_a`` and
``out_point_b`` are also used as work space, so pass distinct arrays. Rotations must be
orthonormal to round-off (as :func:`quat_to_matrix` gives). An unsupported pair raises
ValueError inside compiled code too; check :func:`supported_pair` when building the pair list.
numba's on-disk cache does not notice edits in modules a cached function calls: after editing
these kernels, clear the ``__pycache__`` numba files (``*.nbi``, ``*.nbc``) of the callers.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from clearbench.kernels.frames import (
    FRAME_POLE,
    FRAME_SINGULAR_DIRECTION,
    contact_frame,
    contact_frames_batch,
    frame_tangent,
    write_contact_frame,
)
from clearbench.kernels.gaps import (
    ARC,
    BORE,
    BOX,
    CAPSULE,
    CIRCLE,
    CYLINDER,
    DISC,
    MAX_CONTACTS_PER_PAIR,
    PARAMETER_COUNT,
    PLANE,
    RECTANGLE,
    SHAPE_KIND_NAMES,
    SPHERE,
    SUPPORTED,
    axis_crosses_inside_ring,
    enclosing_ring_gap,
    pair_contacts,
)
from clearbench.kernels.quaternion import (
    quat_multiply,
    quat_multiply_batch,
    quat_normalize,
    quat_normalize_batch,
    quat_to_matrix,
    quat_to_matrix_batch,
)

if TYPE_CHECKING:  # the kernels and this module never need the scene dataclasses at run time
    from clearbench.scenarios.shapes import Shape

__all__ = [
    "ARC",
    "BORE",
    "BOX",
    "CAPSULE",
    "CIRCLE",
    "CYLINDER",
    "DISC",
    "FRAME_POLE",
    "FRAME_SINGULAR_DIRECTION",
    "MAX_CONTACTS_PER_PAIR",
    "PARAMETER_COUNT",
    "PLANE",
    "RECTANGLE",
    "SHAPE_CODES",
    "SPHERE",
    "PairContacts",
    "UnsupportedPairError",
    "check_supported_pair",
    "contact_frame",
    "contact_frames_batch",
    "contacts_between",
    "enclosing_ring_gap",
    "ring_encloses_axis",
    "shape_world_placements",
    "smallest_gaps",
    "frame_tangent",
    "kind_name",
    "pack_shape_parameters",
    "pair_contacts",
    "shape_code",
    "shape_world_placement",
    "supported_pair",
    "write_contact_frame",
]

#: Shape code of every ``Shape.kind`` string.
SHAPE_CODES: dict[str, int] = {name: code for code, name in enumerate(SHAPE_KIND_NAMES)}


#: Fields of each shape kind, in packed order (see :func:`pack_shape_parameters`).
_PACKED_FIELDS: dict[str, tuple[str, ...]] = {
    "sphere": ("radius",),
    "box": ("half_extents",),
    "capsule": ("radius", "half_length"),
    "cylinder": ("radius", "half_length"),
    "plane": (),
    "circle": ("radius",),
    "arc": ("radius", "start_angle", "end_angle"),
    "rectangle": ("half_extents", "depth"),
    "disc": ("radius", "depth"),
    "bore": ("radius", "half_length", "start_angle", "end_angle", "depth"),
}


class UnsupportedPairError(ValueError):
    """No contact kernel exists for this pair of shape kinds."""

    def __init__(self, kind_a: str, kind_b: str):
        self.kind_a = kind_a
        self.kind_b = kind_b
        supported = ", ".join(
            f"{SHAPE_KIND_NAMES[a]}-{SHAPE_KIND_NAMES[b]}"
            for a in range(len(SHAPE_KIND_NAMES))
            for b in range(a, len(SHAPE_KIND_NAMES))
            if SUPPORTED[a, b]
        )
        super().__init__(
            f"no contact geometry for the pair {kind_a}-{kind_b} (shape A is a {kind_a}, "
            f"shape B is a {kind_b}); supported pairs, in either order: {supported}"
        )


def _code(kind: int | str | Shape) -> int:
    if not isinstance(kind, str | int | np.integer):
        kind = kind.kind  # a scenarios.shapes object
    if isinstance(kind, str):
        if kind not in SHAPE_CODES:
            raise ValueError(f"unknown shape kind {kind!r}; known: {', '.join(SHAPE_CODES)}")
        return SHAPE_CODES[kind]
    code = int(kind)
    if not 0 <= code < len(SHAPE_KIND_NAMES):
        raise ValueError(f"unknown shape code {kind!r}; codes are 0..{len(SHAPE_KIND_NAMES) - 1}")
    return code


def shape_code(shape: int | str | Shape) -> int:
    """Shape code (SPHERE, BOX, ...) of a shape object, a kind string or a code."""
    return _code(shape)


def kind_name(shape: int | str | Shape) -> str:
    """Kind string ('sphere', 'box', ...) of a shape object, a kind string or a code."""
    return SHAPE_KIND_NAMES[_code(shape)]


def supported_pair(kind_a: int | str | Shape, kind_b: int | str | Shape) -> bool:
    """True if :func:`pair_contacts` handles shape A of ``kind_a`` against B of ``kind_b``."""
    return bool(SUPPORTED[_code(kind_a), _code(kind_b)])


def check_supported_pair(kind_a: int | str | Shape, kind_b: int | str | Shape) -> None:
    """Raise :class:`UnsupportedPairError` (a ValueError naming both kinds) if unsupported."""
    if not supported_pair(kind_a, kind_b):
        raise UnsupportedPairError(kind_name(kind_a), kind_name(kind_b))


def pack_shape_parameters(shape: Shape) -> np.ndarray:
    """Parameters of ``shape`` as the (PARAMETER_COUNT,) float64 vector the kernels read.

    ========  ============================================
    sphere    [radius]
    box       [half_x, half_y, half_z]
    capsule   [radius, half_length]
    cylinder  [radius, half_length]
    plane     []
    circle    [radius]
    arc       [radius, start_angle, end_angle] (rad)
    rectangle [half_x, half_y, depth] (depth 0: unbounded)
    disc      [radius, depth] (depth 0: unbounded)
    bore      [radius, half_length, start_angle, end_angle, depth] (rad; depth 0: unbounded)
    ========  ============================================

    Unused entries are 0. Lengths in the scene's unit.
    """
    kind = getattr(shape, "kind", None)
    if kind not in _PACKED_FIELDS:
        raise ValueError(f"no packed form for shape {shape!r} of kind {kind!r}")
    values: list[float] = []
    for name in _PACKED_FIELDS[kind]:
        value = getattr(shape, name)
        if value is None:  # an optional bound (a face's depth, > 0 when given): 0 = unbounded
            value = 0.0
        values.extend(value if isinstance(value, tuple | list) else (value,))
    packed = np.zeros(PARAMETER_COUNT)
    packed[: len(values)] = values
    return packed


def shape_world_placement(
    shape: Shape, body_position, body_quaternion
) -> tuple[np.ndarray, np.ndarray]:
    """World placement of a shape's own frame from its body's pose.

    Parameters
    ----------
    shape : Shape
        Shape with its placement (``position``, ``orientation``) in the body frame.
    body_position : array_like (3,)
        World position of the body frame origin (length).
    body_quaternion : array_like (4,)
        World orientation of the body frame, unit quaternion (w, x, y, z).

    Returns
    -------
    position : ndarray (3,)
        World position of the shape frame origin.
    rotation : ndarray (3, 3)
        World rotation of the shape frame (columns = shape axes in world).
    """
    body_position = np.asarray(body_position, dtype=np.float64)
    body_quaternion = quat_normalize(np.asarray(body_quaternion, dtype=np.float64))
    body_rotation = quat_to_matrix(body_quaternion)
    position = body_position + body_rotation @ np.asarray(shape.position, dtype=np.float64)
    orientation = quat_normalize(
        quat_multiply(body_quaternion, np.asarray(shape.orientation, dtype=np.float64))
    )
    return position, quat_to_matrix(orientation)


def shape_world_placements(shape: Shape, body_positions, body_quaternions
                           ) -> tuple[np.ndarray, np.ndarray]:
    """:func:`shape_world_placement` at T body poses at once: ``body_positions`` (T, 3) [L],
    ``body_quaternions`` (T, 4) -> shape positions (T, 3) [L], rotations (T, 3, 3). The same
    arithmetic, vectorised (equal to round-off, not bit for bit)."""
    quaternions = quat_normalize_batch(np.asarray(body_quaternions, dtype=np.float64))
    rotations = quat_to_matrix_batch(quaternions)
    offset = np.asarray(shape.position, dtype=np.float64)
    positions = np.asarray(body_positions, dtype=np.float64) + np.einsum(
        "tij,j->ti", rotations, offset)
    orientations = quat_normalize_batch(
        quat_multiply_batch(quaternions, np.asarray(shape.orientation, dtype=np.float64)))
    return positions, np.ascontiguousarray(quat_to_matrix_batch(orientations))


def smallest_gaps(shape_a: Shape, poses_a, shape_b: Shape, poses_b,
                  encloses: bool = False) -> np.ndarray:
    """Smallest candidate gap of a pair at each of T configurations, (T,) [L]; +inf where the
    pair yields no candidate. ``poses_a``, ``poses_b``: (positions (T, 3), quaternions (T, 4))
    of the two BODY frames. The gap is min(:func:`contacts_between`(...).gap) at each
    configuration, with the shapes' placements computed for all T at once and one kernel call
    per configuration (the cost of measuring a long trajectory).

    A ring that must enclose its journal (``encloses``: a ring against a cylinder) counts a
    journal beyond the ring as through its wall (:func:`enclosing_ring_gap` with
    :func:`ring_encloses_axis`'s test): the gap keeps decreasing with the distance instead of
    turning positive again.
    """
    check_supported_pair(shape_a, shape_b)
    position_a, rotation_a = shape_world_placements(shape_a, *poses_a)
    position_b, rotation_b = shape_world_placements(shape_b, *poses_b)
    code_a, code_b = shape_code(shape_a), shape_code(shape_b)
    params_a, params_b = pack_shape_parameters(shape_a), pack_shape_parameters(shape_b)
    gap = np.empty(MAX_CONTACTS_PER_PAIR)
    point_a = np.empty((MAX_CONTACTS_PER_PAIR, 3))
    point_b = np.empty((MAX_CONTACTS_PER_PAIR, 3))
    frame = np.empty((MAX_CONTACTS_PER_PAIR, 3, 3))
    out = np.full(len(position_a), np.inf)
    for t in range(len(out)):
        count = pair_contacts(code_a, params_a, position_a[t], rotation_a[t], code_b, params_b,
                              position_b[t], rotation_b[t], gap, point_a, point_b, frame)
        if count:
            out[t] = gap[:count].min()
    if encloses:
        placed_a = (shape_a, position_a, rotation_a)
        placed_b = (shape_b, position_b, rotation_b)
        (ring, ring_position, ring_rotation), (cylinder, axis_point, axis_rotation) = (
            (placed_a, placed_b) if shape_b.kind == "cylinder" else (placed_b, placed_a))
        for t in np.nonzero(np.isfinite(out))[0]:
            inside = _axis_inside_ring(ring, ring_position[t], ring_rotation[t], axis_point[t],
                                       axis_rotation[t])
            out[t] = enclosing_ring_gap(out[t], cylinder.radius, inside)
    return out


@dataclass(frozen=True)
class PairContacts:
    """Candidate contacts of one pair (k of them, 0 <= k <= MAX_CONTACTS_PER_PAIR).

    Attributes
    ----------
    gap : ndarray (k,)
        Signed gaps (length), before any contact offset.
    point_a, point_b : ndarray (k, 3)
        Contact points on A's and on B's surface, world coordinates.
    frame : ndarray (k, 3, 3)
        Contact frames, rows (n, t1, t2); n points from A toward B.
    """

    gap: np.ndarray
    point_a: np.ndarray
    point_b: np.ndarray
    frame: np.ndarray

    @property
    def normal(self) -> np.ndarray:
        """Normals (k, 3), from A toward B."""
        return self.frame[:, 0, :]

    @property
    def count(self) -> int:
        return int(self.gap.shape[0])

    def __len__(self) -> int:
        return self.count


def contacts_between(shape_a: Shape, pose_a, shape_b: Shape, pose_b) -> PairContacts:
    """Candidate contacts between two shapes on posed bodies.

    Parameters
    ----------
    shape_a, shape_b : Shape
        ``scenarios.shapes`` objects, placed in their bodies' frames.
    pose_a, pose_b : tuple (position (3,), quaternion (4,))
        World pose of each BODY frame (length; unit quaternion w, x, y, z).

    Returns
    -------
    PairContacts
        Read-only arrays (k,), (k, 3), (k, 3, 3).

    Raises
    ------
    UnsupportedPairError
        If no kernel handles the two kinds (a ValueError naming both).
    """
    check_supported_pair(shape_a, shape_b)
    position_a, rotation_a = shape_world_placement(shape_a, *pose_a)
    position_b, rotation_b = shape_world_placement(shape_b, *pose_b)
    gap = np.empty(MAX_CONTACTS_PER_PAIR)
    point_a = np.empty((MAX_CONTACTS_PER_PAIR, 3))
    point_b = np.empty((MAX_CONTACTS_PER_PAIR, 3))
    frame = np.empty((MAX_CONTACTS_PER_PAIR, 3, 3))
    count = pair_contacts(
        shape_code(shape_a),
        pack_shape_parameters(shape_a),
        position_a,
        rotation_a,
        shape_code(shape_b),
        pack_shape_parameters(shape_b),
        position_b,
        rotation_b,
        gap,
        point_a,
        point_b,
        frame,
    )
    arrays = [gap[:count].copy(), point_a[:count].copy(), point_b[:count].copy()]
    arrays.append(frame[:count].copy())
    for array in arrays:
        array.setflags(write=False)
    return PairContacts(*arrays)


def ring_encloses_axis(shape_a: Shape, pose_a, shape_b: Shape, pose_b) -> bool | None:
    """For a ring (circle or arc) against a cylinder, in either order: True when the cylinder's
    axis crosses the ring's plane inside the ring (a journal in its bore:
    :func:`~clearbench.kernels.gaps.axis_crosses_inside_ring`), False when outside; None for
    any other pair. Poses as in :func:`contacts_between`."""
    kinds = {shape_a.kind, shape_b.kind}
    if "cylinder" not in kinds or not kinds & {"circle", "arc"}:
        return None
    (ring, ring_pose), (cylinder, cylinder_pose) = sorted(
        ((shape_a, pose_a), (shape_b, pose_b)), key=lambda item: item[0].kind == "cylinder")
    ring_position, ring_rotation = shape_world_placement(ring, *ring_pose)
    axis_point, axis_rotation = shape_world_placement(cylinder, *cylinder_pose)
    return _axis_inside_ring(ring, ring_position, ring_rotation, axis_point, axis_rotation)


def _axis_inside_ring(ring: Shape, ring_position, ring_rotation, axis_point,
                      axis_rotation) -> bool:
    """:func:`~clearbench.kernels.gaps.axis_crosses_inside_ring` for a placed ring (circle or
    arc) and a placed cylinder's frame (its axis the frame's z): world positions (3,) [L],
    rotations (3, 3)."""
    start, span = 0.0, 2.0 * np.pi
    if ring.kind == "arc":
        start, span = ring.start_angle, ring.end_angle - ring.start_angle
    return axis_crosses_inside_ring(ring_position, ring_rotation, ring.radius, start, span,
                                    axis_point, axis_rotation[:, 2])
