"""Each shape's boundary as parametrised patches, with the bounds the search needs.

A patch maps a parameter rectangle (u, v) to points of the shape's boundary in its own frame.
Every parametrisation here is orthogonal (the partial derivatives are perpendicular), so a
parameter cell of half-widths (hu, hv) around its centre maps within

    radius = sqrt((Su hu)^2 + (Sv hv)^2)

of the centre's point, where Su, Sv bound |dp/du|, |dp/dv| over the cell (the image of the
straight parameter path is at most that long). This covering radius is what makes the
search's guarantee: a signed distance is 1-Lipschitz, so over the cell it is at least its
value at the centre minus the radius. A curve is a patch with no v extent.

For a convex partner the search also uses :meth:`Patch.drop`: an upper bound of how far a
linear function n . (p - p_centre) can fall below 0 over the cell (|n| <= 1), from the patch's
exact geometry (a plane cell is a parallelogram; a sphere, cylinder, circle or torus cell lies
within its covering radius of the centre and within the sagitta of its curvature of the
tangent plane or line). It is 0 to second order where the partner's gradient is normal to the
patch (flat contact), which is what keeps resting contacts cheap.

The shapes' boundaries (shape frame; a curve is its own boundary):

=========  ===================================================================================
sphere     one sphere patch (polar angle, azimuth)
box        six plane patches
capsule    the lateral cylinder and two hemispheres
cylinder   the lateral cylinder and two flat ends (polar)
circle     the curve; with a tube: a torus
arc        the curve; with a tube: a torus sector and two hemispherical end caps
plane      none: the half-space's boundary is never needed (a bounded solid's deepest point
           below a plane lies on its own boundary, which is sampled)
rectangle  the top face, and, clipped to the partner's reach, the side faces and the bottom
disc       the top face, and, clipped, the side and the bottom
bore       the inner cylinder, and, clipped, the end annuli, the cut faces and the outer
           cylinder
=========  ===================================================================================
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from clearbench.harness.measure.instrument.solids import TWO_PI, tube_radius

_Z = np.array([0.0, 0.0, 1.0])


def _max_abs_cos(centre: np.ndarray, half: np.ndarray) -> np.ndarray:
    """max |cos| over [centre - half, centre + half] (elementwise)."""
    low, high = centre - half, centre + half
    crosses = np.floor(high / math.pi) > np.floor(low / math.pi)  # holds a multiple of pi
    ends = np.maximum(np.abs(np.cos(low)), np.abs(np.cos(high)))
    return np.where(crosses | (2 * half >= math.pi), 1.0, ends)


def _max_abs_sin(centre: np.ndarray, half: np.ndarray) -> np.ndarray:
    """max |sin| over [centre - half, centre + half]."""
    return _max_abs_cos(centre - 0.5 * math.pi, half)


@dataclass(frozen=True)
class Patch:
    """One parametrised piece of a boundary.

    Attributes
    ----------
    kind : str
        ``planar`` (p = origin + u e1 + v e2), ``polar`` (p = (u cos v, u sin v, z0)),
        ``cylinder`` (p = (r cos u, r sin u, v)), ``sphere`` (p = centre + r Q (sin u cos v,
        sin u sin v, cos u)), ``torus`` (p = ((R + r cos v) cos u, (R + r cos v) sin u,
        r sin v)), ``curve`` (p = (R cos u, R sin u, 0)).
    domain : tuple (u0, u1, v0, v1)
        Parameter rectangle (v0 = v1 = 0 for a curve).
    grid : tuple (nu, nv)
        Cells of the initial subdivision.
    data : dict
        The kind's constants (origin, e1, e2; z0; r; centre, r, Q; R, r; R).
    """

    kind: str
    domain: tuple
    grid: tuple
    data: dict = field(default_factory=dict)

    @property
    def is_curve(self) -> bool:
        return self.kind == "curve"

    def points(self, u: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Points (N, 3) at parameters (N,), (N,) in the shape's frame [L]."""
        d = self.data
        if self.kind == "planar":
            return d["origin"] + u[:, None] * d["e1"] + v[:, None] * d["e2"]
        if self.kind == "polar":
            return np.stack([u * np.cos(v), u * np.sin(v), np.full(len(u), d["z0"])], axis=1)
        if self.kind == "cylinder":
            return np.stack([d["r"] * np.cos(u), d["r"] * np.sin(u), v], axis=1)
        if self.kind == "sphere":
            local = np.stack([np.sin(u) * np.cos(v), np.sin(u) * np.sin(v), np.cos(u)], axis=1)
            return d["centre"] + d["r"] * local @ d["Q"].T
        if self.kind == "torus":
            ring = d["R"] + d["r"] * np.cos(v)
            return np.stack([ring * np.cos(u), ring * np.sin(u), d["r"] * np.sin(v)], axis=1)
        if self.kind == "curve":
            return np.stack([d["R"] * np.cos(u), d["R"] * np.sin(u), np.zeros(len(u))], axis=1)
        raise ValueError(f"unknown patch kind {self.kind!r}")

    def tangents(self, u: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """dp/du and dp/dv (N, 3) at parameters (N,), (N,)."""
        d = self.data
        zero = np.zeros(len(u))
        if self.kind == "planar":
            return np.broadcast_to(d["e1"], (len(u), 3)), np.broadcast_to(d["e2"], (len(u), 3))
        if self.kind == "polar":
            return (np.stack([np.cos(v), np.sin(v), zero], axis=1),
                    np.stack([-u * np.sin(v), u * np.cos(v), zero], axis=1))
        if self.kind == "cylinder":
            return (np.stack([-d["r"] * np.sin(u), d["r"] * np.cos(u), zero], axis=1),
                    np.stack([zero, zero, zero + 1.0], axis=1))
        if self.kind == "sphere":
            du = np.stack([np.cos(u) * np.cos(v), np.cos(u) * np.sin(v), -np.sin(u)], axis=1)
            dv = np.stack([-np.sin(u) * np.sin(v), np.sin(u) * np.cos(v), zero], axis=1)
            return d["r"] * du @ d["Q"].T, d["r"] * dv @ d["Q"].T
        if self.kind == "torus":
            ring = d["R"] + d["r"] * np.cos(v)
            return (np.stack([-ring * np.sin(u), ring * np.cos(u), zero], axis=1),
                    d["r"] * np.stack([-np.sin(v) * np.cos(u), -np.sin(v) * np.sin(u),
                                       np.cos(v)], axis=1))
        return (np.stack([-d["R"] * np.sin(u), d["R"] * np.cos(u), zero], axis=1),
                np.zeros((len(u), 3)))

    def speeds(self, u, v, hu, hv) -> tuple[np.ndarray, np.ndarray]:
        """Upper bounds of |dp/du| and |dp/dv| over the cells [L per parameter unit]."""
        d = self.data
        one = np.ones(len(u))
        if self.kind == "planar":
            return one, one
        if self.kind == "polar":
            return one, u + hu
        if self.kind == "cylinder":
            return d["r"] * one, one
        if self.kind == "sphere":
            return d["r"] * one, d["r"] * _max_abs_sin(u, hu)
        if self.kind == "torus":
            return d["R"] + d["r"] * _max_abs_cos(v, hv), d["r"] * one
        return d["R"] * one, 0.0 * one  # curve

    def radius(self, u, v, hu, hv) -> np.ndarray:
        """Covering radius (N,) [L] of the cells: every point of a cell lies within it of the
        cell centre's point."""
        su, sv = self.speeds(u, v, hu, hv)
        return np.hypot(su * hu, sv * hv)

    def curve_drop(self, n: np.ndarray, curvature: np.ndarray, w: np.ndarray, u, hu
                   ) -> np.ndarray:
        """For a curve patch (a circle of radius R): an upper bound (N,) [L] of
        -(n . D - curvature (w . D)^2 / 2) over each cell, D = p - p_centre, for vectors n, w
        (N, 3) and curvatures (N,) of either sign (negative: the partner's signed distance
        curves up, a gain). With s = sin(d), d the angle from the centre (|d| <= hu <= pi/2):
        D = R s t^ - R (1 - cos d) r^ and s^2 / 2 <= 1 - cos d <= s^2 / (1 + cos hu), so the
        expression is at least a s + Q s^2 (a = R n.t^), minimised over |s| <= sin(hu)."""
        radius = self.data["R"]
        tangent = np.stack([-np.sin(u), np.cos(u), np.zeros(len(u))], axis=1)
        radial = np.stack([np.cos(u), np.sin(u), np.zeros(len(u))], axis=1)
        a = radius * np.sum(n * tangent, axis=1)
        n_radial = np.sum(n * radial, axis=1)
        half = np.minimum(hu, 0.5 * math.pi)
        limit, lean = np.sin(half), np.tan(0.5 * half)
        # -R n.r^ (1 - cos d): a gain where n.r^ < 0, a loss where it is > 0.
        q = radius * np.where(n_radial < 0.0, -0.5 * n_radial,
                              -n_radial / (1.0 + np.cos(half)))
        w_tangent = np.abs(np.sum(w * tangent, axis=1))
        w_radial = np.abs(np.sum(w * radial, axis=1))
        # (w . D)^2 between R^2 s^2 (|w.t^| - 2 |w.r^| tan(hu/2))+ ... and R^2 s^2 (|w.t^| +
        # |w.r^| tan(hu/2))^2.
        low = np.maximum(0.0, w_tangent**2 - 2.0 * w_tangent * w_radial * lean)
        high = (w_tangent + w_radial * lean) ** 2
        q = q + np.where(curvature < 0.0, -0.5 * curvature * radius**2 * low,
                         -0.5 * np.where(curvature > 0.0, curvature, 0.0) * radius**2 * high)
        edge = -np.abs(a) * limit + q * limit**2
        with np.errstate(divide="ignore", invalid="ignore"):
            vertex = np.where((q > 0.0) & (np.abs(a) <= 2.0 * q * limit), -a * a / (4.0 * q),
                              edge)
        return -np.minimum(np.where(q > 0.0, vertex, edge), 0.0)

    def planar_drop(self, n: np.ndarray, curvature: np.ndarray, w: np.ndarray, hu, hv
                    ) -> tuple[np.ndarray, np.ndarray]:
        """For a plane patch and a curvature <= 0 (a gain): an upper bound of
        -(n . D - curvature (w . D)^2 / 2) over each cell, as two parts (u side, v side).
        D = x e1 + y e2 with |x| <= hu, |y| <= hv; with a = (n.e1, n.e2), b = (w.e1, w.e2)
        and t = b.(x, y), split a = l b + a_perp: the expression is a_perp.(x, y) + l t +
        k t^2 / 2 (k = -curvature >= 0), bounded below by the sum of the two terms' minima
        (|t| <= |b1| hu + |b2| hv)."""
        d = self.data
        a1, a2 = n @ d["e1"], n @ d["e2"]
        b1, b2 = w @ d["e1"], w @ d["e2"]
        norm2 = b1 * b1 + b2 * b2
        lam = np.where(norm2 > 0.0, (a1 * b1 + a2 * b2) / np.where(norm2 > 0.0, norm2, 1.0),
                       0.0)
        p1, p2 = a1 - lam * b1, a2 - lam * b2
        k = np.maximum(-curvature, 0.0)
        reach_u, reach_v = np.abs(b1) * hu, np.abs(b2) * hv
        reach = reach_u + reach_v
        edge = -np.abs(lam) * reach + 0.5 * k * reach**2
        with np.errstate(divide="ignore", invalid="ignore"):
            vertex = np.where((k > 0.0) & (np.abs(lam) <= k * reach), -lam * lam / (2.0 * k),
                              edge)
        along = -np.minimum(np.where(k > 0.0, vertex, edge), 0.0)
        share = np.where(reach > 0.0, reach_u / np.where(reach > 0.0, reach, 1.0), 0.5)
        return np.abs(p1) * hu + along * share, np.abs(p2) * hv + along * (1.0 - share)

    def extent(self, w: np.ndarray, u, v, hu, hv) -> tuple[np.ndarray, np.ndarray]:
        """Upper bound of |w . (p - p_centre)| over each cell as (u part, v part): the larger
        of the drops of w and of -w."""
        plus_u, plus_v = self.drop(w, u, v, hu, hv)
        minus_u, minus_v = self.drop(-w, u, v, hu, hv)
        larger = plus_u + plus_v >= minus_u + minus_v
        return np.where(larger, plus_u, minus_u), np.where(larger, plus_v, minus_v)

    def drop(self, n: np.ndarray, u, v, hu, hv) -> tuple[np.ndarray, np.ndarray]:
        """Upper bound [L] of -(n . (p - p_centre)) over each cell, for vectors ``n`` (N, 3) of
        length <= 1 in the shape's frame, as two parts (N,), (N,) whose sum is the bound: the
        part that halving the cell's u side reduces, and the v side's (the search halves the
        side with the larger part)."""
        d = self.data
        su, sv = self.speeds(u, v, hu, hv)
        metric_u, metric_v = su * hu, sv * hv
        radius = np.hypot(metric_u, metric_v)
        share_u = np.where(radius > 0.0, metric_u**2 / np.maximum(radius**2, 1e-300), 1.0)
        if self.kind == "planar":
            return np.abs(n @ d["e1"]) * hu, np.abs(n @ d["e2"]) * hv
        if self.kind == "polar":
            # p - p_c = (rho - rho_c) e(phi) + rho_c (e(phi) - e(phi_c)), e the radial unit.
            tangent = np.stack([-np.sin(v), np.cos(v), np.zeros(len(v))], axis=1)
            radial = np.stack([np.cos(v), np.sin(v), np.zeros(len(v))], axis=1)
            n_radial = np.sum(n * radial, axis=1)
            n_tangent = np.abs(np.sum(n * tangent, axis=1))
            n_planar = np.hypot(n[:, 0], n[:, 1])
            # rho_c (e(phi) - e(phi_c)) = rho_c (sin t^ - (1 - cos) r^): a loss of the
            # second term only where n.r^ > 0.
            return (np.abs(n_radial) * hu + n_planar * hu * hv,
                    u * (n_tangent * hv + np.maximum(n_radial, 0.0) * 0.5 * hv * hv))
        if self.kind in ("cylinder", "curve", "torus"):
            core = d["r"] if self.kind == "cylinder" else d["R"]
            tangent = np.stack([-np.sin(u), np.cos(u), np.zeros(len(u))], axis=1)
            radial = np.stack([np.cos(u), np.sin(u), np.zeros(len(u))], axis=1)
            n_radial = np.sum(n * radial, axis=1)
            # -R (1 - cos d) n.r^ is a loss only where n.r^ > 0 (a gain where it is < 0).
            part_u = (np.abs(np.sum(n * tangent, axis=1)) * core * hu
                      + np.maximum(n_radial, 0.0) * core * 0.5 * hu * hu)
            if self.kind == "cylinder":
                return part_u, np.abs(n[:, 2]) * hv
            if self.kind == "curve":
                return part_u, np.zeros(len(u))
            # Torus: the tube point = core point + r m; m turns by at most
            # alpha = |cos v| hu + hv from its value at the centre.
            m = np.cos(v)[:, None] * radial + np.sin(v)[:, None] * _Z
            along = np.sum(n * m, axis=1)
            across = np.sqrt(np.maximum(0.0, np.sum(n * n, axis=1) - along**2))
            turn_u, turn_v = np.abs(np.cos(v)) * hu, hv
            alpha = turn_u + turn_v
            # r n.(m - m_c): m . (m - m_c) <= 0, a loss only where n.m_c > 0.
            tube = d["r"] * (across * alpha + np.maximum(along, 0.0) * 0.5 * alpha**2)
            share = np.where(alpha > 0.0, turn_u / np.where(alpha > 0.0, alpha, 1.0), 1.0)
            return part_u + tube * share, tube * (1.0 - share)
        if self.kind == "sphere":
            local = np.stack([np.sin(u) * np.cos(v), np.sin(u) * np.sin(v), np.cos(u)], axis=1)
            normal = local @ d["Q"].T
            along = np.sum(n * normal, axis=1)
            across = np.sqrt(np.maximum(0.0, np.sum(n * n, axis=1) - along**2))
            # The cell lies below its tangent plane (by at most radius^2 / 2r): a loss only
            # where n points out along the normal.
            total = across * radius + np.maximum(along, 0.0) * radius**2 / (2.0 * d["r"])
            return total * share_u, total * (1.0 - share_u)
        raise ValueError(f"unknown patch kind {self.kind!r}")


#: Initial cells per full turn of an angle (the search halves them where it must).
CELLS_PER_TURN = 8


def _count(span: float, size: float, per_size: float, low: int = 1, high: int = 64) -> int:
    return int(min(high, max(low, math.ceil(per_size * span / size))))


def _turns(span: float) -> int:
    """Initial cells of an angle range ``span`` [rad]."""
    return max(2, math.ceil(CELLS_PER_TURN * span / TWO_PI))


def _planar(origin, e1, e2, u_range, v_range, size: float) -> Patch:
    return Patch("planar", (*u_range, *v_range),
                 (_count(u_range[1] - u_range[0], size, 1.0),
                  _count(v_range[1] - v_range[0], size, 1.0)),
                 {"origin": np.asarray(origin, float), "e1": np.asarray(e1, float),
                  "e2": np.asarray(e2, float)})


def _sphere(centre, radius: float, rotation, polar_end: float) -> Patch:
    return Patch("sphere", (0.0, polar_end, 0.0, TWO_PI),
                 (max(2, round(4 * polar_end / math.pi)), CELLS_PER_TURN),
                 {"centre": np.asarray(centre, float), "r": float(radius),
                  "Q": np.asarray(rotation, float)})


def _cylinder(radius: float, angles, z_range, size: float) -> Patch:
    span = angles[1] - angles[0]
    return Patch("cylinder", (*angles, *z_range),
                 (_turns(span), 1),
                 {"r": float(radius)})


def _polar(z0: float, rho_range, angles) -> Patch:
    span = angles[1] - angles[0]
    return Patch("polar", (*rho_range, *angles), (1, _turns(span)),
                 {"z0": float(z0)})


def _end_cap_frame(angle: float, outward_sign: float) -> np.ndarray:
    """Rotation whose z column is the arc's tangent at ``angle`` times ``outward_sign`` and
    whose x column is the radial direction there (right-handed)."""
    radial = np.array([math.cos(angle), math.sin(angle), 0.0])
    tangent = outward_sign * np.array([-math.sin(angle), math.cos(angle), 0.0])
    return np.stack([radial, np.cross(tangent, radial), tangent], axis=1)


def _reach_radius(clip) -> float:
    """Largest distance from the z axis of a point of the clip box (lo (3,), hi (3,))."""
    lo, hi = clip
    return float(math.hypot(max(abs(lo[0]), abs(hi[0])), max(abs(lo[1]), abs(hi[1]))))


def boundary_patches(solid, clip=None) -> list[Patch]:
    """The patches of ``solid``'s boundary (:class:`~.solids.Solid`), in its shape's frame.

    Parameters
    ----------
    solid : Solid
    clip : tuple (lo (3,), hi (3,)) or None
        A box in the shape's frame that holds every point of the partner; the unbounded faces
        (the sides of a face without depth, a bore's annuli without depth) are sampled only
        inside it. Needed for those shapes only.
    """
    s = solid.shape
    kind = solid.kind
    if kind == "sphere":
        return [_sphere((0, 0, 0), s.radius, np.eye(3), math.pi)]
    if kind == "box":
        size = max(s.half_extents)
        patches = []
        for axis in range(3):
            j, k = (axis + 1) % 3, (axis + 2) % 3
            for sign in (1.0, -1.0):
                origin = np.zeros(3)
                origin[axis] = sign * s.half_extents[axis]
                patches.append(_planar(origin, np.eye(3)[j], np.eye(3)[k],
                                       (-s.half_extents[j], s.half_extents[j]),
                                       (-s.half_extents[k], s.half_extents[k]), size))
        return patches
    if kind == "capsule":
        flip = np.diag([1.0, -1.0, -1.0])
        return [_cylinder(s.radius, (0.0, TWO_PI), (-s.half_length, s.half_length), s.radius),
                _sphere((0, 0, s.half_length), s.radius, np.eye(3), 0.5 * math.pi),
                _sphere((0, 0, -s.half_length), s.radius, flip, 0.5 * math.pi)]
    if kind == "cylinder":
        return [_cylinder(s.radius, (0.0, TWO_PI), (-s.half_length, s.half_length), s.radius),
                _polar(s.half_length, (0.0, s.radius), (0.0, TWO_PI)),
                _polar(-s.half_length, (0.0, s.radius), (0.0, TWO_PI))]
    if kind in ("circle", "arc"):
        angles = (0.0, TWO_PI) if kind == "circle" else (s.start_angle, s.end_angle)
        span = angles[1] - angles[0]
        tube = tube_radius(s)
        if tube <= 0.0:
            return [Patch("curve", (*angles, 0.0, 0.0),
                          (_turns(span), 1), {"R": float(s.radius)})]
        patches = [Patch("torus", (*angles, 0.0, TWO_PI),
                         (_turns(span), 4),
                         {"R": float(s.radius), "r": tube})]
        if kind == "arc" and span < TWO_PI:
            for angle, sign in ((angles[0], -1.0), (angles[1], 1.0)):
                centre = (s.radius * math.cos(angle), s.radius * math.sin(angle), 0.0)
                patches.append(_sphere(centre, tube, _end_cap_frame(angle, sign), 0.5 * math.pi))
        return patches
    if kind == "plane":
        return []
    if kind in ("rectangle", "disc"):
        return _face_patches(s, kind, clip)
    if kind == "bore":
        return _bore_patches(s, clip)
    raise ValueError(f"the instrument has no boundary for shape kind {kind!r}")


def _depth_range(depth, clip) -> tuple[float, float] | None:
    """The z range [bottom, 0] of a face's sides: down to -depth, or to the clip box."""
    bottom = -depth if depth is not None else -math.inf
    if clip is not None:
        bottom = max(bottom, float(clip[0][2]))
        if float(clip[0][2]) > 0.0 or float(clip[1][2]) < bottom:
            return None
    if not math.isfinite(bottom):
        raise ValueError("a face without depth needs the partner's reach (clip) to sample its "
                         "sides")
    return (bottom, 0.0) if bottom < 0.0 else None


def _face_patches(s, kind: str, clip) -> list[Patch]:
    zs = _depth_range(s.depth, clip)
    if kind == "rectangle":
        hx, hy = s.half_extents
        size = max(hx, hy)
        patches = [_planar((0, 0, 0), (1, 0, 0), (0, 1, 0), (-hx, hx), (-hy, hy), size)]
        if zs is not None:
            for axis, half, other in ((0, hx, hy), (1, hy, hx)):
                e_other = np.eye(3)[1 - axis]
                for sign in (1.0, -1.0):
                    origin = np.zeros(3)
                    origin[axis] = sign * half
                    patches.append(_planar(origin, e_other, _Z, (-other, other), zs, size))
            if s.depth is not None and zs[0] == -s.depth:
                patches.append(_planar((0, 0, -s.depth), (1, 0, 0), (0, 1, 0), (-hx, hx),
                                       (-hy, hy), size))
        return patches
    patches = [_polar(0.0, (0.0, s.radius), (0.0, TWO_PI))]
    if zs is not None:
        patches.append(_cylinder(s.radius, (0.0, TWO_PI), zs, s.radius))
        if s.depth is not None and zs[0] == -s.depth:
            patches.append(_polar(-s.depth, (0.0, s.radius), (0.0, TWO_PI)))
    return patches


def _bore_patches(s, clip) -> list[Patch]:
    angles = (s.start_angle, s.end_angle)
    size = s.radius
    patches = [_cylinder(s.radius, angles, (-s.half_length, s.half_length), size)]
    outer = s.radius + s.depth if s.depth is not None else math.inf
    if clip is not None:
        outer = min(outer, _reach_radius(clip))
    elif not math.isfinite(outer):
        raise ValueError("a bore without depth needs the partner's reach (clip) to sample its "
                         "end faces")
    if outer <= s.radius:
        return patches
    for z0 in (s.half_length, -s.half_length):
        patches.append(_polar(z0, (s.radius, outer), angles))
    if s.end_angle - s.start_angle < TWO_PI:
        for angle in angles:
            radial = (math.cos(angle), math.sin(angle), 0.0)
            patches.append(_planar((0, 0, 0), radial, _Z, (s.radius, outer),
                                   (-s.half_length, s.half_length), size))
    if s.depth is not None and outer == s.radius + s.depth:
        patches.append(_cylinder(outer, angles, (-s.half_length, s.half_length), size))
    return patches
