"""How a scene's bodies, ideal joints and drivers map onto MuJoCo's kinematic tree.

MuJoCo integrates a tree of bodies in joint coordinates: joints of the tree are exact, anything
else is a soft equality constraint. The scene's joint graph is therefore split into a spanning
tree (Kruskal, preferring prismatic, then revolute, spherical and fixed joints as tree edges,
so that the joints left over to close loops are the ones MuJoCo's equalities can express) and
loop closures:

==========  =======================  ================================================
joint       tree edge                loop closure
==========  =======================  ================================================
revolute    hinge                    two ``connect`` equalities on the axis
spherical   ball                     one ``connect`` equality
prismatic   slide                    unsupported (no MuJoCo equality keeps one slide)
fixed       no joint (welded child)  ``weld`` equality
==========  =======================  ================================================

Bodies joined to no fixed body get a free joint. A driven body needs each prescribed component
to be one degree of freedom of its own joints, which is the case for (a) a hinge (slide) to a
fixed body about (along) the world axis of its one driven component, or (b) a body with no
tree joint driven in translation only: it gets slides along world x, y, z and a ball joint at
its centre of mass, or (c) such a body whose three rotations are driven and held at zero: the
slides only (its orientation cannot change, exactly as prescribed). Pure Python: no ``mujoco``
import.
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

__all__ = ["TREE_JOINT", "DrivenDof", "Topology", "TreeLink", "plan_topology",
           "rotations_held"]

#: MuJoCo tree joint realising each scene joint kind (None: child welded to its parent).
TREE_JOINT = {"revolute": "hinge", "prismatic": "slide", "spherical": "ball", "fixed": None}


@dataclass(frozen=True)
class TreeLink:
    """How one scene body enters the MuJoCo tree.

    kind: 'static' (fixed body, child of the world, no joint), 'free' (free joint),
    'translation_driven' (slides x, y, z + ball at the centre of mass),
    'translation_driven_held' (slides x, y, z only: every rotation is driven and held at zero,
    so the orientation stays exactly the initial one), 'hinge', 'slide',
    'ball' or 'weld' (tree joint ``joint`` to ``parent``).
    """

    body: str
    parent: str | None
    kind: str
    joint: str | None = None


@dataclass(frozen=True)
class Topology:
    """Tree links in parent-before-child order, loop closures, driven dofs and the reasons
    (feature, why) for which the scene cannot be built."""

    links: tuple
    closures: tuple
    driven: dict
    problems: tuple
    ignored_joints: tuple = ()

    def link(self, body: str) -> TreeLink:
        for link in self.links:
            if link.body == body:
                return link
        raise KeyError(body)


def plan_topology(scene: Scene) -> Topology:
    """Split the joint graph of ``scene`` into a MuJoCo tree and loop closures."""
    graph = split_joint_graph(scene)
    fixed, adjacency, drivers_of = graph.fixed, graph.adjacency, graph.drivers_of
    closures = graph.closures
    links: list[TreeLink] = []
    visited: set[str] = set()

    def visit_from(start: str) -> None:
        for parent, joint, child in breadth_first_edges(adjacency, [start], visited):
            links.append(TreeLink(child, parent, TREE_JOINT[joint.kind] or "weld", joint.name))

    for body in scene.bodies:
        if body.name in fixed:
            visited.add(body.name)
            links.append(TreeLink(body.name, None, "static"))
    for body in scene.bodies:
        if body.name in fixed:
            visit_from(body.name)
    for body in scene.bodies:
        if body.name not in visited:
            visited.add(body.name)
            rotations = [d for d in drivers_of.get(body.name, ()) if d.is_rotation]
            kind = "free"
            if body.motion is Motion.DRIVEN and not rotations:
                kind = "translation_driven"
            elif body.motion is Motion.DRIVEN and rotations_held(rotations):
                kind = "translation_driven_held"
            links.append(TreeLink(body.name, None, kind))
            visit_from(body.name)

    problems = []
    for joint in closures:
        if joint.kind == "prismatic":
            reason = (f"prismatic joint {joint.name!r} closes a loop: no MuJoCo equality "
                      "constraint leaves exactly one sliding freedom")
            problems += [("closed_loop", reason), ("joint:prismatic", reason)]
    driven, driver_problems = plan_drivers(
        scene, drivers_of,
        {link.body for link in links
         if link.kind in ("translation_driven", "translation_driven_held")},
        {link.body: link.joint for link in links
         if link.kind in ("hinge", "slide") and link.parent in fixed},
        "MuJoCo")
    problems += driver_problems
    return Topology(tuple(links), tuple(j.name for j in closures), driven, tuple(problems),
                    graph.ignored)

