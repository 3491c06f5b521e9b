"""Certified minimisation of a partner's signed distance over a patched surface.

Branch and bound on the parameter cells of :mod:`.surfaces`, for T configurations at once:
every cell is evaluated at its centre (the partner's exact signed distance f there: a real
point, so the smallest value seen is a witness, an upper bound of the minimum), and given a
lower bound of f over the whole cell:

- always f(centre) - (covering radius): a signed distance is 1-Lipschitz;
- for a convex partner also f(centre) - drop, where drop bounds how far the linear function
  gradient . (p - p_centre) falls over the cell (:meth:`.surfaces.Patch.drop`): a convex
  function lies above its tangent plane.

A cell whose lower bound is at least (best witness - tolerance), or at least the caller's
``floor`` (the search only needs to know that f stays above it there), is dropped; the others
are halved along their longer side. On exit every part of the surface is covered by a dropped
cell, so the minimum lies in [lower, best] with lower = the smallest bound of a dropped cell
>= min(best - tolerance, floor). The cells are capped (:data:`CELLS_PER_STATE` evaluated per
configuration searched, :data:`MAX_CELLS` alive in all at a level, :data:`MAX_LEVELS`
halvings);
a search stopped there reports the bound it reached, never the tolerance it aimed at. That
happens where a whole curve of the boundary is a minimum no bound can single out, the medial
surface of a solid (a ball sunk more than half through a slab: every point of a circle on it
is deepest).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from clearbench.harness.measure.instrument.solids import combine

#: Most cells evaluated per configuration searched, and alive at one level in all.
CELLS_PER_STATE = 300_000
MAX_CELLS = 2_000_000
#: Most levels of halving.
MAX_LEVELS = 120


@dataclass(frozen=True)
class SearchResult:
    """Per configuration (T,): the smallest value found ``best`` [L], its point ``witness``
    (T, 3) in the sampled shape's frame (NaN where no cell was searched), and ``lower`` [L],
    a certified lower bound of the minimum (``best`` itself where nothing is below the
    floor)."""

    best: np.ndarray
    witness: np.ndarray
    lower: np.ndarray


def _initial_cells(patches, states: np.ndarray):
    """Cells (state, patch, u, v, hu, hv) of the initial grids of every patch, for every
    state."""
    columns = [[], [], [], [], [], []]
    for k, patch in enumerate(patches):
        u0, u1, v0, v1 = patch.domain
        nu, nv = patch.grid
        hu, hv = 0.5 * (u1 - u0) / nu, 0.5 * (v1 - v0) / nv
        uu, vv = np.meshgrid(u0 + (2 * np.arange(nu) + 1) * hu, v0 + (2 * np.arange(nv) + 1) * hv,
                             indexing="ij")
        count = uu.size
        columns[0].append(np.repeat(states, count))
        columns[1].append(np.full(count * len(states), k))
        columns[2].append(np.tile(uu.ravel(), len(states)))
        columns[3].append(np.tile(vv.ravel(), len(states)))
        columns[4].append(np.full(count * len(states), hu))
        columns[5].append(np.full(count * len(states), hv))
    return [np.concatenate(c) for c in columns]


def minimise(patches, rotation: np.ndarray, translation: np.ndarray, partner, tolerance,
             floor=None, states=None, polish: bool = True,
             cells_per_state: int = CELLS_PER_STATE) -> SearchResult:
    """Minimise the partner's signed distance over the patches at T configurations.

    Parameters
    ----------
    patches : list of :class:`~.surfaces.Patch`
        The sampled shape's boundary, in its own frame.
    rotation, translation : ndarray (T, 3, 3), (T, 3)
        The map q = rotation p + translation from the sampled shape's frame to the partner's,
        per configuration [L].
    partner : :class:`~.solids.Solid`
    tolerance : float or ndarray (T,)
        Resolution aimed at [L] (> 0).
    floor : ndarray (T,), optional
        Values the caller needs resolved only below this [L]: a cell whose lower bound is above
        it is dropped (default: +inf, resolve everything).
    states : ndarray of int, optional
        Configurations to search (default all); the others keep best = lower = +inf.
    polish : bool
        Refine the witness by a bounded local search (:func:`_polish`); the certified bound
        does not depend on it.
    cells_per_state : int
        The budget of cells evaluated per configuration (the search stops there and reports
        the bound it reached).
    """
    count = len(rotation)
    tolerance = np.broadcast_to(np.asarray(tolerance, dtype=np.float64), (count,))
    floor = (np.full(count, np.inf) if floor is None
             else np.broadcast_to(np.asarray(floor, dtype=np.float64), (count,)))
    states = np.arange(count) if states is None else np.asarray(states, dtype=np.int64)
    best = np.full(count, np.inf)
    witness = np.full((count, 3), np.nan)
    lower = np.full(count, np.inf)
    at = np.zeros((count, 4))  # patch index, u, v, covering radius of the best cell
    if not len(patches) or not len(states):
        return SearchResult(best, witness, lower)
    state, patch_index, u, v, hu, hv = _initial_cells(patches, states)
    cap = min(MAX_CELLS, cells_per_state * len(states))
    work = np.zeros(count, dtype=np.int64)
    rotation_t = np.swapaxes(rotation, 1, 2)
    for _level in range(MAX_LEVELS):
        values = np.empty(len(state))
        bounds = np.empty(len(state))
        wide_u = np.empty(len(state), dtype=bool)
        points = np.empty((len(state), 3))
        radii = np.empty(len(state))
        for k, patch in enumerate(patches):
            rows = np.nonzero(patch_index == k)[0]
            if not len(rows):
                continue
            s, uk, vk, huk, hvk = state[rows], u[rows], v[rows], hu[rows], hv[rows]
            local = patch.points(uk, vk)
            mapped = np.einsum("nij,nj->ni", rotation[s], local) + translation[s]
            f, gradient = partner.distance(mapped)
            su, sv = patch.speeds(uk, vk, huk, hvk)
            radius = np.hypot(su * huk, sv * hvk)
            bound = f - radius
            split_u = su * huk >= sv * hvk  # the Lipschitz bound: halve the longer side
            # How far the cell reaches across the partner's z axis (its xy-plane): what the
            # curved models need (|D_xy|), often far less than the covering radius.
            across = radius
            if partner.curved_models:
                axes = rotation_t[s]  # columns: the partner's axes in the patch's frame
                reach_x = sum(patch.extent(axes[:, :, 0], uk, vk, huk, hvk))
                reach_y = sum(patch.extent(axes[:, :, 1], uk, vk, huk, hvk))
                across = np.minimum(radius, np.hypot(reach_x, reach_y))
            factors = partner.lower_models(mapped, f, gradient, across)
            if factors:
                model, loss_u, loss_v = _factor_bounds(factors, patch, rotation_t[s], uk, vk,
                                                       huk, hvk, su * huk, sv * hvk)
                for normal, offset in partner.half_spaces():
                    # The solid lies in {n . q <= c}: its signed distance is >= n . q - c.
                    n_local = np.einsum("nij,j->ni", rotation_t[s], normal)
                    part_u, part_v = patch.drop(n_local, uk, vk, huk, hvk)
                    plane = mapped @ normal - offset - part_u - part_v
                    wins = plane > model
                    model = np.where(wins, plane, model)
                    loss_u = np.where(wins, part_u, loss_u)
                    loss_v = np.where(wins, part_v, loss_v)
                better = model > bound
                bound = np.where(better, model, bound)
                # Halve the side that loses most where the losses make the bound's slack;
                # where the model itself is loose (a superset far from the solid), the
                # metric's longer side: smaller cells are what the Lipschitz bound needs.
                losses = loss_u + loss_v
                by_loss = np.where((losses > 0.0) & (2.0 * losses >= f - model),
                                   loss_u >= loss_v, split_u)
                split_u = np.where(better, by_loss, split_u)
            values[rows], bounds[rows], points[rows], radii[rows] = f, bound, local, radius
            wide_u[rows] = split_u
        order = np.lexsort((values, state))
        first = order[np.r_[True, state[order][1:] != state[order][:-1]]]
        improved = values[first] < best[state[first]]
        best[state[first[improved]]] = values[first[improved]]
        witness[state[first[improved]]] = points[first[improved]]
        chosen = first[improved]
        at[state[chosen]] = np.stack([patch_index[chosen], u[chosen], v[chosen],
                                      radii[chosen]], axis=1)
        threshold = np.minimum(best[state] - tolerance[state], floor[state])
        dropped = bounds >= threshold
        np.minimum.at(lower, state[dropped], bounds[dropped])
        keep = ~dropped
        # A configuration whose evaluated cells would pass its budget stops here with the
        # bound it reached.
        work += np.bincount(state, minlength=count)
        alive = np.bincount(state[keep], minlength=count)
        stopped = keep & (work[state] + 2 * alive[state] > cells_per_state)
        if stopped.any():
            np.minimum.at(lower, state[stopped], bounds[stopped])
            keep &= ~stopped
        if not keep.any():
            break
        if _level == MAX_LEVELS - 1 or 2 * np.count_nonzero(keep) > cap:
            np.minimum.at(lower, state[keep], bounds[keep])
            break
        state, patch_index, u, v, hu, hv, wide = (state[keep], patch_index[keep], u[keep],
                                                  v[keep], hu[keep], hv[keep], wide_u[keep])
        hu = np.where(wide, 0.5 * hu, hu)
        hv = np.where(wide, hv, 0.5 * hv)
        shift_u = np.where(wide, hu, 0.0)
        shift_v = np.where(wide, 0.0, hv)
        state = np.concatenate([state, state])
        patch_index = np.concatenate([patch_index, patch_index])
        u = np.concatenate([u - shift_u, u + shift_u])
        v = np.concatenate([v - shift_v, v + shift_v])
        hu = np.concatenate([hu, hu])
        hv = np.concatenate([hv, hv])
    # Polish where it can matter: every state without a floor, and the states whose minimum
    # may lie below their floor.
    if polish:
        _polish(patches, rotation, translation, partner, best, witness, at,
                ~np.isfinite(floor) | (lower < floor))
    lower = np.minimum(lower, best)
    return SearchResult(best, witness, lower)


def _factor_bounds(factors, patch, to_local, u, v, hu, hv, metric_u, metric_v):
    """Lower bound (N,) of the partner's signed distance over the cells from its lower models
    (:meth:`~.solids.Solid.lower_models`), and how much of the bound's loss halving the u
    or the v side would address (N,), (N,). ``metric_u``, ``metric_v``: the cells' half-sides
    [L] (a model that fails for a cell this large, curvature inf, loses in proportion)."""
    bounds, losses = [], []
    for models in factors:
        best = np.full(len(u), -np.inf)
        best_u, best_v = np.zeros(len(u)), np.zeros(len(u))
        for value0, n, curvature, w in models:
            if patch.is_curve:
                part_u = patch.curve_drop(np.einsum("nij,nj->ni", to_local, n), curvature,
                                          np.einsum("nij,nj->ni", to_local, w), u, hu)
                part_v = np.zeros(len(u))
                model = value0 - part_u
                better = model > best
                best = np.where(better, model, best)
                best_u = np.where(better, part_u, best_u)
                continue
            if patch.kind == "planar" and np.any(curvature < 0.0):
                gain = np.minimum(curvature, 0.0)
                part_u, part_v = patch.planar_drop(np.einsum("nij,nj->ni", to_local, n), gain,
                                                   np.einsum("nij,nj->ni", to_local, w), hu, hv)
                model = value0 - part_u - part_v
                better = model > best
                best = np.where(better, model, best)
                best_u = np.where(better, part_u, best_u)
                best_v = np.where(better, part_v, best_v)
                continue
            curvature = np.maximum(curvature, 0.0)  # a gain is left out on other surfaces
            part_u, part_v = patch.drop(np.einsum("nij,nj->ni", to_local, n), u, v, hu, hv)
            curved = curvature > 0.0
            if curved.any():
                # (w . (q - p))^2 <= extent^2, extent = the drop of w over the cell.
                extent_u, extent_v = patch.extent(np.einsum("nij,nj->ni", to_local, w), u, v,
                                                  hu, hv)
                extent = extent_u + extent_v
                with np.errstate(invalid="ignore"):  # inf curvature: replaced below
                    quad = np.where(curved, 0.5 * curvature * extent**2, 0.0)
                share = extent_u / np.where(extent > 0.0, extent, 1.0)
                part_u, part_v = part_u + quad * share, part_v + quad * (1.0 - share)
                failed = np.isinf(curvature)
                wide = metric_u >= metric_v
                part_u = np.where(failed, np.where(wide, np.inf, 0.0), part_u)
                part_v = np.where(failed, np.where(wide, 0.0, np.inf), part_v)
            model = value0 - part_u - part_v
            better = model > best
            best = np.where(better, model, best)
            best_u, best_v = np.where(better, part_u, best_u), np.where(better, part_v, best_v)
        bounds.append(best)
        losses.append((best_u, best_v))
    if len(bounds) == 1:
        return bounds[0], *losses[0]
    stacked = np.stack(bounds, axis=1)
    # The factors that make the combined value: the positive ones, else the largest.
    counts = (stacked > 0.0) | ((stacked.max(axis=1, keepdims=True) <= 0.0)
                                & (stacked == stacked.max(axis=1, keepdims=True)))
    loss_u = sum(np.where(counts[:, i], part[0], 0.0) for i, part in enumerate(losses))
    loss_v = sum(np.where(counts[:, i], part[1], 0.0) for i, part in enumerate(losses))
    return combine(stacked), loss_u, loss_v


#: Iterations and trial steps per iteration of the witness's local search.
POLISH_ITERATIONS = 12
POLISH_TRIALS = 8


def _polish(patches, rotation, translation, partner, best, witness, at, wanted) -> None:
    """Bounded local search from each configuration's best cell: steepest descent of the exact
    signed distance along the patch (the partner's gradient projected on the patch's
    tangents), each step the best of :data:`POLISH_TRIALS` lengths halving from twice the
    cell's covering radius, the parameters kept in the patch's domain. It only moves the
    witness to a real point with a smaller value (``best`` and ``witness`` updated in place);
    the certified lower bound is the search's. ``wanted`` (T,): the states to polish."""
    for k, patch in enumerate(patches):
        rows = np.nonzero(wanted & np.isfinite(best) & (at[:, 0] == k))[0]
        if not len(rows):
            continue
        u0, u1, v0, v1 = patch.domain
        u, v, step = at[rows, 1].copy(), at[rows, 2].copy(), 2.0 * at[rows, 3]
        value = best[rows].copy()
        m, d = rotation[rows], translation[rows]
        factors = 0.5 ** np.arange(POLISH_TRIALS)
        for _ in range(POLISH_ITERATIONS):
            mapped = np.einsum("nij,nj->ni", m, patch.points(u, v)) + d
            _, gradient = partner.distance(mapped)
            n = np.einsum("nji,nj->ni", m, gradient)
            tu, tv = patch.tangents(u, v)
            su2, sv2 = np.sum(tu * tu, axis=1), np.sum(tv * tv, axis=1)
            gu, gv = np.sum(n * tu, axis=1), np.sum(n * tv, axis=1)
            du = np.where(su2 > 0.0, -gu / np.where(su2 > 0.0, su2, 1.0), 0.0)
            dv = np.where(sv2 > 0.0, -gv / np.where(sv2 > 0.0, sv2, 1.0), 0.0)
            length = np.sqrt(du * du * su2 + dv * dv * sv2)
            moving = length > 0.0
            du = np.where(moving, du / np.where(moving, length, 1.0), 0.0)
            dv = np.where(moving, dv / np.where(moving, length, 1.0), 0.0)
            t = step[:, None] * factors[None, :]  # (n, trials)
            tu_ = np.clip(u[:, None] + t * du[:, None], u0, u1).ravel()
            tv_ = np.clip(v[:, None] + t * dv[:, None], v0, v1).ravel()
            trial = np.einsum("nij,nj->ni", np.repeat(m, POLISH_TRIALS, axis=0),
                              patch.points(tu_, tv_)) + np.repeat(d, POLISH_TRIALS, axis=0)
            values = partner.distance(trial)[0].reshape(len(rows), POLISH_TRIALS)
            pick = np.argmin(values, axis=1)
            found = values[np.arange(len(rows)), pick]
            better = found < value
            index = np.arange(len(rows)) * POLISH_TRIALS + pick
            u = np.where(better, tu_[index], u)
            v = np.where(better, tv_[index], v)
            value = np.where(better, found, value)
            step = np.where(better, 2.0 * t[np.arange(len(rows)), pick],
                            step * factors[-1] ** 2)
        improved = value < best[rows]
        best[rows[improved]] = value[improved]
        witness[rows[improved]] = patch.points(u[improved], v[improved])
