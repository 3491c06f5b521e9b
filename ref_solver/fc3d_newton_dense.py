"""The semismooth Newton method of :mod:`fc3d_newton` for dense problems, compiled whole.

The same iteration as :func:`fc3d_newton.solve_newton` (Alart–Curnier function, regularised
direction (J + delta I) d = -Phi with delta from the residual, Armijo line search on
0.5 |Phi|^2, NSGS rescue sweeps when no descent step is found, natural-map residual and its
round-off floor as stopping tests), with the loop, the factorisations and the products in one
numba kernel: the reference stepper solves thousands of problems of tens of rows, where each
numpy call from Python costs more than its arithmetic.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from clearbench.ref_solver.contact_problem import (
    ContactProblem,
    SolverOptions,
    SolverResult,
    SolverStatus,
    _dense_to_csr,
)
from clearbench.ref_solver.dense_kernels import (
    bilateral_operator_dense,
    lu_solve,
    matvec_plus,
    residuals,
    roundoff_floor_dense,
)
from clearbench.ref_solver.fc3d_local import LOCAL_KIND
from clearbench.ref_solver.fc3d_newton_parts import (
    ARMIJO,
    DELTA_MAX,
    DELTA_MIN,
    MAX_HALVINGS,
    MAX_RESCUES,
    RESCUE_SWEEPS,
    alart_curnier_system,
    bilateral_scalings,
    contact_scalings,
    dense_jacobian,
)
from clearbench.ref_solver.fc3d_nsgs import nsgs_kernel
from clearbench.ref_solver.fc3d_residual import floor_message, hopeless

#: Status codes of :func:`newton_dense_kernel`.
CONVERGED, MAX_ITERATIONS, HOPELESS, NON_FINITE, NO_DESCENT, ROUNDOFF = range(6)
_AC = LOCAL_KIND["ac"]


@njit(cache=True)
def _dense_diagonal_blocks(W: np.ndarray, n_bilateral: int, n_contacts: int) -> np.ndarray:
    """(nc, 3, 3) diagonal contact blocks of a dense W."""
    blocks = np.empty((n_contacts, 3, 3))
    for i in range(n_contacts):
        k = n_bilateral + 3 * i
        for a in range(3):
            for c in range(3):
                blocks[i, a, c] = W[k + a, k + c]
    return blocks


@njit(cache=True)
def regularised_direction(W, n_bilateral, rho_b, A, B, phi, residual, J, d) -> bool:
    """d solving (J + delta I) d = -Phi, delta = min(1e-3, max(1e-12, residual)) grown by 100
    until the factorisation succeeds (at most 6 tries); False if none does."""
    delta = min(DELTA_MAX, max(DELTA_MIN, residual))
    minus_phi = -phi
    for _ in range(6):
        dense_jacobian(W, n_bilateral, rho_b, A, B, delta, J)
        if lu_solve(J, minus_phi, d):
            return True
        delta *= 100.0
    return False


@njit(cache=True)
def least_norm_direction(W, n_bilateral, rho_b, A, B, phi, J, d) -> bool:
    """d = the minimum-norm least-squares solution of J d = -Phi (singular values below 1e-10
    of the largest dropped); False if it is not finite.

    Redundant contacts (two rings of one journal, closed together) make W, hence J, singular
    with a null space of impulse distributions that change no velocity. The regularised
    direction then mixes a huge null-space component into the step and the line search crawls
    (thousands of iterations from 1e-9 to 1e-12); the least-norm direction leaves the null
    space alone and keeps Newton's convergence on the rest.
    """
    dense_jacobian(W, n_bilateral, rho_b, A, B, 0.0, J)
    solution = np.linalg.lstsq(J, -phi, rcond=1e-10)[0]
    for i in range(d.size):
        d[i] = solution[i]
        if not math.isfinite(d[i]):
            return False
    return True


@njit(cache=True)
def newton_dense_kernel(W, q, mu, n_bilateral, r, u, tolerance, use_max, max_iterations,
                        use_floor, stall_window, stall_after, local_tolerance,
                        local_max_iterations, history, least_norm=False):
    """Semismooth Newton on the dense problem (W (m, m), q (m,), mu (nc,), n_bilateral).

    The direction is :func:`regularised_direction`, or :func:`least_norm_direction` with
    ``least_norm``.

    ``r`` (m,) is the start and receives the result, ``u`` (m,) receives W r + q, ``history``
    (>= max_iterations,) the tested residual after each iteration. Returns (status code,
    iterations, residual in the tested normalisation, |F| / |q|, |F| / max, NSGS rescues,
    entries of history, the round-off floor of the last test (0 when not evaluated)).
    """
    m = q.size
    nc = mu.size
    rho_n, rho_t = contact_scalings(_dense_diagonal_blocks(W, n_bilateral, nc))
    diagonal = np.empty(n_bilateral)
    for b in range(n_bilateral):
        diagonal[b] = W[b, b]
    rho_b = bilateral_scalings(diagonal)
    phi = np.zeros(m)
    A = np.zeros((nc, 3, 3))
    B = np.zeros((nc, 3, 3))
    phi_try = np.zeros(m)
    A_try = np.zeros((nc, 3, 3))
    B_try = np.zeros((nc, 3, 3))
    J = np.empty((m, m))
    d = np.empty(m)
    r_try = np.empty(m)
    u_try = np.empty(m)
    rescue_history = np.empty(RESCUE_SWEEPS)
    csr_data = np.zeros(0)
    csr_indices = np.zeros(0, dtype=np.int32)
    csr_indptr = np.zeros(0, dtype=np.int32)
    operator = np.zeros((0, 0))
    have_csr = False
    matvec_plus(W, r, q, u)
    _, residual_q, residual_max = residuals(r, u, q, mu, n_bilateral)
    residual = residual_max if use_max else residual_q
    iteration = 0
    rescues = 0
    n_history = 0
    best_residual = np.inf
    floor = 0.0
    while True:
        if residual <= tolerance:
            return CONVERGED, iteration, residual, residual_q, residual_max, rescues, \
                n_history, floor
        if use_floor and math.isfinite(residual):
            floor = roundoff_floor_dense(W, r, u, q, mu, use_max)
            if residual <= floor:
                return ROUNDOFF, iteration, residual, residual_q, residual_max, rescues, \
                    n_history, floor
        if not math.isfinite(residual):
            return NON_FINITE, iteration, residual, residual_q, residual_max, rescues, \
                n_history, floor
        if iteration >= max_iterations:
            return MAX_ITERATIONS, iteration, residual, residual_q, residual_max, rescues, \
                n_history, floor
        if 0 < stall_window < n_history and iteration >= stall_after and hopeless(
                history[n_history - 1 - stall_window], residual, stall_window, tolerance,
                max_iterations - iteration):
            return HOPELESS, iteration, residual, residual_q, residual_max, rescues, \
                n_history, floor
        iteration += 1
        merit = alart_curnier_system(r, u, mu, n_bilateral, rho_n, rho_t, rho_b, phi, A, B,
                                     np.bool_(True))
        if least_norm:
            step_ok = least_norm_direction(W, n_bilateral, rho_b, A, B, phi, J, d)
        else:
            step_ok = regularised_direction(W, n_bilateral, rho_b, A, B, phi, residual, J, d)
        if step_ok:
            step = 1.0
            step_ok = False
            for _ in range(MAX_HALVINGS):
                for i in range(m):
                    r_try[i] = r[i] + step * d[i]
                matvec_plus(W, r_try, q, u_try)
                merit_try = alart_curnier_system(r_try, u_try, mu, n_bilateral, rho_n, rho_t,
                                                 rho_b, phi_try, A_try, B_try, np.bool_(False))
                if merit_try <= (1.0 - 2.0 * ARMIJO * step) * merit:
                    step_ok = True
                    break
                step *= 0.5
        if step_ok:
            r[:] = r_try
            u[:] = u_try
        else:
            rescues += 1
            if rescues > MAX_RESCUES and residual >= best_residual:
                return NO_DESCENT, iteration, residual, residual_q, residual_max, rescues, \
                    n_history, floor
            if not have_csr:
                csr_data, csr_indices, csr_indptr = _dense_to_csr(W)
                operator = bilateral_operator_dense(W, n_bilateral)
                have_csr = True
            rescue_history[:] = np.nan
            # (scalars as np.int64: a literal argument would compile nsgs_kernel once more)
            nsgs_kernel(csr_indptr, csr_indices, csr_data, q, mu, n_bilateral, operator, r,
                        u_try, np.int64(_AC), tolerance, use_max, np.int64(RESCUE_SWEEPS),
                        local_tolerance, local_max_iterations, np.int64(RESCUE_SWEEPS),
                        rescue_history, np.int64(0), np.int64(0), np.bool_(False))
            matvec_plus(W, r, q, u)
        _, residual_q, residual_max = residuals(r, u, q, mu, n_bilateral)
        residual = residual_max if use_max else residual_q
        best_residual = min(best_residual, residual)
        history[n_history] = residual
        n_history += 1


def solve_newton_dense(problem: ContactProblem, options: SolverOptions,
                       r0: np.ndarray | None = None) -> SolverResult:
    """:func:`fc3d_newton.solve_newton` by :func:`newton_dense_kernel` (same result fields and
    messages)."""
    m = problem.size
    r = np.zeros(m) if r0 is None else np.array(r0, dtype=np.float64, copy=True)
    if r.shape != (m,):
        raise ValueError(f"r0 must have shape ({m},), got {r.shape}")
    u = np.empty(m)
    history = np.empty(options.max_iterations)
    code, iterations, residual, residual_q, residual_max, rescues, n_history, floor = \
        newton_dense_kernel(problem.W_dense(), problem.q, problem.mu, problem.n_bilateral, r,
                            u, options.tolerance, options.use_max_normalisation,
                            options.max_iterations, options.roundoff_floor,
                            options.stall_window, options.stall_after, options.local_tolerance,
                            options.local_max_iterations, history,
                            options.newton_direction == "least_norm")
    status = _STATUS[code]
    message = ""
    if code == ROUNDOFF:
        message = floor_message(residual, floor, options.tolerance)
    elif code == NON_FINITE:
        message = "non-finite residual"
    elif code == MAX_ITERATIONS:
        message = (f"{options.max_iterations} Newton iterations done, residual {residual:.3g}"
                   f" > {options.tolerance:.3g}")
    elif code == HOPELESS:
        message = (f"stopped after {iterations} iterations at residual {residual:.3g}: at "
                   f"its rate over the last {options.stall_window} it would not reach "
                   f"{options.tolerance:.3g} within {options.max_iterations}")
    elif code == NO_DESCENT:
        message = f"no descent direction after {rescues} NSGS rescues"
    return SolverResult(
        r=r, u=u, iterations=int(iterations), residual=float(residual),
        residual_q=float(residual_q), residual_max=float(residual_max),
        converged=status is SolverStatus.CONVERGED, status=status, method="newton-ac",
        message=message + (f" ({rescues} NSGS rescues)" if rescues else ""),
        history=history[:n_history].copy(),
    )


_STATUS = (SolverStatus.CONVERGED, SolverStatus.MAX_ITERATIONS, SolverStatus.STALLED,
           SolverStatus.NUMERICAL_FAILURE, SolverStatus.STALLED, SolverStatus.CONVERGED)
