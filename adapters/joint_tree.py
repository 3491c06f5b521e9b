"""The joint graph of a scene split into a spanning tree and loop closures, for engines that
integrate bodies in joint coordinates (MuJoCo's kinematic tree, PyBullet's multibodies).

Engine-neutral: each engine maps the tree edges onto its own tree joints and the closures onto
its own (soft) constraints. The split is Kruskal's over the joints in the order of
:data:`TREE_PRIORITY` (prismatic, then revolute, spherical and fixed joints as tree edges), so
that the joints left over to close loops are the ones engines' loop constraints express best;
all fixed bodies are one node (the world). Drivers are found by body, and a driver prescribes a
tree joint's coordinate only when the joint axis is the world axis of the driven component
(:func:`axis_sign`). Pure Python.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass

import numpy as np

from clearbench.scenarios.bodies import Motion
from clearbench.scenarios.drivers import Driver
from clearbench.scenarios.joints import Joint
from clearbench.scenarios.scene import Scene

__all__ = ["AXIS_TOLERANCE", "TREE_PRIORITY", "DrivenDof", "JointGraph", "axis_sign",
           "breadth_first_edges", "plan_drivers", "rotations_held", "split_joint_graph"]

#: Preference of a joint kind as a tree edge (lower first).
TREE_PRIORITY = {"prismatic": 0, "revolute": 1, "spherical": 2, "fixed": 3}
#: |1 - |a . b|| below which a joint axis is a world axis.
AXIS_TOLERANCE = 1e-9


@dataclass(frozen=True)
class DrivenDof:
    """A driven joint coordinate: ``joint`` ('tree': the body's tree joint, or 'slide_x',
    'slide_y', 'slide_z') moves as ``sign`` times the driver's displacement / velocity."""

    driver: Driver
    joint: str
    sign: float = 1.0


@dataclass(frozen=True)
class JointGraph:
    """A scene's joints split into a spanning tree and loop closures.

    Attributes
    ----------
    fixed : frozenset of str
        The fixed bodies (together: the world node).
    tree_edges, closures : tuple of Joint
        Joints of the spanning tree, and the joints that close loops.
    ignored : tuple of str
        Joints between two fixed bodies (nothing to do).
    adjacency : dict
        Body name -> list of (tree joint, other body) over the tree edges.
    drivers_of : dict
        Body name -> its drivers, in scene order.
    """

    fixed: frozenset
    tree_edges: tuple
    closures: tuple
    ignored: tuple
    adjacency: dict
    drivers_of: dict


def split_joint_graph(scene: Scene) -> JointGraph:
    """Split the joint graph of ``scene`` into a spanning tree and loop closures."""
    fixed = frozenset(b.name for b in scene.bodies if b.motion is Motion.FIXED)
    parent: dict[str, str] = {}

    def node(name: str) -> str:
        return "<fixed>" if name in fixed else name

    def root(name: str) -> str:
        while parent.get(name, name) != name:
            name = parent[name]
        return name

    ignored, tree_edges, closures = [], [], []
    order = sorted(range(len(scene.joints)),
                   key=lambda i: (TREE_PRIORITY[scene.joints[i].kind], i))
    for i in order:
        joint = scene.joints[i]
        if joint.body_a in fixed and joint.body_b in fixed:
            ignored.append(joint.name)
            continue
        a, b = root(node(joint.body_a)), root(node(joint.body_b))
        if a == b:
            closures.append(joint)
        else:
            parent[a] = b
            tree_edges.append(joint)
    adjacency: dict[str, list] = {b.name: [] for b in scene.bodies}
    for joint in tree_edges:
        adjacency[joint.body_a].append((joint, joint.body_b))
        adjacency[joint.body_b].append((joint, joint.body_a))
    drivers_of: dict[str, list] = {}
    for driver in scene.drivers:
        drivers_of.setdefault(driver.body, []).append(driver)
    return JointGraph(fixed, tuple(tree_edges), tuple(closures), tuple(ignored), adjacency,
                      drivers_of)


def rotations_held(rotations: list[Driver]) -> bool:
    """True when the three rotation components are all driven and each profile is zero
    throughout (the body keeps its initial orientation)."""
    return len({d.component for d in rotations}) == 3 and all(
        not any(d.values) for d in rotations)


def axis_sign(joint: Joint, driver: Driver) -> float | None:
    """Sign (+1 or -1) relating the coordinate of ``joint`` (a revolute or prismatic joint to a
    fixed body) to the driven component of ``driver``, or None when the joint is of the other
    kind or its axis is not that world axis.

    A joint is stated in body_a -> body_b terms; the tree child moves relative to the fixed
    parent, so the sign follows the axis alignment only.
    """
    wanted = "revolute" if driver.is_rotation else "prismatic"
    if joint.kind != wanted:
        return None
    alignment = float(np.asarray(joint.axis, dtype=float) @ np.eye(3)[driver.axis_index])
    if abs(abs(alignment) - 1.0) >= AXIS_TOLERANCE:
        return None
    return float(np.sign(alignment))


def breadth_first_edges(adjacency: dict, starts, visited: set) -> list[tuple[str, Joint, str]]:
    """(parent, joint, child) of every body reached breadth-first from the bodies ``starts``
    through tree joints (``JointGraph.adjacency``), skipping bodies in ``visited``; the bodies
    reached are added to ``visited``. Parents come before their children."""
    edges = []
    queue = deque(starts)
    while queue:
        current = queue.popleft()
        for joint, other in adjacency[current]:
            if other in visited:
                continue
            visited.add(other)
            edges.append((current, joint, other))
            queue.append(other)
    return edges


def plan_drivers(scene: Scene, drivers_of: dict, translation_driven: set,
                 grounded_joint: dict, engine: str) -> tuple[dict, list]:
    """Which joint coordinate each driver prescribes, the same rule for every tree engine.

    Parameters
    ----------
    scene : Scene
    drivers_of : dict
        Body name -> its drivers (``JointGraph.drivers_of``).
    translation_driven : set of str
        Bodies without ideal joints given slides x, y, z of their own (and a ball joint unless
        their rotations are held): their translation drivers drive those slides.
    grounded_joint : dict
        Body name -> name of its revolute or prismatic tree joint to a fixed body.
    engine : str
        Engine name for the problem text.

    Returns
    -------
    driven : dict
        Body name -> tuple of :class:`DrivenDof`.
    problems : list of (feature, reason)
        Drivers the engine cannot prescribe.
    """
    joints = {j.name: j for j in scene.joints}
    driven: dict[str, tuple] = {}
    problems = []
    for body, drivers in drivers_of.items():
        if body in translation_driven:
            # Held rotations have no joint: the orientation cannot change (exact).
            driven[body] = tuple(DrivenDof(d, f"slide_{d.component}") for d in drivers
                                 if not d.is_rotation)
            continue
        if body in grounded_joint and len(drivers) == 1:
            # The joint axis is the scene joint's (world, initial pose): the coordinate is the
            # body's rotation (translation) about (along) it.
            sign = axis_sign(joints[grounded_joint[body]], drivers[0])
            if sign is not None:
                driven[body] = (DrivenDof(drivers[0], "tree", sign),)
                continue
        components = ", ".join(d.component for d in drivers)
        problems.append((
            "drivers",
            f"body {body!r} (drivers on {components}): {engine} can prescribe a component only "
            "as a joint coordinate of its own: one rotation (translation) by a revolute "
            "(prismatic) joint to a fixed body about (along) that world axis, or translations "
            "of a body with no ideal joint (its rotations undriven, or all three held at zero)"))
    return driven, problems
