"""A labelled schematic of a scene (matplotlib, PNG): every shape's outline in the initial
pose, projected on the plane the viewer looks at, each body in its viewer colour, and the
labels of the parts, the joints (J1..J7, S3) and the contacts (C1..C7) with leader lines.
Lengths in the scene's unit."""

from __future__ import annotations

import math

import numpy as np

from clearbench.harness.report.figures import _png, _pyplot
from clearbench.harness.report.viewer.scene_geometry import body_colours, schematic_labels
from clearbench.kernels.quaternion import quat_normalize, quat_to_matrix
from clearbench.scenarios.geometry import shape_world_placement
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.shapes import Shape

#: Points on a drawn circle.
CIRCLE_POINTS = 72


def _circle(radius: float, start: float = 0.0, end: float = 2 * math.pi, z: float = 0.0
            ) -> np.ndarray:
    angles = np.linspace(start, end, max(8, int(CIRCLE_POINTS * (end - start) / (2 * math.pi))))
    return np.column_stack([radius * np.cos(angles), radius * np.sin(angles),
                            np.full_like(angles, z)])


def shape_outline(shape: Shape) -> list[np.ndarray]:
    """Polylines (each (n, 3), shape frame [L]) that draw the shape's outline: a sphere's
    three great circles, a box's edges, a cylinder's or capsule's end circles and four sides,
    a curve itself, a face's border; none for an unbounded plane."""
    kind = shape.kind
    if kind == "sphere":
        r = shape.radius
        ring = _circle(r)
        return [ring, ring[:, [0, 2, 1]], ring[:, [2, 0, 1]]]
    if kind == "box":
        hx, hy, hz = shape.half_extents
        corners = np.array([[sx * hx, sy * hy, sz * hz] for sx in (-1, 1) for sy in (-1, 1)
                            for sz in (-1, 1)])
        edges = [(0, 1), (2, 3), (4, 5), (6, 7), (0, 2), (1, 3), (4, 6), (5, 7), (0, 4),
                 (1, 5), (2, 6), (3, 7)]
        return [corners[[i, j]] for i, j in edges]
    if kind in ("cylinder", "capsule", "bore"):
        r, h = shape.radius, shape.half_length
        start, end = ((shape.start_angle, shape.end_angle) if kind == "bore"
                      else (0.0, 2 * math.pi))
        lines = [_circle(r, start, end, -h), _circle(r, start, end, h)]
        for angle in np.linspace(start, end, 4, endpoint=kind == "bore"):
            lines.append(np.array([[r * math.cos(angle), r * math.sin(angle), -h],
                                   [r * math.cos(angle), r * math.sin(angle), h]]))
        return lines
    if kind == "circle":
        return [_circle(shape.radius)]
    if kind == "arc":
        return [_circle(shape.radius, shape.start_angle, shape.end_angle)]
    if kind == "rectangle":
        hx, hy = shape.half_extents
        return [np.array([[-hx, -hy, 0], [hx, -hy, 0], [hx, hy, 0], [-hx, hy, 0],
                          [-hx, -hy, 0]], dtype=float)]
    if kind == "disc":
        return [_circle(shape.radius)]
    return []


def projection_axes(direction) -> tuple[np.ndarray, np.ndarray]:
    """Two unit axes (3,) spanning the plane seen when looking along ``direction``: the
    world axes the direction is least along (the C-60 seen along z: x and y)."""
    order = np.argsort(np.abs(np.asarray(direction, dtype=float)))
    first, second = sorted(order[:2])
    return np.eye(3)[first], np.eye(3)[second]


def _free_spot(point: np.ndarray, outward: np.ndarray, reach: float, length: int,
               placed: list[tuple[np.ndarray, int]]) -> np.ndarray:
    """Where a label of ``length`` characters goes: out from ``point`` along ``outward``
    (turned by up to 60 degrees either way, up to 3 reaches out), the first spot whose text
    box (about 0.14 reach a character, 0.4 reach high) clears every label already placed
    (else the last tried)."""
    spot = point + reach * outward
    for distance in (1.0, 1.7, 2.4, 3.0):
        for turn in (0.0, 0.5, -0.5, 1.0, -1.0):
            c, s = math.cos(turn), math.sin(turn)
            direction = np.array([c * outward[0] - s * outward[1],
                                  s * outward[0] + c * outward[1]])
            spot = point + distance * reach * direction
            if all(abs(spot[0] - other[0]) >= 0.07 * reach * (length + n)
                   or abs(spot[1] - other[1]) >= 0.4 * reach for other, n in placed):
                return spot
    return spot


def schematic_figure(scene: Scene, view_axis: int = 2, title: str = "") -> bytes:
    """The scene's labelled schematic as PNG bytes, seen along world axis ``view_axis``."""
    plt = _pyplot()
    expanded = scene.expanded
    colours = body_colours(scene)
    u, v = projection_axes(np.eye(3)[view_axis])
    figure, axes = plt.subplots(figsize=(7.0, 6.2))
    from matplotlib.collections import LineCollection

    for index, body in enumerate(expanded.bodies):
        segments = []
        for shape in body.shapes:
            position, rotation = shape_world_placement(shape, body.position, body.orientation)
            for line in shape_outline(shape):
                world = position + line @ rotation.T
                segments.append(np.column_stack([world @ u, world @ v]))
        if segments:
            axes.add_collection(LineCollection(
                segments, colors=colours[index],
                linewidths=0.6 if body.motion.value == "fixed" else 1.1))
    axes.autoscale_view()
    labels = schematic_labels(scene)
    points = []
    for label in labels:
        body = expanded.bodies[label.body]
        rotation = quat_to_matrix(quat_normalize(np.asarray(body.orientation, dtype=float)))
        points.append(np.asarray(body.position) + rotation @ np.asarray(label.point))
    centre = np.mean(points, axis=0) if points else np.zeros(3)
    reach = 0.12 * max(np.ptp(np.array(points) @ u), np.ptp(np.array(points) @ v), 1e-9) \
        if points else 1.0
    style = {"part": ("black", "normal"), "joint": ("#004a80", "bold"),
             "contact": ("#a00000", "bold")}
    placed: list[tuple[np.ndarray, int]] = []
    for label, point in zip(labels, points, strict=True):
        xy = np.array([point @ u, point @ v])
        outward = xy - np.array([centre @ u, centre @ v])
        norm = float(np.linalg.norm(outward))
        outward = outward / norm if norm > 0 else np.array([1.0, 0.0])
        text_at = _free_spot(xy, outward, reach, len(label.text), placed)
        placed.append((text_at, len(label.text)))
        colour, weight = style[label.kind]
        axes.annotate(label.text.replace("_", " "), xy, text_at, fontsize=8,
                      color=colour, fontweight=weight, ha="center", va="center",
                      arrowprops={"arrowstyle": "-", "color": colour, "linewidth": 0.5},
                      bbox={"boxstyle": "round,pad=0.15", "facecolor": "white",
                            "edgecolor": "none", "alpha": 0.85})
    names = "xyz"
    unit = scene.units.length
    axes.set_xlabel(f"{names[int(np.argmax(u))]} [{unit}]")
    axes.set_ylabel(f"{names[int(np.argmax(v))]} [{unit}]")
    axes.set_aspect("equal", adjustable="datalim")
    axes.grid(True, alpha=0.2)
    axes.set_title(title or f"{scene.name}: parts, joints and contacts in the initial pose",
                   fontsize=10)
    return _png(figure)
