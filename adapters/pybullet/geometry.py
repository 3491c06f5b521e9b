"""Scene shapes as PyBullet collision pieces, one set per side of each contact pair.

PyBullet filters collisions per collision object (a link or a rigid body), not per shape, and
combines friction and restitution as products of the two objects' values. So every SIDE of every
contact pair gets collision objects of its own (A's carry the pair's mu and e, B's carry 1 and
1), and side A's geometry carries the pair's offset (the scene takes the offset on A's side):

the pieces of each shape: :mod:`clearbench.adapters.primitive_pieces` (shared with the Drake
adapter; re-exported here). PyBullet's ``height`` of a capsule is 2 half_length (between the
centres), of a cylinder its full length (its end caps collide too); a plane on a fixed body is a
GEOM_PLANE.

Box, cylinder and plane pieces have a collision margin (0.001 m by PyBullet's default) that can
be changed only on a shape created without a child transform, so each of them becomes a
collision object of its own whose frame is the piece's frame. Spheres and capsules have their
radius as margin; rings and bores (spheres, capsules) go in compounds of at most 16 children
(:data:`~.settings.MAX_COMPOUND_CHILDREN`; :func:`check_compound` guards it). Pure Python.
"""

from __future__ import annotations

from clearbench.adapters.primitive_pieces import (  # noqa: F401  (re-exported)
    Piece,
    SideGeometry,
    face_thickness,
    journal_clearance_growth,
    journal_of,
    pair_clearance_growth,
    ring_chord_error,
    ring_sphere_radius,
    ring_step,
    side_geometry,
    toward_partner,
)
from clearbench.adapters.pybullet.settings import MAX_COMPOUND_CHILDREN, PybulletSettings
from clearbench.scenarios.scales import smallest_feature_length
from clearbench.scenarios.scene import Scene

#: Piece kinds whose margin can only be set on a collision object of their own.
MARGIN_KINDS = ("box", "cylinder", "plane")



def margin_feature_length(scene: Scene) -> float:
    """The smallest feature the margins of box and cylinder pieces must stay well below [L]:
    :func:`~clearbench.scenarios.scales.smallest_feature_length` (clearances, offsets, shape
    sizes) or the ``depth`` of a face, whichever is smaller (a face becomes a box or cylinder
    that thick)."""
    depths = [float(shape.depth) for body in scene.expanded.bodies for shape in body.shapes
              if getattr(shape, "depth", None)]
    return min([smallest_feature_length(scene)] + depths)


def collision_margin(scene: Scene, settings: PybulletSettings) -> float | None:
    """Margin of box, cylinder and plane pieces [L], None: PyBullet's (0.001 m)."""
    if settings.collision_margin_relative is not None:
        return settings.collision_margin_relative * margin_feature_length(scene)
    return settings.collision_margin


def check_compound(pieces, where: str = "compound") -> None:
    """Guard: PyBullet drops the children of a compound beyond 16 without a word."""
    if len(pieces) > MAX_COMPOUND_CHILDREN:
        raise ValueError(f"{where}: {len(pieces)} children in one PyBullet compound; PyBullet "
                         f"keeps only {MAX_COMPOUND_CHILDREN} and drops the rest silently "
                         "(split them across links)")


def collision_groups(side: SideGeometry) -> list[tuple]:
    """The pieces of one side, split into collision objects: each box, cylinder or plane alone
    (its margin can be set only there), spheres and capsules in compounds of <= 16."""
    single = [(piece,) for piece in side.pieces if piece.kind in MARGIN_KINDS]
    rest = [piece for piece in side.pieces if piece.kind not in MARGIN_KINDS]
    chunks = [tuple(rest[k:k + MAX_COMPOUND_CHILDREN])
              for k in range(0, len(rest), MAX_COMPOUND_CHILDREN)]
    groups = single + chunks
    for group in groups:
        check_compound(group, f"{side.body}/{side.shape}")
    return groups


