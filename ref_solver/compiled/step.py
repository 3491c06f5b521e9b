"""One Moreau–Jean step with the combined projection, compiled: steps 1-5 of
:mod:`clearbench.ref_solver.stepper` (free velocity, velocity stage with the contact solve,
position update, projection, activation loop), as ``MoreauJeanStepper._single_step`` without
impact localisation, by the same kernels.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from clearbench.ref_solver.activation import RULE_GAP, RULE_HELD, first_round
from clearbench.ref_solver.compiled.contact_solve import solve
from clearbench.ref_solver.constraints import contact_rows, row_values
from clearbench.ref_solver.forces import rotation_matrices
from clearbench.ref_solver.gyroscopic import integrate_orientations
from clearbench.ref_solver.projection_kernel import candidates, closed_gap_limit, project
from clearbench.ref_solver.step_kernels import (
    crossing_fraction,
    free_velocity,
    velocity_problem,
)


@njit(cache=True)
def valid_slots(count, mask):
    """``mask`` (npair, K) restricted to the slots that hold a candidate (``count`` (npair,))."""
    out = mask.copy()
    for i in range(mask.shape[0]):
        for k in range(count[i], mask.shape[1]):
            out[i, k] = False
    return out


@njit(cache=True)
def _selected(mask):
    """(pairs, slots) int64 of the true entries of ``mask`` (npair, K), pair-major."""
    n = 0
    for i in range(mask.shape[0]):
        for k in range(mask.shape[1]):
            n += mask[i, k]
    pairs = np.empty(n, dtype=np.int64)
    slots = np.empty(n, dtype=np.int64)
    j = 0
    for i in range(mask.shape[0]):
        for k in range(mask.shape[1]):
            if mask[i, k]:
                pairs[j] = i
                slots[j] = k
                j += 1
    return pairs, slots


@njit(cache=True)
def _normal_velocities(s, x, rotation, cand, nu, free):
    """Normal velocities (npair, K) [L/T] of every candidate at the twists ``nu`` and ``free``
    (nb, 6) (``MoreauJeanStepper._normal_velocity``; the contact rows alone: they do not depend
    on the bilateral rows before them)."""
    at_start = np.zeros_like(cand[0])
    at_free = np.zeros_like(cand[0])
    pairs, slots = _selected(valid_slots(cand[4], np.ones(cand[0].shape, dtype=np.bool_)))
    nc = pairs.shape[0]
    if nc == 0:
        return at_start, at_free
    m = 3 * nc
    row_body = np.full((m, 2), -1, dtype=np.int64)
    row_coef = np.zeros((m, 2, 6))
    g = s.geometry
    contact_rows(x, rotation, s.fixed, g[3], g[6], g[7], pairs, slots, cand[1], cand[2],
                 cand[3], row_body, row_coef, 0)
    values_start = row_values(row_body, row_coef, nu, 0, m)
    values_free = row_values(row_body, row_coef, free, 0, m)
    for c in range(nc):
        at_start[pairs[c], slots[c]] = values_start[3 * c]
        at_free[pairs[c], slots[c]] = values_free[3 * c]
    return at_start, at_free


@njit(cache=True)
def first_round_active(s, cfg, h, x, rotation, cand, nu, free, previous):
    """(npair, K) bool: the contacts of the first activation round of a step of length ``h``
    [T] under ``cfg.activation_rule`` (:func:`clearbench.ref_solver.activation.first_round`);
    ``previous`` (npair, K, 3) the previous step's impulses."""
    if cfg.activation_rule == RULE_GAP:
        return valid_slots(cand[4], cand[0] <= cfg.activation_margin)
    if cfg.activation_rule == RULE_HELD:
        u_start = u_free = np.zeros_like(cand[0])   # not read by the rule
    else:
        u_start, u_free = _normal_velocities(s, x, rotation, cand, nu, free)
    active = first_round(
        cfg.activation_rule, cand[0], u_start, u_free, previous, h, cfg.theta,
        cfg.activation_margin, cfg.activation_hold, s.pair_restitution,
        cfg.restitution_threshold)
    return valid_slots(cand[4], active)


@njit(cache=True)
def _finite(a):
    for value in a.ravel():
        if not np.isfinite(value):
            return False
    return True


