"""The projection stage of the combined projection scheme, compiled whole.

The same Gauss–Newton projection as ``MoreauJeanStepper._project`` (rows of the joints,
drivers and active contacts at the current configuration; contacts that carry an impulse as
equalities, the others unilateral; the multipliers of the mixed LCP by the active-set method
of :func:`projection.solve_projection`; the correction dq = Mp^-1 H^T delta halved until the
largest violation decreases), with the candidates, the rows, the Delassus operator, the
least-squares solves and the orientation update in one numba call per projection. The
corrections of one projection together move no point by more than :data:`PROJECTION_REACH`
times the violation it set out to remove.

The system's arrays travel as one tuple, :func:`geometry_arrays` (the order is the argument
order of :func:`constraints.contact_candidates` and :func:`constraints.bilateral_rows`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from clearbench.ref_solver.constraints import (
    bilateral_rows,
    contact_candidates,
    contact_rows,
    delassus,
)
from clearbench.ref_solver.forces import rotation_matrices
from clearbench.ref_solver.gyroscopic import integrate_orientations
from clearbench.scenarios.geometry import MAX_CONTACTS_PER_PAIR

#: Halvings of a projection correction that does not reduce the largest violation before the
#: projection gives up (a correction scaled by 2^-8 that still does not help is not a descent).
MAX_PROJECTION_HALVINGS = 8
#: Active-set iterations of the multipliers' mixed LCP.
MAX_ACTIVE_SET_ITERATIONS = 50
#: Largest displacement of a body's points over one projection (the sum of its accepted
#: corrections), as a multiple of the largest violation it set out to remove
#: (:func:`correction_budget`). A Gauss–Newton correction is the least motion (in the
#: projection's metric) that removes the linearised violations; it is far larger than them only
#: where the rows are nearly dependent and their values not compatible (redundant contacts of
#: clearance joints closed with impulse together with a stop's contacts), and there it follows
#: a direction the linearisation does not describe: the correction that moved the C-60's hook by
#: 13.9 mm and turned it by 2.07 rad in one step to remove a violation of 2.1 um (``c60-trip``,
#: variant ``paper-table-4``, 16 us, step 706) met the active rows again at other candidates,
#: and the run went on with the mechanism taken apart. The C-60's projections at 1 us move
#: points by far less (docs/reference-solver.md, "The projection's bound", measures them).
PROJECTION_REACH = 1000.0
#: A projection moving points by at most this fraction of the scene's length scale is never
#: bounded: near convergence (violations of 1e-12 mm) the corrections of redundant rows read
#: 1e-7 mm on the C-60, the round-off of the rows' directions, not a departure from the
#: linearisation.
CORRECTION_FLOOR = 1e-6


def geometry_arrays(system) -> tuple:
    """The arrays of ``system`` (a :class:`~.system.MultibodySystem`) that the compiled rows
    and candidates need, as one tuple (see the module docstring)."""
    s = system
    return (s.body_fixed, s.shape_kind, s.shape_parameters, s.shape_body, s.shape_position,
            s.shape_rotation, s.pair_shape_a, s.pair_shape_b, s.pair_offset, s.joint_kind,
            s.joint_body_a, s.joint_body_b, s.joint_anchor_a, s.joint_anchor_b,
            s.joint_frame_a, s.joint_axis_b, s.joint_relative_rotation, s.driver_body,
            s.driver_component, s.driver_quantity, s.driver_start, s.driver_times,
            s.driver_values, s.driver_initial, s.driver_reference)


@njit(cache=True)
def candidates(arrays, x, rotation):
    """Every pair's contact candidates at (x (nb, 3), rotation (nb, 3, 3)): (gap (npair, K),
    point_a, point_b (npair, K, 3), frame (npair, K, 3, 3), count (npair,))."""
    return selected_candidates(arrays, x, rotation, np.ones(arrays[6].shape[0], np.bool_))


@njit(cache=True)
def selected_candidates(arrays, x, rotation, selected):
    """:func:`candidates` of the pairs with ``selected`` (npair,) bool set; the others have no
    candidate (count 0, gap inf)."""
    npair = arrays[6].shape[0]
    k = MAX_CONTACTS_PER_PAIR
    gap = np.full((npair, k), np.inf)
    point_a = np.zeros((npair, k, 3))
    point_b = np.zeros((npair, k, 3))
    frame = np.zeros((npair, k, 3, 3))
    count = np.zeros(npair, dtype=np.int64)
    if npair:
        contact_candidates(x, rotation, arrays[1], arrays[2], arrays[3], arrays[4], arrays[5],
                           arrays[6], arrays[7], arrays[8], gap, point_a, point_b, frame, count,
                           selected)
    return gap, point_a, point_b, frame, count


#: Round-off of a contact's gap relative to the scene's largest feature length: a gap is
#: computed from world positions through rotations and the gap kernel's nearest points, and
#: varies by hundreds of units in the last place of that length from step to step (measured:
#: closed slots at rest whose gap after the velocity stage is 1e-13 to 1e-12 mm on the C-60,
#: largest feature 7.8 mm, on the half-speed trip test's python loop). 1e-10 of the length
#: (7.8e-10 mm there) is over 700 times the largest of those, and 1e-7 or less of a change of
#: candidate that :func:`closed_gap_limit` exists to catch (0.06 mm on the C-60's trip).
GAP_ROUNDOFF = 1e-10


def closed_gap_slack(position_tolerance, length_scale):
    """The slack [L] of :func:`closed_gap_limit`: the projection's ``position_tolerance`` [L]
    or the gaps' round-off (:data:`GAP_ROUNDOFF` of the scene's ``length_scale`` [L]), the
    larger. Without the round-off, a closed slot at rest whose gap after the velocity stage
    is a few 1e-13 mm read as having taken another candidate and was left unilateral."""
    return max(position_tolerance, GAP_ROUNDOFF * length_scale)


@njit(cache=True)
def closed_gap_limit(gap_start, velocity_start, velocity_end, h, slack):
    """The largest gap [L] at which a contact slot that closed in the velocity stage still holds
    that contact at the projection: its gap at the step's start ``gap_start`` (0 if
    penetrating) plus twice the travel of its points relative to each other over the step, h
    (|velocity_start| + |velocity_end|) ([L/T], the contact-frame relative velocities at the
    step's start and end, 3-vectors), plus ``slack`` [L] (:func:`closed_gap_slack`). The
    same contact's gap changes by at most h times the larger of the two speeds, and by the
    curvature of its surfaces by less again while a step's travel is below their radii; the
    factor 2 covers both. A slot whose
    gap exceeds it holds another candidate (the gap kernel's slot took another point while the
    bodies moved, as a ring's minimum slot does when the minimum it held vanishes): Eq. (21)'s
    equality g = 0 would pull that point onto the face, a jump of the body by its gap."""
    speed_start = math.sqrt(velocity_start[0] ** 2 + velocity_start[1] ** 2
                            + velocity_start[2] ** 2)
    speed_end = math.sqrt(velocity_end[0] ** 2 + velocity_end[1] ** 2 + velocity_end[2] ** 2)
    return max(gap_start, 0.0) + 2.0 * h * (speed_start + speed_end) + slack


@njit(cache=True)
def projection_rows(arrays, n_bilateral, t, x, p, active, closed):
    """Rows of the projection at (x, p): (row_body (m, 2), row_coef (m, 2, 6), values (m,)
    [L], n_equal, worst [L]), as ``MoreauJeanStepper._violations``: bilateral rows and the
    normal rows of the active contacts that hold a candidate here, equalities (bilateral rows,
    contacts whose gap here is at most their ``closed`` (npair, K) [L]: :func:`closed_gap_limit`
    of those that closed in the velocity stage, -inf for the others) first, then the unilateral
    rows, each group in row order; ``worst``
    is the largest equality violation or penetration."""
    rotation = rotation_matrices(p)
    # Only the pairs with an active slot make rows: the others are not evaluated.
    npair = active.shape[0]
    selected = np.zeros(npair, dtype=np.bool_)
    for k in range(npair):
        for s in range(active.shape[1]):
            selected[k] = selected[k] or active[k, s]
    gap, point_a, point_b, frame, count = selected_candidates(arrays, x, rotation, selected)
    n_selected = 0
    for k in range(npair):
        for s in range(gap.shape[1]):
            if active[k, s] and s < count[k]:
                n_selected += 1
    pairs = np.empty(n_selected, dtype=np.int64)
    slots = np.empty(n_selected, dtype=np.int64)
    c = 0
    for k in range(npair):
        for s in range(gap.shape[1]):
            if active[k, s] and s < count[k]:
                pairs[c] = k
                slots[c] = s
                c += 1
    m_all = n_bilateral + 3 * n_selected
    body_all = np.full((m_all, 2), -1, dtype=np.int64)
    coef_all = np.zeros((m_all, 2, 6))
    violation = np.zeros(m_all)
    if n_bilateral:
        target = np.zeros(m_all)
        bilateral_rows(t, x, p, rotation, arrays[0], arrays[9], arrays[10], arrays[11],
                       arrays[12], arrays[13], arrays[14], arrays[15], arrays[16], arrays[17],
                       arrays[18], arrays[19], arrays[20], arrays[21], arrays[22], arrays[23],
                       arrays[24], body_all, coef_all, violation, target)
    if n_selected:
        contact_rows(x, rotation, arrays[0], arrays[3], arrays[6], arrays[7], pairs, slots,
                     point_a, point_b, frame, body_all, coef_all, n_bilateral)
    n_equal = n_bilateral
    for c in range(n_selected):
        if gap[pairs[c], slots[c]] <= closed[pairs[c], slots[c]]:
            n_equal += 1
    m = n_bilateral + n_selected
    order = np.empty(m, dtype=np.int64)
    values = np.empty(m)
    for i in range(n_bilateral):
        order[i] = i
        values[i] = violation[i]
    equal_fill = n_bilateral
    unilateral_fill = n_equal
    for c in range(n_selected):
        value = gap[pairs[c], slots[c]]
        if value <= closed[pairs[c], slots[c]]:
            order[equal_fill] = n_bilateral + 3 * c
            values[equal_fill] = value
            equal_fill += 1
        else:
            order[unilateral_fill] = n_bilateral + 3 * c
            values[unilateral_fill] = value
            unilateral_fill += 1
    worst = 0.0
    for i in range(n_equal):
        worst = max(worst, abs(values[i]))
    for i in range(n_equal, m):
        worst = max(worst, -values[i])
    row_body = np.empty((m, 2), dtype=np.int64)
    row_coef = np.empty((m, 2, 6))
    for i in range(m):
        row_body[i] = body_all[order[i]]
        row_coef[i] = coef_all[order[i]]
    return row_body, row_coef, values, n_equal, worst


@njit(cache=True)
def active_set_multipliers(W, b, n_equal, tolerance, max_iterations):
    """:func:`projection.solve_projection` compiled: (delta (m,), converged)."""
    m = b.shape[0]
    active = np.zeros(m, dtype=np.bool_)
    for i in range(m):
        active[i] = i < n_equal or b[i] < 0.0
    delta = np.zeros(m)
    for _ in range(max_iterations):
        delta[:] = 0.0
        n_active = 0
        for i in range(m):
            if active[i]:
                n_active += 1
        if n_active:
            idx = np.empty(n_active, dtype=np.int64)
            c = 0
            for i in range(m):
                if active[i]:
                    idx[c] = i
                    c += 1
            sub = np.empty((n_active, n_active))
            rhs = np.empty(n_active)
            for a in range(n_active):
                rhs[a] = -b[idx[a]]
                for c in range(n_active):
                    sub[a, c] = W[idx[a], idx[c]]
            solution = np.linalg.lstsq(sub, rhs, rcond=1e-12)[0]
            for a in range(n_active):
                delta[idx[a]] = solution[a]
        # Drop the unilateral row that pulls most (negative multiplier), if any.
        pulling = -1
        for i in range(n_equal, m):
            if active[i] and delta[i] < 0.0 and (pulling < 0 or delta[i] < delta[pulling]):
                pulling = i
        if pulling >= 0:
            active[pulling] = False
            continue
        violated = -1
        worst = 0.0
        for i in range(n_equal, m):
            if active[i]:
                continue
            w_i = b[i]
            for j in range(m):
                w_i += W[i, j] * delta[j]
            if w_i < -tolerance and (violated < 0 or w_i < worst):
                violated = i
                worst = w_i
        if violated < 0:
            return delta, True
        active[violated] = True
    return delta, False


@njit(cache=True)
def correction_budget(worst, length_scale):
    """Largest displacement [L] of a body's points over a projection that set out to remove a
    largest violation ``worst`` [L]: :data:`PROJECTION_REACH` times it, plus
    :data:`CORRECTION_FLOOR` times the scene's ``length_scale`` [L]."""
    return PROJECTION_REACH * worst + CORRECTION_FLOOR * length_scale


@njit(cache=True)
def correction_size(delta, length_scale):
    """Largest displacement [L] of a body's points under the correction ``delta`` (nb, 6)
    (translations [L], rotation vectors [rad]): |dx| + r |dtheta| over the bodies, with r the
    scene's ``length_scale`` [L] (its largest feature: a turn counts as the motion of a point
    that far from the centre of mass; constraint points can lie farther, 21 mm on the C-60's
    bodies against its 7.8 mm, and move more than counted)."""
    size = 0.0
    for b in range(delta.shape[0]):
        translation = math.sqrt(delta[b, 0] ** 2 + delta[b, 1] ** 2 + delta[b, 2] ** 2)
        rotation = math.sqrt(delta[b, 3] ** 2 + delta[b, 4] ** 2 + delta[b, 5] ** 2)
        size = max(size, translation + length_scale * rotation)
    return size


@njit(cache=True)
def project(arrays, n_bilateral, t, x, p, active, closed, metric_inverse, cluster,
            cluster_dofs, cluster_start, position_tolerance, max_iterations, length_scale):
    """Globalised Gauss–Newton projection of (x (nb, 3), p (nb, 4)) in place (see the module
    docstring); its corrections together move no body's points by more than the budget of
    the largest violation at the start (:func:`correction_budget`, ``length_scale`` [L]): a
    correction beyond what is left of it is scaled to it, and the projection stops
    unconverged when it is spent. Returns (iterations, largest remaining violation [L],
    converged)."""
    fixed = arrays[0]
    nb = x.shape[0]
    row_body, row_coef, values, n_equal, worst = projection_rows(
        arrays, n_bilateral, t, x, p, active, closed)
    budget = correction_budget(worst, length_scale)
    for iteration in range(max_iterations + 1):
        if worst <= position_tolerance or values.size == 0:
            return iteration, worst, True
        if iteration == max_iterations:
            break
        m = values.size
        w, y = delassus(row_body, row_coef, m, metric_inverse, cluster, cluster_dofs,
                        cluster_start)
        multipliers, _ = active_set_multipliers(w, values, n_equal, 0.1 * position_tolerance,
                                                MAX_ACTIVE_SET_ITERATIONS)
        delta = np.zeros((nb, 6))
        for b in range(nb):
            for i in range(6):
                acc = 0.0
                for j in range(m):
                    acc += y[6 * b + i, j] * multipliers[j]
                delta[b, i] = acc
        size = correction_size(delta, length_scale)
        if size > budget:
            delta *= budget / size
            size = budget
        x0 = x.copy()
        p0 = p.copy()
        improved = False
        for _ in range(MAX_PROJECTION_HALVINGS + 1):
            x[:] = x0 + delta[:, :3]
            p[:] = integrate_orientations(p0, np.ascontiguousarray(delta[:, 3:]), fixed)
            trial = projection_rows(arrays, n_bilateral, t, x, p, active, closed)
            if trial[4] < worst:
                improved = True
                break
            delta *= 0.5
            size *= 0.5
        if not improved:
            x[:] = x0
            p[:] = p0
            return iteration + 1, worst, False
        row_body, row_coef, values, n_equal, worst = trial
        budget -= size
        if budget <= 0.0 and worst > position_tolerance:
            return iteration + 1, worst, False
    return max_iterations, worst, False
