"""Exact signed distance functions of each shape's solid, in the shape's own frame.

The solids (the ones the gap kernel models, docs/harness.md "The independent instrument"):

=========  ===================================================================================
sphere     the ball of ``radius``
box        the box of ``half_extents``
capsule    the points within ``radius`` of the segment z in [-half_length, half_length]
cylinder   the finite solid cylinder rho <= radius, |z| <= half_length
plane      the half-space z <= 0
rectangle  the slab |x| <= half_x, |y| <= half_y, -depth <= z <= 0 (depth None: z <= 0)
disc       rho <= radius, -depth <= z <= 0 (depth None: z <= 0)
bore       the material outside the hole: radius <= rho <= radius + depth (depth None: no outer
           bound), |z| <= half_length, polar angle in [start_angle, end_angle]
circle     the circle of ``radius`` in the xy-plane (a curve, no volume), or, with a
           ``tube_radius`` > 0, the points within that distance of it (a torus)
arc        the part of that circle between the angles (rad), or the points within
           ``tube_radius`` of it (a torus sector with round ends)
=========  ===================================================================================

Each signed distance is exact: the distance to the solid outside it, minus the distance to its
complement inside it (a curve has no inside: its distance is unsigned). Solids that are
products of simpler sets in orthogonal subspaces (a box, a cylinder, a slab, a bore) combine
their factors' signed distances exactly: outside, the norm of the positive parts; inside, the
largest (least negative) one. :meth:`Solid.gradient` is a unit (sub)gradient of the signed
distance: for a convex solid, the supporting hyperplane the search's bounds rely on
(:mod:`.search`); for every solid, the direction to its nearest boundary point (the witness
on it). Points are (N, 3) arrays in the shape's frame, lengths in the scene's unit [L].
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

TWO_PI = 2.0 * math.pi


def tube_radius(shape) -> float:
    """A ring's tube radius [L] (0 for a bare curve, and for a shape without the field)."""
    return float(getattr(shape, "tube_radius", 0.0) or 0.0)


def _sign(values: np.ndarray) -> np.ndarray:
    """sign with sign(0) = +1 (a valid subgradient of |x| at 0)."""
    return np.where(values >= 0.0, 1.0, -1.0)


def _unit(vectors: np.ndarray, fallback) -> np.ndarray:
    """Rows of ``vectors`` (N, 3) normalised; rows of zero length get ``fallback`` (3,)."""
    norm = np.linalg.norm(vectors, axis=1, keepdims=True)
    safe = np.where(norm > 0.0, norm, 1.0)
    return np.where(norm > 0.0, vectors / safe, np.asarray(fallback, dtype=np.float64))


def _axis(count: int, index: int, signs=None) -> np.ndarray:
    out = np.zeros((count, 3))
    out[:, index] = 1.0 if signs is None else signs
    return out


def combine(values: np.ndarray) -> np.ndarray:
    """The product combination of factor values (N, m): the norm of the positive parts plus
    the largest value where it is negative (nondecreasing in each factor)."""
    return np.linalg.norm(np.maximum(values, 0.0), axis=1) + np.minimum(values.max(axis=1), 0.0)


def _product(components: list[tuple[np.ndarray, np.ndarray]]) -> tuple[np.ndarray, np.ndarray]:
    """Signed distance and gradient of a product of sets in orthogonal subspaces from its
    factors' (value (N,), gradient (N, 3)) pairs."""
    values = np.stack([c[0] for c in components], axis=1)  # (N, m)
    gradients = np.stack([c[1] for c in components], axis=1)  # (N, m, 3)
    positive = np.maximum(values, 0.0)
    outside = np.linalg.norm(positive, axis=1)
    largest = np.argmax(values, axis=1)
    rows = np.arange(len(values))
    inside = np.minimum(values[rows, largest], 0.0)
    safe = np.where(outside > 0.0, outside, 1.0)
    gradient_out = np.einsum("nm,nmk->nk", positive, gradients) / safe[:, None]
    gradient = np.where((outside > 0.0)[:, None], gradient_out, gradients[rows, largest])
    return outside + inside, gradient