@njit(cache=True)
def _velocity_stage(s, cfg, memory, t, h, x, p, v, omega, rotation, nu, free, inverse, cand,
                    active, history):
    """``MoreauJeanStepper._velocity_stage``: (x, p, v, omega at t + h, impulses
    (npair, K, 3), closed (npair, K) [L]: the gap up to which a contact that stays closed is
    an equality of the projection, -inf for the others; solver iterations, residual,
    converged, sweeps)."""
    previous_impulse, previous_bilateral, newton_first = memory[0], memory[1], memory[2]
    theta = cfg.theta
    pairs, slots = _selected(valid_slots(cand[4], active))
    nc = pairs.shape[0]
    nbil = s.n_bilateral
    m = nbil + 3 * nc
    new_nu = free.copy()
    impulses = np.zeros_like(previous_impulse)
    closed = np.full(active.shape, -np.inf)
    iterations, residual, converged, sweeps = 0, 0.0, True, 0
    if m:
        w, y, q, row_body, row_coef, _, _ = velocity_problem(
            s.geometry, nbil, s.n_joint_rows, t + h, h, theta, x, p, v, omega, rotation,
            cand[1], cand[2], cand[3], pairs, slots, nu, free, inverse, s.cluster,
            s.cluster_dofs, s.cluster_start, s.pair_restitution, cfg.restitution_threshold,
            cfg.midpoint_joints)
        if not (_finite(q) and _finite(w)):
            raise ValueError("the one-step contact problem has a non-finite W or q")
        r0 = np.empty(m)
        r0[:nbil] = previous_bilateral
        mu = np.empty(nc)
        for c in range(nc):
            mu[c] = s.pair_friction[pairs[c]]
            for a in range(3):
                r0[nbil + 3 * c + a] = previous_impulse[pairs[c], slots[c], a]
        r, iterations, residual, converged = solve(w, q, mu, nbil, r0, cfg, newton_first,
                                                   history)
        sweeps = iterations * nc
        new_nu = free + (y @ r).reshape(-1, 6)
        previous_bilateral[:] = r[:nbil]
        for c in range(nc):
            for a in range(3):
                impulses[pairs[c], slots[c], a] = r[nbil + 3 * c + a]
        if nc:
            # Contacts that stay closed: a normal impulse and no rebound (see the stepper),
            # with the gap up to which their slot still holds them.
            u_new = row_values(row_body, row_coef, new_nu, nbil, m)
            u_start = row_values(row_body, row_coef, nu, nbil, m)
            largest = 0.0
            for c in range(nc):
                largest = max(largest, abs(r[nbil + 3 * c]))
            floor = 1e-14 * max(largest, 1e-300)
            for c in range(nc):
                if r[nbil + 3 * c] > floor and u_new[3 * c] <= 0.5 * cfg.restitution_threshold:
                    closed[pairs[c], slots[c]] = closed_gap_limit(
                        cand[0][pairs[c], slots[c]], u_start[3 * c:3 * c + 3],
                        u_new[3 * c:3 * c + 3], h, cfg.closed_gap_slack)
    for b in range(s.fixed.shape[0]):
        if s.fixed[b]:
            new_nu[b] = 0.0
    v_theta = theta * new_nu + (1.0 - theta) * nu
    x_new = x + h * v_theta[:, :3]
    p_new = integrate_orientations(p, np.ascontiguousarray(h * v_theta[:, 3:]), s.fixed)
    return (x_new, p_new, new_nu[:, :3].copy(), new_nu[:, 3:].copy(), impulses, closed,
            iterations, residual, converged, sweeps)


@njit(cache=True)
def _projection_stage(s, cfg, t, x, p, active, closed):
    """``MoreauJeanStepper._projection_stage`` on (x, p) in place: (iterations, largest
    violation [L], converged); contacts of ``closed`` as equalities, retried unilateral."""
    start_x, start_p = x.copy(), p.copy()
    iterations, worst, converged = project(
        s.geometry, s.n_bilateral, t, x, p, active, closed, s.projection_inverse,
        s.single_cluster, s.single_dofs, s.single_start, cfg.position_tolerance,
        cfg.max_projection_iterations, cfg.length_scale)
    if converged or not np.isfinite(closed).any():
        return iterations, worst, converged
    best_worst, best_x, best_p = worst, x.copy(), p.copy()
    x[:] = start_x
    p[:] = start_p
    more, worst, converged = project(
        s.geometry, s.n_bilateral, t, x, p, active, np.full_like(closed, -np.inf),
        s.projection_inverse, s.single_cluster, s.single_dofs, s.single_start,
        cfg.position_tolerance, cfg.max_projection_iterations, cfg.length_scale)
    iterations += more
    if not converged and best_worst < worst:
        worst = best_worst
        x[:] = best_x
        p[:] = best_p
    return iterations, worst, converged


