"""The instrument's reading of one pair of shapes: a witnessed signed distance and its resolution.

What is measured
----------------
For two solids A and B (:mod:`.solids`; a bare circle or arc is a curve, its own boundary,
with nothing inside it) the signed distance read here is

    G = min( min over the boundary of A of f_B ,  min over the boundary of B of f_A )

with f_X the exact signed distance of X's solid. Separated, both terms are the distance
between the solids (> 0). Overlapping, -G is the depth of the deepest boundary point of one
solid inside the other (its distance to the other's surface): a real point, so no kernel that
models the same solids can report less penetration, and it is never more than the depth one
must move the shapes apart (a point at depth d needs a move of at least d). For a curve
against a solid it is the depth of the curve's deepest point inside the solid.

Terms left out where they cannot be the minimum: a plane's boundary (the deepest point of a
bounded solid below a plane lies on its own boundary), and a solid's boundary against a bare
curve (the curve has no inside; separated, the other term gives the same distance). Faces and
bores without a depth are unbounded: their boundary is sampled only where the partner's
bounding sphere can reach, and a pair of two unbounded shapes is not read.

The guarantee
-------------
Each term is minimised by the certified search of :mod:`.search`. The reading's ``gap`` is the
smallest value found at a real point (so G <= gap), and ``resolution`` is how far below it G
can still be: G lies in [gap - resolution, gap], with ``resolution`` at most the tolerance
asked for (default :data:`RESOLUTION_FRACTION` of the pair's smallest length) unless the
search's cell cap stopped it (then the bound it reached is reported, larger).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from clearbench.harness.measure.instrument.placement import (
    relative_transforms,
    shape_placements,
)
from clearbench.harness.measure.instrument.search import CELLS_PER_STATE, minimise
from clearbench.harness.measure.instrument.solids import Solid
from clearbench.harness.measure.instrument.surfaces import boundary_patches

#: Default resolution of a reading, as a fraction of the pair's smallest length (radius, half
#: length, half extent, depth or tube radius of either shape): 1e-6 resolves a C-60 arc's
#: (r 0.5 mm) gaps to 0.5 nm, far below its 5 um clearances, the compliant engines'
#: penetrations of 0.1-1 um and the 19 um the old kernel missed. The search's cost hardly
#: depends on it (its bounds are second order where the contact is smooth): reading a
#: 201-state MuJoCo c60-on took 1.31, 1.41 and 1.47 s at 1e-3, 1e-4 and 1e-5 (wall, in turn),
#: and 0.87-0.92 s of CPU at 1e-6 against 0.82-0.93 s at 1e-5.
RESOLUTION_FRACTION = 1e-6

_FACE_KINDS = ("rectangle", "disc", "bore")


@dataclass(frozen=True)
class IndependentGap:
    """The instrument's reading of one pair at one configuration.

    Attributes
    ----------
    gap : float
        Signed distance [L] witnessed at a real point (> 0: separated by this distance; < 0:
        a boundary point of one shape lies this deep inside the other's solid). The true
        value is at most this.
    resolution : float
        The true value lies in [gap - resolution, gap] [L].
    point_a, point_b : ndarray (3,)
        Witnesses, world [L]: a point on A's boundary and the nearest point of B's boundary to
        it, or the reverse (``witnessed_on`` says which one was sampled).
    witnessed_on : str
        ``"a"`` or ``"b"``: whose boundary holds the witness.
    """

    gap: float
    resolution: float
    point_a: np.ndarray
    point_b: np.ndarray
    witnessed_on: str = "a"

    @property
    def lower(self) -> float:
        """Certified lower bound of the signed distance [L]."""
        return self.gap - self.resolution


@dataclass(frozen=True)
class PairGaps:
    """:class:`IndependentGap` at T configurations: ``gap``, ``lower`` (T,) [L] (``gap`` is
    +inf where the search found nothing below its floor: then only ``lower`` >= floor is
    known), ``point_a``, ``point_b`` (T, 3) world [L] (NaN where gap is +inf)."""

    gap: np.ndarray
    lower: np.ndarray
    point_a: np.ndarray
    point_b: np.ndarray
    witnessed_on: np.ndarray

    @property
    def resolution(self) -> np.ndarray:
        return self.gap - self.lower


def pair_resolution(shape_a, shape_b) -> float:
    """Default resolution [L] of a reading of this pair: :data:`RESOLUTION_FRACTION` of its
    smallest length."""
    sizes = Solid(shape_a).sizes + Solid(shape_b).sizes
    return RESOLUTION_FRACTION * min(s for s in sizes if s > 0.0)


def _sampled(solid: Solid, partner: Solid) -> bool:
    """True when ``solid``'s boundary can be sampled against ``partner`` (it is bounded, or
    it is a face or bore whose partner is bounded)."""
    if solid.kind == "plane":
        return False
    return solid.bound is not None or (solid.kind in _FACE_KINDS and partner.bound is not None)


def _terms(a: Solid, b: Solid) -> tuple[bool, bool]:
    """Which terms are needed: (A's boundary against B, B's boundary against A)."""
    ab = _sampled(a, b) and (b.has_volume or not _sampled(b, a))
    ba = _sampled(b, a) and (a.has_volume or not ab)
    if not (ab or ba):
        raise ValueError(f"the instrument cannot read the pair {a.kind}-{b.kind} (shapes "
                         f"{getattr(a.shape, 'name', '?')!r}, {getattr(b.shape, 'name', '?')!r}):"
                         " neither boundary is bounded")
    return ab, ba


def _clip_box(solid: Solid, rotation, position, partner: Solid, partner_rotation,
              partner_position, states) -> tuple[np.ndarray, np.ndarray] | None:
    """Box in ``solid``'s frame holding the partner's bounding sphere at every state searched."""
    if solid.bound is not None or partner.bound is None:
        return None
    centre, reach = partner.bound
    world = np.einsum("tij,j->ti", partner_rotation[states], centre) + partner_position[states]
    local = np.einsum("tji,tj->ti", rotation[states], world - position[states])
    return local.min(axis=0) - reach, local.max(axis=0) + reach


def _screen(sampled: Solid, rotation, translation, partner: Solid, states) -> np.ndarray:
    """Per state, a lower bound of the pair's signed distance valid where it is > 0: the
    partner's signed distance at the sampled shape's bounding-sphere centre minus its radius
    (-inf where the sampled shape is unbounded)."""
    if sampled.bound is None:
        return np.full(len(states), -np.inf)
    centre, reach = sampled.bound
    mapped = np.einsum("tij,j->ti", rotation[states], centre) + translation[states]
    return partner.distance(mapped)[0] - reach


def pair_gaps(shape_a, poses_a, shape_b, poses_b, resolution: float | None = None,
              floor=None, states=None, polish: bool = True,
              cells_per_state: int = CELLS_PER_STATE) -> PairGaps:
    """The instrument's reading of a pair at T configurations of its two bodies.

    Parameters
    ----------
    shape_a, shape_b : Shape
        ``scenarios.shapes`` objects placed in their bodies' frames.
    poses_a, poses_b : tuple (positions (T, 3), quaternions (T, 4))
        World poses of the two BODY frames [L] (quaternions w, x, y, z).
    resolution : float, optional
        Tolerance of the search [L] (default :func:`pair_resolution`).
    floor : float or ndarray (T,), optional
        Resolve values only below this [L]: where the signed distance is certainly above it,
        the search may stop with ``gap`` = +inf and ``lower`` >= floor.
    states : array of int, optional
        Configurations to read (default all); the others get gap = lower = +inf.
    polish : bool
        Refine each witness by a bounded local search (exact to round-off where the minimum
        is smooth); without it the gap is within ``resolution`` of the minimum all the same.
    cells_per_state : int
        The search's cap per configuration (:mod:`.search`); a reading stopped there has the
        larger resolution it reached.
    """
    a, b = Solid(shape_a), Solid(shape_b)
    do_ab, do_ba = _terms(a, b)
    position_a, rotation_a = shape_placements(shape_a, *poses_a)
    position_b, rotation_b = shape_placements(shape_b, *poses_b)
    count = len(position_a)
    states = np.arange(count) if states is None else np.asarray(states, dtype=np.int64)
    tolerance = pair_resolution(shape_a, shape_b) if resolution is None else float(resolution)
    floor = np.broadcast_to(np.asarray(np.inf if floor is None else floor, dtype=float),
                            (count,))
    gap = np.full(count, np.inf)
    lower = np.full(count, np.inf)
    point_a = np.full((count, 3), np.nan)
    point_b = np.full((count, 3), np.nan)
    witnessed_on = np.full(count, "", dtype="<U1")
    placed = {"a": (a, rotation_a, position_a), "b": (b, rotation_b, position_b)}
    terms = [name for name, wanted in (("a", do_ab), ("b", do_ba)) if wanted]
    # States whose bounding-sphere screen already puts the pair above the floor (and apart).
    screen = np.full(len(states), -np.inf)
    for name in terms:
        (solid, rotation, position), (other, other_rotation, other_position) = (
            placed[name], placed["b" if name == "a" else "a"])
        m, d = relative_transforms(rotation, position, other_rotation, other_position)
        screen = np.maximum(screen, _screen(solid, m, d, other, states))
    cleared = (screen > 0.0) & (screen >= floor[states])
    lower[states[cleared]] = screen[cleared]
    searched = states[~cleared]
    for name in terms:
        (solid, rotation, position), (other, other_rotation, other_position) = (
            placed[name], placed["b" if name == "a" else "a"])
        if not len(searched):
            break
        clip = _clip_box(solid, rotation, position, other, other_rotation, other_position,
                         searched)
        patches = boundary_patches(solid, clip)
        m, d = relative_transforms(rotation, position, other_rotation, other_position)
        result = minimise(patches, m, d, other, tolerance, floor, searched, polish,
                          cells_per_state)
        lower[searched] = np.minimum(lower[searched], result.lower[searched])
        better = searched[result.best[searched] < gap[searched]]
        if not len(better):
            continue
        gap[better] = result.best[better]
        local = result.witness[better]
        on_self = np.einsum("tij,tj->ti", rotation[better], local) + position[better]
        in_other = np.einsum("tij,tj->ti", m[better], local) + d[better]
        value, gradient = other.distance(in_other)
        foot = in_other - value[:, None] * gradient
        on_other = np.einsum("tij,tj->ti", other_rotation[better], foot) + other_position[better]
        own, partner = (point_a, point_b) if name == "a" else (point_b, point_a)
        own[better], partner[better] = on_self, on_other
        witnessed_on[better] = name
    lower = np.minimum(lower, gap)
    return PairGaps(gap, lower, point_a, point_b, witnessed_on)


def independent_gap(shape_a, pose_a, shape_b, pose_b, resolution: float | None = None
                    ) -> IndependentGap:
    """The instrument's signed distance between two shapes on posed bodies (module docstring).

    Parameters
    ----------
    shape_a, shape_b : Shape
        ``scenarios.shapes`` objects placed in their bodies' frames (a circle's or arc's
        optional ``tube_radius`` is honoured).
    pose_a, pose_b : tuple (position (3,), quaternion (4,))
        World pose of each BODY frame (length; quaternion w, x, y, z), as
        :func:`clearbench.scenarios.geometry.contacts_between` takes them.
    resolution : float, optional
        Tolerance of the search [L] (default :func:`pair_resolution`).

    Returns
    -------
    IndependentGap

    Raises
    ------
    ValueError
        For a pair of two unbounded shapes (plane, face or bore without depth) or an unknown
        kind, naming both shapes.
    """
    poses = []
    for position, quaternion in (pose_a, pose_b):
        poses.append((np.asarray(position, dtype=float)[None, :],
                      np.asarray(quaternion, dtype=float)[None, :]))
    result = pair_gaps(shape_a, poses[0], shape_b, poses[1], resolution)
    gap = float(result.gap[0])
    if not math.isfinite(gap):  # pragma: no cover - without a floor every state is searched
        raise RuntimeError("the instrument's search returned no witness")
    return IndependentGap(gap, float(gap - result.lower[0]), result.point_a[0].copy(),
                          result.point_b[0].copy(), str(result.witnessed_on[0]))