def _interval(points: np.ndarray, index: int, half: float):
    """|x_index| <= half."""
    coordinate = points[:, index]
    signs = _sign(coordinate)
    return np.abs(coordinate) - half, _axis(len(points), index, signs)


def _below(points: np.ndarray, depth: float | None):
    """z <= 0 (depth None) or -depth <= z <= 0."""
    z = points[:, 2]
    if depth is None:
        return z.copy(), _axis(len(points), 2)
    centred = z + 0.5 * depth
    return np.abs(centred) - 0.5 * depth, _axis(len(points), 2, _sign(centred))


def _round(points: np.ndarray, radius: float):
    """x^2 + y^2 <= radius^2 (any z)."""
    planar = points.copy()
    planar[:, 2] = 0.0
    return np.linalg.norm(planar, axis=1) - radius, _unit(planar, (1.0, 0.0, 0.0))


def _in_angles(angle: np.ndarray, start: float, span: float) -> np.ndarray:
    """True where the polar ``angle`` [rad] lies in [start, start + span]."""
    if span >= TWO_PI:
        return np.ones(angle.shape, dtype=bool)
    return np.mod(angle - start, TWO_PI) <= span


def _nearest_on_arc(points: np.ndarray, radius: float, start: float, span: float) -> np.ndarray:
    """Nearest point (N, 3) of the arc of ``radius`` in the plane z = 0 (angles ``start`` ..
    ``start + span``) to each point: the point at the point's polar angle when that angle is
    in the arc, else the nearer end (the distance grows with the angle away from the point's)."""
    angle = np.arctan2(points[:, 1], points[:, 0])
    inside = _in_angles(angle, start, span)
    on_circle = np.stack([radius * np.cos(angle), radius * np.sin(angle),
                          np.zeros(len(points))], axis=1)
    if span >= TWO_PI:
        return on_circle
    ends = np.array([[radius * math.cos(a), radius * math.sin(a), 0.0]
                     for a in (start, start + span)])
    to_ends = np.linalg.norm(points[:, None, :] - ends[None, :, :], axis=2)
    nearer = ends[np.argmin(to_ends, axis=1)]
    return np.where(inside[:, None], on_circle, nearer)


def _nearest_on_segment(points: np.ndarray, angle: float, low: float, high: float
                        ) -> np.ndarray:
    """Nearest point (N, 3) of the radial segment at polar ``angle`` from ``low`` to ``high``
    (``high`` may be inf) in the plane z = 0."""
    direction = np.array([math.cos(angle), math.sin(angle), 0.0])
    along = np.clip(points @ direction, low, high)
    return along[:, None] * direction[None, :]


def _annular_sector(points: np.ndarray, inner: float, outer: float, start: float,
                    span: float):
    """The 2D region inner <= rho <= outer (outer may be inf), polar angle in [start, start +
    span], extruded along z: its exact signed distance in the xy-plane and gradient, from the
    nearest point of its boundary (two arcs and two radial segments)."""
    planar = points.copy()
    planar[:, 2] = 0.0
    candidates = [_nearest_on_arc(planar, inner, start, span)]
    if math.isfinite(outer):
        candidates.append(_nearest_on_arc(planar, outer, start, span))
    if span < TWO_PI:
        candidates += [_nearest_on_segment(planar, a, inner, outer)
                       for a in (start, start + span)]
    nearest = np.stack(candidates, axis=1)  # (N, c, 3)
    distances = np.linalg.norm(planar[:, None, :] - nearest, axis=2)
    best = np.argmin(distances, axis=1)
    rows = np.arange(len(points))
    distance = distances[rows, best]
    foot = nearest[rows, best]
    rho = np.linalg.norm(planar, axis=1)
    inside = (rho >= inner) & (rho <= outer) & _in_angles(
        np.arctan2(planar[:, 1], planar[:, 0]), start, span)
    away = _unit(planar - foot, (-1.0, 0.0, 0.0))
    sign = np.where(inside, -1.0, 1.0)
    # On the boundary itself (distance 0) the direction is the inner surface's outward normal
    # (toward the axis); only the witness point uses it there.
    return sign * distance, sign[:, None] * away


