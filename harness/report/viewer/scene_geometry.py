"""What the viewer draws of a scene: each body's shapes as the parameters of a three.js
geometry, and the labels of a labelled schematic (parts, joints, contacts).

The viewer builds every shape from its parameters in the browser (a sphere from its radius, a
bore from its radius, length and angles, ...), once per scene: every engine's copy of a body
shares the geometry, only the poses differ. Lengths in the scene's unit.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np

from clearbench.kernels.quaternion import quat_normalize, quat_to_matrix
from clearbench.scenarios.bodies import Motion
from clearbench.scenarios.geometry import contacts_between, shape_world_placement
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.shapes import Shape

#: Colours of the moving bodies (Okabe-Ito without black and yellow, then Tableau's), and of
#: fixed ones.
BODY_COLOURS = ("#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#8c564b",
                "#7f7f7f", "#bcbd22", "#17becf", "#9467bd", "#1f77b4")
FIXED_COLOUR = "#9a9a9a"
#: A curve with no volume (circle, arc) is drawn as a tube of this fraction of the scene's size
#: (a shape's own ``tube_radius`` wins where it has one).
CURVE_TUBE = 0.004
#: An unbounded plane is drawn as a square of this many times the scene's size.
PLANE_SPAN = 2.0
#: A joint or contact label: ``..._J3_bot`` -> J3, ``Hook_Tbar_C4_2`` -> C4, ``..._S3_top`` -> S3.
MARK_IN_NAME = re.compile(r"(?:^|_)([JCS]\d+)(?=_|$)")


def shape_parameters(shape: Shape, scene_size: float) -> dict:
    """The shape's kind, its placement in its body frame (``p`` (3,), ``q`` (4,) w,x,y,z) and
    the numbers the viewer builds its geometry from (lengths in the scene's unit, angles
    [rad]). ``scene_size``: a length that sizes curves' tubes and unbounded planes."""
    tube = float(getattr(shape, "tube_radius", 0.0) or 0.0) or CURVE_TUBE * scene_size
    kind = shape.kind
    values: dict[str, float | list[float]] = {}
    if kind == "sphere":
        values = {"radius": shape.radius}
    elif kind == "box":
        values = {"half": list(shape.half_extents)}
    elif kind in ("capsule", "cylinder"):
        values = {"radius": shape.radius, "half_length": shape.half_length}
    elif kind == "plane":
        values = {"half": [PLANE_SPAN * scene_size / 2] * 2}
    elif kind == "circle":
        values = {"radius": shape.radius, "tube": tube, "start": 0.0, "end": 2 * math.pi}
    elif kind == "arc":
        values = {"radius": shape.radius, "tube": tube, "start": shape.start_angle,
                  "end": shape.end_angle}
    elif kind == "rectangle":
        values = {"half": list(shape.half_extents)}
    elif kind == "disc":
        values = {"radius": shape.radius}
    elif kind == "bore":
        values = {"radius": shape.radius, "half_length": shape.half_length,
                  "start": shape.start_angle, "end": shape.end_angle}
    else:
        raise ValueError(f"shape {shape.name!r}: the viewer cannot draw a {kind!r}")
    return {"kind": kind, "name": shape.name, "p": [float(v) for v in shape.position],
            "q": [float(v) for v in shape.orientation],
            **{k: (float(v) if not isinstance(v, list) else [float(x) for x in v])
               for k, v in values.items()}}


def scene_points(scene: Scene) -> np.ndarray:
    """(n, 3) world points of the scene's shapes in its initial pose (each shape's origin, and
    for the round ones the ends of two diameters): what the camera frames and what sizes the
    drawing [L]."""
    points = []
    for body in scene.expanded.bodies:
        for shape in body.shapes:
            if shape.kind == "plane":
                continue
            position, rotation = shape_world_placement(shape, body.position, body.orientation)
            points.append(position)
            radius = getattr(shape, "radius", 0.0)
            half = getattr(shape, "half_extents", ())
            for axis in range(2):
                extent = radius or (half[axis] if len(half) > axis else 0.0)
                points += [position + extent * rotation[:, axis],
                           position - extent * rotation[:, axis]]
        points.append(np.asarray(body.position, dtype=float))
    return np.asarray(points, dtype=float).reshape(-1, 3)


