"""How a scene's bodies, ideal joints and drivers map onto PyBullet objects.

PyBullet has three kinds of bodies: static bodies (mass 0), rigid bodies in maximal coordinates
(``useMaximalCoordinates=True``: btRigidBody, split impulse available) and Featherstone
multibodies (``createMultiBody``'s default: a tree of links in joint coordinates, exact joints,
no split impulse). The scene's joint graph is split into a spanning tree (Kruskal, preferring
prismatic, then revolute, spherical and fixed joints as tree edges) and loop closures
(``createConstraint``: point-to-point, fixed or prismatic constraints, soft: they drift):

==========  ==========================  =============================================
joint       tree edge (exact)           loop closure (soft, global ``erp``)
==========  ==========================  =============================================
revolute    JOINT_REVOLUTE              two JOINT_POINT2POINT on the axis
spherical   JOINT_SPHERICAL             one JOINT_POINT2POINT
prismatic   JOINT_PRISMATIC             JOINT_PRISMATIC constraint
fixed       JOINT_FIXED                 JOINT_FIXED constraint
==========  ==========================  =============================================

Every connected component of moving bodies is one multibody: with a fixed base at the world
when it is joined to a fixed body (fixed bodies never move, so all of them are the world), a
floating base (its first body) otherwise. A body with no joint and no driver is its own
multibody (``body_model = 'multibody'``), or a rigid body (``'rigid'``) when its contacts fit one
collision object (one pair side of at most 16 pieces): a rigid body with several collision
objects would need soft fixed constraints between them.

Drivers: a prescribed component must be a joint coordinate of its own (as in the MuJoCo
adapter): a hinge (slide) to a fixed body about (along) the world axis of the body's single
driven component, or, for a body without joints driven in translation only, three slides along
world x, y, z from a fixed base and a spherical joint at the centre of mass (no spherical joint
when all three rotations are driven and held at zero). Pure Python.
"""

from __future__ import annotations

from dataclasses import dataclass

from clearbench.adapters.joint_tree import (
    DrivenDof,
    breadth_first_edges,
    plan_drivers,
    rotations_held,
    split_joint_graph,
)
from clearbench.scenarios.bodies import Motion
from clearbench.scenarios.scene import Scene

__all__ = ["DrivenDof", "LinkPlan", "Topology", "TreePlan", "plan_topology"]


@dataclass(frozen=True)
class LinkPlan:
    """One scene body as a link of a multibody.

    ``parent`` is the parent scene body (None: the multibody's base, i.e. the world for a fixed
    base); ``kind`` is the joint to it: 'revolute', 'prismatic', 'spherical', 'fixed',
    'translation' (slides x, y, z + spherical at the centre of mass), 'translation_held'
    (slides only), or 'base' for the floating base body itself.
    """

    body: str
    parent: str | None
    kind: str
    joint: str | None = None


@dataclass(frozen=True)
class TreePlan:
    """A multibody: fixed at the world (``fixed_base``) or floating (first link is 'base')."""

    fixed_base: bool
    links: tuple


@dataclass(frozen=True)
class Topology:
    """Where every scene body goes, the loop closures, driven dofs and problems."""

    static: tuple
    rigid: tuple
    trees: tuple
    closures: tuple
    driven: dict
    problems: tuple
    ignored_joints: tuple = ()


def plan_topology(scene: Scene, body_model: str, collision_objects: dict[str, int]
                  ) -> Topology:
    """Plan the PyBullet bodies of ``scene``.

    Parameters
    ----------
    scene : Scene
    body_model : {'multibody', 'rigid'}
    collision_objects : dict
        Number of collision objects (pair sides split into groups) of each body.
    """
    graph = split_joint_graph(scene)
    fixed, adjacency, drivers_of = graph.fixed, graph.adjacency, graph.drivers_of

    visited = set(fixed)
    trees: list[TreePlan] = []
    rigid: list[str] = []

    def grow(start_links: list[LinkPlan], starts: list[str], fixed_base: bool) -> None:
        links = list(start_links)
        for parent, joint, child in breadth_first_edges(adjacency, starts, visited):
            links.append(LinkPlan(child, None if parent in fixed else parent, joint.kind,
                                  joint.name))
        if links:
            trees.append(TreePlan(fixed_base, tuple(links)))

    # Components joined to the world.
    grow([], sorted(fixed), True)
    for body in scene.bodies:
        if body.name in visited:
            continue
        visited.add(body.name)
        rotations = [d for d in drivers_of.get(body.name, ()) if d.is_rotation]
        if body.motion is Motion.DRIVEN and (not rotations or rotations_held(rotations)):
            kind = "translation_held" if rotations else "translation"
            grow([LinkPlan(body.name, None, kind)], [body.name], True)
            continue
        alone = not adjacency[body.name]
        if (alone and body_model == "rigid" and body.motion is Motion.FREE
                and collision_objects.get(body.name, 0) <= 1):
            rigid.append(body.name)
            continue
        grow([LinkPlan(body.name, None, "base")], [body.name], False)

    links = [link for tree in trees for link in tree.links]
    driven, problems = plan_drivers(
        scene, drivers_of,
        {link.body for link in links if link.kind in ("translation", "translation_held")},
        {link.body: link.joint for link in links
         if link.kind in ("revolute", "prismatic") and link.parent is None},
        "PyBullet")
    return Topology(tuple(sorted(fixed)), tuple(rigid), tuple(trees),
                    tuple(j.name for j in graph.closures), driven, tuple(problems),
                    graph.ignored)