def _flat(model):
    """A convex factor's (value, gradient) as a lower model with no curvature."""
    value, gradient = model
    return value, gradient, np.zeros(len(value)), gradient


def _inside_cylinder(points: np.ndarray, outer: float, radius: np.ndarray):
    """Lower model of the signed distance of {rho <= outer} (a superset of a cylinder or a
    capsule of that radius: value rho - outer, convex) for the balls of ``radius`` (N,)
    around ``points``: |c + D| >= |c| + c^.D + (w.D)^2 / (2 (|c| + |D|)) in the xy-plane
    (w = z x c^), a negative curvature -1 / (rho + radius) (a gain)."""
    value, radial = _round(points, outer)
    rho = value + outer
    across = np.stack([-radial[:, 1], radial[:, 0], np.zeros(len(rho))], axis=1)
    return value, radial, -1.0 / (rho + radius), across


def _torus(points: np.ndarray, ring: float, tube: float, radius: np.ndarray):
    """Lower model of the torus's signed distance g(rho, z) - tube, g = |(rho - ring, z)|:
    g is convex in (rho, z), so g' >= g + a (rho' - rho) + b (z' - z) with (a, b) its unit
    gradient; rho' - rho lies within rho^.D + |D_perp|^2 / (2 (rho +- |D_xy|)), a gain where
    a > 0 (curvature -a / (rho + r)) and a loss where a < 0 (|a| / (rho - r), inf where the
    ball of radius r reaches the axis)."""
    value, radial = _round(points, 0.0)
    rho = value
    z = points[:, 2]
    meridian = np.hypot(rho - ring, z)
    safe = np.where(meridian > 0.0, meridian, 1.0)
    a = np.where(meridian > 0.0, (rho - ring) / safe, 1.0)
    b = np.where(meridian > 0.0, z / safe, 0.0)
    normal = a[:, None] * radial + b[:, None] * np.array([0.0, 0.0, 1.0])
    clearance = rho - radius
    loss = np.where(clearance > 0.0, -a / np.maximum(clearance, 1e-300), np.inf)
    curvature = np.where(a > 0.0, -a / (rho + radius), loss)
    across = np.stack([-radial[:, 1], radial[:, 0], np.zeros(len(rho))], axis=1)
    return meridian - tube, normal, curvature, across


def _outside_cylinder(points: np.ndarray, inner: float, radius: np.ndarray):
    """Lower model of the signed distance of {rho >= inner} (value inner - rho) for the balls
    of ``radius`` (N,) around ``points``: in the xy-plane |c + D| <= |c| + c^.D + (w.D)^2 /
    (2 (|c| + c^.D)) with w = z x c^, and |c| + c^.D >= rho - radius; curvature inf where the
    ball reaches the axis."""
    value, radial = _round(points, inner)
    rho = value + inner
    clearance = rho - radius
    curvature = np.where(clearance > 0.0, 1.0 / np.maximum(clearance, 1e-300), np.inf)
    across = np.stack([-radial[:, 1], radial[:, 0], np.zeros(len(rho))], axis=1)
    return -value, -radial, curvature, across