@njit(cache=True)
def _crossing(s, cfg, h, x, rotation, cand, cand_end, closing, nu, free):
    """The contacts that call for impact localisation among ``closing`` (npair, K) (open at
    the step's start, closed at the end of its first activation round): of a pair with
    restitution > 0, open at the start (finite gap > 0) and approaching faster than the
    restitution threshold. Returns (the crossing fraction of the earliest of them in (0, 1],
    +inf when there is none; their mask (npair, K)), as ``MoreauJeanStepper._crossing``."""
    mask = np.zeros_like(closing)
    earliest = np.inf
    u_start = np.zeros_like(cand[0])
    computed = False
    for i in range(closing.shape[0]):
        if not s.pair_restitution[i] > 0.0:
            continue
        for k in range(closing.shape[1]):
            start = cand[0][i, k]
            if not (closing[i, k] and np.isfinite(start) and start > 0.0):
                continue
            if not computed:
                u_start = _normal_velocities(s, x, rotation, cand, nu, free)[0]
                computed = True
            if u_start[i, k] < -cfg.restitution_threshold:
                mask[i, k] = True
                earliest = min(earliest, crossing_fraction(start, u_start[i, k] * h,
                                                           cand_end[0][i, k]))
    return earliest, mask


@njit(cache=True)
def _substep(s, cfg, memory, t, h, x, p, v, omega, history, cand, suppress, watch):
    """Steps 1-5 of the scheme over a step of length h >= 0 [T] from (t, x (nb, 3), p (nb, 4),
    v (nb, 3), omega (nb, 3)) (not modified), whose contact candidates are ``cand``
    (:func:`~clearbench.ref_solver.projection_kernel.candidates` at (x, p)), as
    ``MoreauJeanStepper._single_step``: ``suppress`` (npair, K) the contacts the activation loop
    must not add; ``watch``: when the first activation round closes contacts that call for
    impact localisation (:func:`_crossing`), stop there.

    Returns (x, p, v, omega at t + h, impulses (npair, K, 3) in the contact frames [F T], active
    (npair, K), solver iterations, residual, converged, projection converged, contact sweeps,
    the candidates at the returned (x, p), the crossing fraction (+inf: the step is complete;
    else the step was stopped and only its iterations and sweeps count), the crossing mask).
    The previous impulses of ``memory`` are those of the completed step.
    """
    theta = cfg.theta
    rotation = rotation_matrices(p)
    nb = x.shape[0]
    nu = np.empty((nb, 6))
    nu[:, :3] = v
    nu[:, 3:] = omega
    free, inverse, _ = free_velocity(
        t + theta * h, h, theta, x, p, rotation, v, omega, s.mass, s.inertia,
        s.inverse_inertia, s.gravity, s.fixed, s.force_kind, s.force_body_a, s.force_body_b,
        s.force_parameters, memory[3], s.has_springs, cfg.length_step, s.mass_matrix,
        s.inverse_mass, s.cluster_dofs, s.cluster_start)
    active = first_round_active(s, cfg, h, x, rotation, cand, nu, free, memory[0])
    iterations, sweeps, rounds = 0, 0, 0
    projection_converged = True
    cand_new = cand
    no_crossing = np.zeros_like(active)
    while True:
        rounds += 1
        (x_new, p_new, v_new, omega_new, impulses, closed, its, residual, converged,
         more_sweeps) = _velocity_stage(s, cfg, memory, t, h, x, p, v, omega, rotation, nu,
                                        free, inverse, cand, active, history)
        iterations += its
        sweeps += more_sweeps
        if not cfg.projection:
            cand_new = candidates(s.geometry, x_new, rotation_matrices(p_new))
            break
        _, _, projection_converged = _projection_stage(s, cfg, t + h, x_new, p_new, active,
                                                       closed)
        cand_new = candidates(s.geometry, x_new, rotation_matrices(p_new))
        closing = valid_slots(cand_new[4], cand_new[0] <= 0.0) & ~active & ~suppress
        if watch and rounds == 1 and closing.any():
            fraction, mask = _crossing(s, cfg, h, x, rotation, cand, cand_new, closing, nu,
                                       free)
            if fraction < np.inf:
                return (x_new, p_new, v_new, omega_new, impulses, active, iterations, 0.0,
                        True, True, sweeps, cand_new, fraction, mask)
        if not closing.any() or rounds >= cfg.max_activation_rounds:
            break
        active = active | closing
    previous_impulse = memory[0]
    previous_impulse[:] = 0.0
    for i in range(active.shape[0]):
        for k in range(active.shape[1]):
            if active[i, k]:
                previous_impulse[i, k] = impulses[i, k]
    return (x_new, p_new, v_new, omega_new, impulses, active, iterations, residual,
            converged, projection_converged, sweeps, cand_new, np.inf, no_crossing)


