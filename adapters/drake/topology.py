"""How a scene's bodies, ideal joints and drivers map onto a Drake MultibodyPlant.

Fixed scene bodies are the world: their shapes are registered on the world body at their
poses. The joint graph is split into a spanning tree and loop closures
(:func:`~clearbench.adapters.joint_tree.split_joint_graph`): each tree edge is a Drake joint
(``RevoluteJoint``, ``PrismaticJoint``, ``BallRpyJoint``, ``WeldJoint``) whose frames are the
joint's world frame at the initial pose, so every coordinate is 0 there; a body with no tree
joint is a free body (Drake's quaternion floating joint). Loop closures are SAP constraints
(a revolute joint: two ``AddBallConstraint`` on its axis; spherical: one; fixed:
``AddWeldConstraint``); TAMSI has no constraints and Drake has no prismatic one.

Drivers: a driven component must be the coordinate of a revolute (prismatic) tree joint to a
fixed body about (along) that world axis, or a translation of a driven body with no ideal joint,
which then hangs from the world by slides x, y, z (massless intermediate bodies) and a
``BallRpyJoint`` at its centre of mass (none when its three rotations are held at zero)
(:func:`~clearbench.adapters.joint_tree.plan_drivers`, the rule of every tree engine). Pure
Python.
"""

from __future__ import annotations

from dataclasses import dataclass

from clearbench.adapters.joint_tree import (
    breadth_first_edges,
    plan_drivers,
    rotations_held,
    split_joint_graph,
)
from clearbench.scenarios.bodies import Motion
from clearbench.scenarios.scene import Scene

__all__ = ["Topology", "TreeEdge", "plan_topology"]

#: Closure joint kinds expressible as SAP constraints.
CLOSURE_KINDS = ("revolute", "spherical", "fixed")


@dataclass(frozen=True)
class TreeEdge:
    """A scene joint as a Drake tree joint: ``child`` hangs from ``parent`` (None: the world)."""

    parent: str | None
    child: str
    joint: object


@dataclass(frozen=True)
class Topology:
    """Where every scene body goes, the loop closures, driven dofs and problems."""

    fixed: frozenset
    edges: tuple
    free: tuple
    closures: tuple
    driven: dict
    problems: tuple
    slides: dict


def plan_topology(scene: Scene, approximation: str) -> Topology:
    """Plan the Drake plant of ``scene`` for the discrete ``approximation``."""
    graph = split_joint_graph(scene)
    visited = set(graph.fixed)
    edges = [TreeEdge(None if parent in graph.fixed else parent, child, joint)
             for parent, joint, child in breadth_first_edges(graph.adjacency,
                                                             sorted(graph.fixed), visited)]
    free = []
    slides = {}
    for body in scene.bodies:
        if body.name in visited:
            continue
        visited.add(body.name)
        rotations = [d for d in graph.drivers_of.get(body.name, ()) if d.is_rotation]
        if (body.motion is Motion.DRIVEN and not graph.adjacency[body.name]
                and (not rotations or rotations_held(rotations))):
            # Slides x, y, z from the world, then a ball joint at the centre of mass unless
            # every rotation is held at zero.
            slides[body.name] = bool(rotations)
            continue
        free.append(body.name)
        edges += [TreeEdge(parent, child, joint) for parent, joint, child in
                  breadth_first_edges(graph.adjacency, [body.name], visited)]
    driven, problems = plan_drivers(
        scene, graph.drivers_of, set(slides),
        {e.child: e.joint.name for e in edges
         if e.parent is None and e.joint.kind in ("revolute", "prismatic")}, "Drake")
    problems = list(problems)
    for joint in graph.closures:
        if approximation == "tamsi":
            problems.append(("closed_loop", f"joint {joint.name!r} closes a loop: Drake's "
                             "constraints need the SAP solver (sap, lagged, similar), not "
                             "tamsi"))
        elif joint.kind not in CLOSURE_KINDS:
            problems.append((f"joint:{joint.kind}", f"joint {joint.name!r} closes a loop and "
                             f"Drake has no {joint.kind} constraint"))
    return Topology(graph.fixed, tuple(edges), tuple(free), graph.closures, driven,
                    tuple(problems), slides)