def scene_size(scene: Scene) -> float:
    """The diagonal of the box around :func:`scene_points` [L] (1 when the scene has no
    extent, a lone sphere's at least its diameter)."""
    points = scene_points(scene)
    size = float(np.linalg.norm(np.ptp(points, axis=0))) if len(points) else 0.0
    radii = [getattr(s, "radius", 0.0) for b in scene.bodies for s in b.shapes]
    return max(size, 2 * max(radii, default=0.0)) or 1.0


@dataclass(frozen=True)
class Label:
    """A label of the schematic: ``text`` at ``point`` (3,), in the frame of body ``body``
    (index into the scene's bodies) [L]; ``kind``: ``part``, ``joint`` or ``contact``."""

    text: str
    kind: str
    body: int
    point: tuple


def _local(scene: Scene, body: int, world) -> tuple:
    """A world point in body ``body``'s frame at the initial pose."""
    entry = scene.expanded.bodies[body]
    rotation = quat_to_matrix(quat_normalize(np.asarray(entry.orientation, dtype=float)))
    return tuple(float(v) for v in rotation.T @ (np.asarray(world) - np.asarray(entry.position)))


def schematic_labels(scene: Scene) -> list[Label]:
    """Labels of the parts (each moving body at the centre of its shapes), the joints (each
    name ``J<n>``/``S<n>`` of a contact pair, at its ring: the pair's contact point in the
    initial pose) and the contacts (``C<n>``, likewise), each on the body of the pair's first
    shape; one label per mark, at the middle of its pairs' points."""
    expanded = scene.expanded
    index = {b.name: i for i, b in enumerate(expanded.bodies)}
    labels = []
    for i, body in enumerate(expanded.bodies):
        if body.motion is Motion.FIXED or not body.shapes:
            continue
        centres = [shape_world_placement(s, body.position, body.orientation)[0]
                   for s in body.shapes]
        labels.append(Label(body.name, "part", i,
                            _local(scene, i, np.mean(centres, axis=0))))
    marks: dict[str, list] = {}
    for contact in expanded.contacts:
        match = MARK_IN_NAME.search(contact.name)
        if not match:
            continue
        a, b = expanded.bodies[index[contact.body_a]], expanded.bodies[index[contact.body_b]]
        result = contacts_between(a.shape(contact.shape_a), (a.position, a.orientation),
                                  b.shape(contact.shape_b), (b.position, b.orientation))
        if result.count:
            k = int(np.argmin(result.gap))
            point = 0.5 * (result.point_a[k] + result.point_b[k])
        else:
            point = shape_world_placement(a.shape(contact.shape_a), a.position,
                                          a.orientation)[0]
        moving = index[contact.body_a] if a.motion is not Motion.FIXED else index[contact.body_b]
        marks.setdefault(match.group(1), []).append((moving, point))
    for mark, entries in sorted(marks.items(), key=lambda item: (item[0][0],
                                                                 int(item[0][1:]))):
        body = entries[0][0]
        centre = np.mean([p for _, p in entries], axis=0)
        labels.append(Label(mark, "joint" if mark[0] in "JS" else "contact", body,
                            _local(scene, body, centre)))
    return labels


def body_colours(scene: Scene) -> list[str]:
    """One colour per body of the scene: fixed bodies grey, moving ones in turn."""
    colours, k = [], 0
    for body in scene.expanded.bodies:
        if body.motion is Motion.FIXED:
            colours.append(FIXED_COLOUR)
        else:
            colours.append(BODY_COLOURS[k % len(BODY_COLOURS)])
            k += 1
    return colours


def scene_description(scene: Scene) -> dict:
    """The viewer's description of ``scene`` (JSON-ready): bodies with colours and shapes,
    labels, size [L] and the length unit."""
    size = scene_size(scene)
    colours = body_colours(scene)
    bodies = [{"name": body.name, "fixed": body.motion is Motion.FIXED, "colour": colours[i],
               "shapes": [shape_parameters(s, size) for s in body.shapes]}
              for i, body in enumerate(scene.expanded.bodies)]
    return {"name": scene.name, "length_unit": scene.units.length,
            "time_unit": scene.units.time, "size": size,
            "gravity": [float(g) for g in scene.gravity], "bodies": bodies,
            "labels": [{"text": lb.text, "kind": lb.kind, "body": lb.body,
                        "point": list(lb.point)} for lb in schematic_labels(scene)]}