@njit(cache=True)
def _add_piece(world, frames, active, impulses, piece_frames, piece_active):
    """Adds a substep's impulses (npair, K, 3, contact frames ``piece_frames`` (npair, K, 3,
    3)) of its active contacts to ``world`` (npair, K, 3) (world axes); ``frames`` takes the
    piece's frames and ``active`` its contacts, as ``MoreauJeanStepper._combine``."""
    for i in range(world.shape[0]):
        for k in range(world.shape[1]):
            if piece_active[i, k]:
                for j in range(3):
                    world[i, k, j] += (impulses[i, k, 0] * piece_frames[i, k, 0, j]
                                       + impulses[i, k, 1] * piece_frames[i, k, 1, j]
                                       + impulses[i, k, 2] * piece_frames[i, k, 2, j])
                    for a in range(3):
                        frames[i, k, a, j] = piece_frames[i, k, a, j]
                active[i, k] = True


@njit(cache=True)
def single_step(s, cfg, memory, t, x, p, v, omega, history, cand):
    """One step of length ``cfg.time_step`` from (t, x (nb, 3), p (nb, 4), v (nb, 3), omega
    (nb, 3)) (not modified), whose contact candidates are ``cand``
    (:func:`~clearbench.ref_solver.projection_kernel.candidates` at (x, p)), with impact
    localisation when ``cfg.impact_splits`` > 0 (``MoreauJeanStepper._advance``: a step whose
    first activation round closes an impacting contact is redone as the free motion to the
    crossing, the impact as a step of zero length and the rest of the step, at most
    ``impact_splits`` times; the impulses of the pieces summed in world axes and given in the
    frames of each contact's last piece).

    ``memory`` = (previous impulses (npair, K, 3), previous bilateral impulses (nbil,), the
    hybrid chain's ``newton_first`` (1,)), the warm starts, updated in place. Returns (x, p, v,
    omega at t + h, impulses (npair, K, 3) in the contact frames [F T], frames (npair, K, 3, 3)
    of the contacts at the start of the step (of their last piece), active (npair, K), solver
    iterations, residual, converged, projection converged, contact sweeps, the candidates at
    the returned (x, p), whether the step was split). The last activation round's closing
    test computes those candidates; the next step starts from them instead of computing them
    again (the same kernel on the same state: the same values to the bit).
    """
    none = np.zeros(cand[0].shape, dtype=np.bool_)
    h = cfg.time_step
    splits = cfg.impact_splits
    result = _substep(s, cfg, memory, t, h, x, p, v, omega, history, cand, none, splits > 0)
    if result[12] == np.inf:
        return (result[0], result[1], result[2], result[3], result[4], cand[3], result[5],
                result[6], result[7], result[8], result[9], result[10], result[11], False)
    world = np.zeros_like(result[4])
    frames = cand[3].copy()
    active = np.zeros_like(none)
    # The abandoned first round's work counts in the cost, not in the convergence.
    iterations, residual, converged = result[6], 0.0, True
    projection_converged, sweeps = True, result[10]
    while True:
        # (a) The free motion to the crossing, the crossing contacts not activated; (b) the
        # impact at the crossing as a step of zero length, unless every crossing contact is
        # still open there (the rest of the step then takes it).
        fraction = min(result[12] * (1.0 + 1e-9) + 4.0 * np.finfo(np.float64).eps, 1.0)
        h1 = fraction * h
        mask = result[13]
        for piece_length, suppress in ((h1, mask), (0.0, none)):
            if piece_length == 0.0 and not (
                    valid_slots(cand[4], cand[0] <= cfg.activation_margin) & mask).any():
                break
            piece = _substep(s, cfg, memory, t, piece_length, x, p, v, omega, history, cand,
                             suppress, False)
            _add_piece(world, frames, active, piece[4], cand[3], piece[5])
            t = t + piece_length
            x, p, v, omega, cand = piece[0], piece[1], piece[2], piece[3], piece[11]
            iterations += piece[6]
            residual = max(residual, piece[7])
            converged = converged and piece[8]
            projection_converged = projection_converged and piece[9]
            sweeps += piece[10]
        if fraction >= 1.0:
            break
        # (c) The rest of the step, which may localise a later impact.
        h = h - h1
        splits -= 1
        result = _substep(s, cfg, memory, t, h, x, p, v, omega, history, cand, none,
                          splits > 0)
        iterations += result[6]
        sweeps += result[10]
        if result[12] == np.inf:
            _add_piece(world, frames, active, result[4], cand[3], result[5])
            residual = max(residual, result[7])
            converged = converged and result[8]
            projection_converged = projection_converged and result[9]
            x, p, v, omega, cand = result[0], result[1], result[2], result[3], result[11]
            break
    impulses = np.zeros_like(world)
    for i in range(world.shape[0]):
        for k in range(world.shape[1]):
            for a in range(3):
                impulses[i, k, a] = (frames[i, k, a, 0] * world[i, k, 0]
                                     + frames[i, k, a, 1] * world[i, k, 1]
                                     + frames[i, k, a, 2] * world[i, k, 2])
    return (x, p, v, omega, impulses, frames, active, iterations, residual, converged,
            projection_converged, sweeps, cand, True)