@dataclass(frozen=True)
class Solid:
    """A shape's solid: exact signed distance, gradient, convexity, volume, bounding sphere.

    Attributes
    ----------
    shape : Shape
        The ``scenarios.shapes`` object (its kind-specific fields are read).
    convex : bool
        The solid is convex, so its signed distance is a convex function and
        f(q) >= f(p) + gradient(p) . (q - p) for all p, q (the search's sharper bound).
    has_volume : bool
        False for a bare curve (a circle or arc without tube): nothing is inside it.
    bound : tuple (centre (3,), radius) or None
        A sphere containing the solid, in the shape's frame [L]; None if it is unbounded.
    """

    shape: object

    @property
    def kind(self) -> str:
        return self.shape.kind

    @property
    def tube(self) -> float:
        return tube_radius(self.shape) if self.kind in ("circle", "arc") else 0.0

    @property
    def convex(self) -> bool:
        return self.kind in ("sphere", "box", "capsule", "cylinder", "plane", "rectangle",
                             "disc")

    @property
    def has_volume(self) -> bool:
        return self.kind not in ("circle", "arc") or self.tube > 0.0

    @property
    def bound(self) -> tuple[np.ndarray, float] | None:
        s = self.shape
        origin = np.zeros(3)
        if self.kind == "sphere":
            return origin, float(s.radius)
        if self.kind == "box":
            return origin, float(np.linalg.norm(s.half_extents))
        if self.kind == "capsule":
            return origin, float(s.half_length + s.radius)
        if self.kind == "cylinder":
            return origin, float(math.hypot(s.radius, s.half_length))
        if self.kind in ("circle", "arc"):
            return origin, float(s.radius + self.tube)
        if self.kind in ("rectangle", "disc") and s.depth is not None:
            reach = (float(np.linalg.norm(s.half_extents)) if self.kind == "rectangle"
                     else float(s.radius))
            return np.array([0.0, 0.0, -0.5 * s.depth]), float(math.hypot(reach, 0.5 * s.depth))
        if self.kind == "bore" and s.depth is not None:
            return origin, float(math.hypot(s.radius + s.depth, s.half_length))
        return None

    @property
    def sizes(self) -> list[float]:
        """The shape's lengths [L] (radius, half length, half extents, depth, tube radius)."""
        s = self.shape
        values = [getattr(s, name) for name in ("radius", "half_length", "depth")
                  if getattr(s, name, None) is not None]
        values += list(getattr(s, "half_extents", ()))
        if self.tube > 0.0:
            values.append(self.tube)
        return [float(v) for v in values]

    @property
    def curved_models(self) -> bool:
        """True when :meth:`lower_models` has models curved across the z axis (they need how
        far a cell reaches in the xy-plane)."""
        return self.kind in ("cylinder", "capsule", "disc", "bore") or self.tube > 0.0

    def lower_models(self, points: np.ndarray, value: np.ndarray, gradient: np.ndarray,
                     radius: np.ndarray) -> list[list[tuple]]:
        """Lower models of the signed distance f around ``points`` (N, 3), for the points q
        with |(q - p)_xy| <= ``radius`` (N,) [L] (the displacement's part in the shape's
        xy-plane; the models do not depend on z); ``value``, ``gradient``: f and its gradient
        there.

        Returns factors, each a list of models (value0 (N,), n (N, 3) with |n| <= 1,
        curvature (N,) >= 0, w (N, 3) unit) of one factor's signed distance d:

            d(q) >= value0 + n . (q - p) - curvature (w . (q - p))^2 / 2

        for every q in the ball. A factor's lower bound is its best model's; with several
        factors, f >= F(the factors' lower bounds), F the product combination of
        :func:`_product` (nondecreasing in each factor), so the bound holds.

        A convex solid is its own tangent plane (curvature 0); a product of sets (a box, a
        slab, a cylinder) has one factor per set, each its own tangent plane, and a round
        factor (and a capsule) also the inside of its infinite cylinder, which curves up
        across the radius (curvature -1 / (rho + r), a gain). A non-convex one
        is bounded through a product of sets that contains it (a superset's signed distance is
        never larger; an intersection's is at least each part's): a bore by (rho >= R and,
        with a depth, rho <= R + depth) x (|z| <= half_length), the first model concave
        across the radius (value R - rho, curvature 1 / (rho - r) along w = z x rho^ for a
        ball of radius r off the axis); a ring's tube by its whole torus (an arc's tube lies
        in it), whose signed distance sqrt((rho - R)^2 + z^2) - t is convex in (rho, z):
        its tangent there, with rho's own curvature across the radius. A bare curve has none
        (the search falls back on the Lipschitz bound)."""
        p = np.asarray(points, dtype=np.float64)
        s = self.shape
        # Products of sets: one factor per set, each its own tangent (a kink of the product,
        # a box's edge, costs nothing then); a round factor also curves up across z.
        if self.kind == "box":
            return [[_flat(_interval(p, i, s.half_extents[i]))] for i in range(3)]
        if self.kind == "rectangle":
            return [[_flat(_interval(p, 0, s.half_extents[0]))],
                    [_flat(_interval(p, 1, s.half_extents[1]))], [_flat(_below(p, s.depth))]]
        if self.kind in ("cylinder", "disc"):
            round_models = [_flat(_round(p, s.radius)), _inside_cylinder(p, s.radius, radius)]
            along = (_interval(p, 2, s.half_length) if self.kind == "cylinder"
                     else _below(p, s.depth))
            return [round_models, [_flat(along)]]
        if self.convex:
            models = [(value, gradient, np.zeros(len(value)), gradient)]
            if self.kind == "capsule":
                models.append(_inside_cylinder(points, s.radius, radius))
            return [models]
        if self.kind == "bore":
            radial = [_outside_cylinder(p, s.radius, radius)]
            if s.depth is not None:
                radial.append(_flat(_round(p, s.radius + s.depth)))
            return [radial, [_flat(_interval(p, 2, s.half_length))]]
        if self.tube > 0.0:
            return [[_torus(p, s.radius, self.tube, radius)]]
        return []

    def half_spaces(self) -> list[tuple[np.ndarray, float]]:
        """Half-spaces {n . p <= c} (unit n (3,), c [L]) that hold the whole solid, for the
        search's extra lower bounds (the solid's signed distance is at least n . p - c): the
        two sides of the wedge of angles of a bore or an arc's tube spanning at most pi (the
        tube reaches its radius beyond them)."""
        if self.kind == "bore" or (self.kind == "arc" and self.tube > 0.0):
            start, end = self.shape.start_angle, self.shape.end_angle
            if end - start <= math.pi:
                reach = self.tube if self.kind == "arc" else 0.0
                return [(np.array([math.sin(start), -math.cos(start), 0.0]), reach),
                        (np.array([-math.sin(end), math.cos(end), 0.0]), reach)]
        return []

    def distance(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Signed distance (N,) [L] and unit gradient (N, 3) at ``points`` (N, 3) [L] in the
        shape's frame."""
        p = np.asarray(points, dtype=np.float64)
        s = self.shape
        kind = self.kind
        if kind == "sphere":
            return np.linalg.norm(p, axis=1) - s.radius, _unit(p, (0.0, 0.0, 1.0))
        if kind == "box":
            return _product([_interval(p, i, s.half_extents[i]) for i in range(3)])
        if kind == "capsule":
            axis_point = np.zeros_like(p)
            axis_point[:, 2] = np.clip(p[:, 2], -s.half_length, s.half_length)
            away = p - axis_point
            return np.linalg.norm(away, axis=1) - s.radius, _unit(away, (1.0, 0.0, 0.0))
        if kind == "cylinder":
            return _product([_round(p, s.radius), _interval(p, 2, s.half_length)])
        if kind == "plane":
            return p[:, 2].copy(), _axis(len(p), 2)
        if kind == "rectangle":
            return _product([_interval(p, 0, s.half_extents[0]),
                             _interval(p, 1, s.half_extents[1]), _below(p, s.depth)])
        if kind == "disc":
            return _product([_round(p, s.radius), _below(p, s.depth)])
        if kind == "bore":
            outer = math.inf if s.depth is None else s.radius + s.depth
            sector = _annular_sector(p, s.radius, outer, s.start_angle,
                                     s.end_angle - s.start_angle)
            return _product([sector, _interval(p, 2, s.half_length)])
        if kind in ("circle", "arc"):
            start, span = ((0.0, TWO_PI) if kind == "circle"
                           else (s.start_angle, s.end_angle - s.start_angle))
            away = p - _nearest_on_arc(p, s.radius, start, span)
            return np.linalg.norm(away, axis=1) - self.tube, _unit(away, (0.0, 0.0, 1.0))
        raise ValueError(f"the instrument has no solid for shape kind {kind!r} "
                         f"(shape {getattr(s, 'name', '?')!r})")
