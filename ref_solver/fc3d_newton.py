"""Semismooth Newton method on the Alart–Curnier formulation of the whole problem.

Unknown r (m,). Equation Phi(r) = 0 with, per contact, the Alart–Curnier function of
:func:`fc3d_local.alart_curnier` (rho_N = 1 / W_ii[N, N], rho_T = 1 / max(W_ii[T1, T1],
W_ii[T2, T2])) and, per bilateral row b, Phi_b = u_b / W_bb (so that all rows have impulse
units). A generalised Jacobian is J = A + B W with A, B block diagonal; each iteration solves
J d = -Phi by LU (dense up to 100 rows, sparse above) and takes an Armijo step on 0.5 |Phi|^2.

When no descent step exists (a kink of Phi, or a singular J), a few NSGS sweeps are run from the
current iterate and Newton resumes (the hybrid strategy Siconos also uses); the run stops as
STALLED after too many such rescues without progress. Convergence is measured by the
natural-map residual, as for NSGS.
"""

from __future__ import annotations

import logging
import math

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from clearbench.ref_solver.contact_problem import (
    ContactProblem,
    SolverOptions,
    SolverResult,
    SolverStatus,
)
from clearbench.ref_solver.fc3d_local import LOCAL_KIND
from clearbench.ref_solver.fc3d_newton_dense import solve_newton_dense
from clearbench.ref_solver.fc3d_newton_parts import (
    ARMIJO,
    DELTA_MAX,
    DELTA_MIN,
    DENSE_LIMIT,
    MAX_HALVINGS,
    MAX_RESCUES,
    RESCUE_SWEEPS,
    alart_curnier_system,
    bilateral_scalings,
    contact_scalings,
    dense_jacobian,
)
from clearbench.ref_solver.fc3d_nsgs import bilateral_operator_of, diagonal_blocks, nsgs_kernel
from clearbench.ref_solver.fc3d_residual import (
    abs_operator_of,
    floor_message,
    hopeless,
    residual_both,
    roundoff_floor,
)

logger = logging.getLogger(__name__)

def _block_diagonal(n_bilateral: int, bilateral_diagonal: np.ndarray, blocks: np.ndarray):
    """Sparse (m, m) matrix diag(bilateral_diagonal) ⊕ blocks[0] ⊕ ... ⊕ blocks[nc - 1]."""
    nc = blocks.shape[0]
    contact_part = sp.bsr_matrix(
        (blocks, np.arange(nc), np.arange(nc + 1)), shape=(3 * nc, 3 * nc)
    )
    if n_bilateral == 0:
        return contact_part.tocsc()
    return sp.block_diag([sp.diags(bilateral_diagonal), contact_part], format="csc")


def _regularised_direction_dense(W_dense, nb, rho_b, A, B, phi, residual, J):
    """Dense counterpart of :func:`_regularised_direction` (small problems)."""
    delta = min(DELTA_MAX, max(DELTA_MIN, residual))
    for _ in range(6):
        dense_jacobian(W_dense, nb, rho_b, A, B, delta, J)
        try:
            d = np.linalg.solve(J, -phi)
            if np.all(np.isfinite(d)):
                return d
        except np.linalg.LinAlgError:
            pass
        delta *= 100.0
    return None


def _regularised_direction(J, phi: np.ndarray, residual: float) -> np.ndarray | None:
    """Solve (J + delta I) d = -Phi; None if no finite solution.

    W (hence J) is singular on redundant contact sets (four contacts under a box face give 12
    rows for 6 degrees of freedom). The proximal term delta I (J is dimensionless) picks a
    bounded direction; delta shrinks with the residual (Levenberg–Marquardt style, which keeps
    fast local convergence) and grows when the factorisation fails.
    """
    identity = sp.identity(J.shape[0], format="csc")
    delta = min(DELTA_MAX, max(DELTA_MIN, residual))
    for _ in range(6):
        try:
            with np.errstate(all="ignore"):
                d = spla.splu((J + delta * identity).tocsc()).solve(-phi)
            if np.all(np.isfinite(d)):
                return d
        except RuntimeError:  # exactly singular
            pass
        delta *= 100.0
    return None


def solve_newton(
    problem: ContactProblem, options: SolverOptions, r0: np.ndarray | None = None,
    compiled: bool = True,
) -> SolverResult:
    """Semismooth Newton solve of ``problem``; see ``solve_contact_problem``.

    Problems of at most ``DENSE_LIMIT`` rows are solved by the compiled kernel of
    :mod:`fc3d_newton_dense` unless ``compiled`` is False (the Python driver below, kept as
    the reference of the kernel's tests); larger ones by the Python driver with sparse LU,
    except with the least-norm direction, which only the dense kernel has.
    """
    if options.newton_direction == "least_norm" or (compiled and problem.size <= DENSE_LIMIT):
        return solve_newton_dense(problem, options, r0)
    W = problem.W_csr()
    q, mu, nb, nc, m = problem.q, problem.mu, problem.n_bilateral, problem.n_contacts, problem.size
    use_max = options.use_max_normalisation
    rho_n, rho_t = contact_scalings(diagonal_blocks(W, nb, nc))
    rho_b = bilateral_scalings(W.diagonal()[:nb]) if nb else np.zeros(0)
    r = np.zeros(m) if r0 is None else np.array(r0, dtype=np.float64, copy=True)
    if r.shape != (m,):
        raise ValueError(f"r0 must have shape ({m},), got {r.shape}")
    phi = np.zeros(m)
    A = np.zeros((nc, 3, 3))
    B = np.zeros((nc, 3, 3))
    phi_try = np.zeros(m)
    A_try = np.zeros((nc, 3, 3))
    B_try = np.zeros((nc, 3, 3))
    W_dense = problem.W_dense() if m <= DENSE_LIMIT else None
    J_dense = np.empty((m, m)) if W_dense is not None else None
    history: list[float] = []
    rescues = 0
    best_residual = np.inf
    status = SolverStatus.MAX_ITERATIONS
    message = ""
    iteration = 0
    residual = np.inf

    # Products W r: dense numpy below the dense limit (a scipy.sparse product costs ~10 us of
    # Python overhead per call, more than the arithmetic of a small problem).
    W_product = W_dense if W_dense is not None else W

    def measure(r_: np.ndarray, u_: np.ndarray | None = None):
        """(u = W r + q unless given, |F|/|q|, |F|/max, the tested one of the two)."""
        if u_ is None:
            u_ = W_product @ r_ + q
        _, rel_q, rel_max = residual_both(r_, u_, q, mu, nb)
        return u_, rel_q, rel_max, (rel_max if use_max else rel_q)

    u, residual_q, residual_max, residual = measure(r)
    while True:
        if residual <= options.tolerance:
            status = SolverStatus.CONVERGED
            break
        if options.roundoff_floor and math.isfinite(residual):
            floor = roundoff_floor(abs_operator_of(problem), r, u, q, mu, use_max)
            if residual <= floor:
                status = SolverStatus.CONVERGED
                message = floor_message(residual, floor, options.tolerance)
                break
        if not math.isfinite(residual):
            status = SolverStatus.NUMERICAL_FAILURE
            message = "non-finite residual"
            break
        if iteration >= options.max_iterations:
            status = SolverStatus.MAX_ITERATIONS
            break
        window = options.stall_window
        if 0 < window < len(history) and iteration >= options.stall_after and hopeless(
                history[-1 - window], residual, window, options.tolerance,
                options.max_iterations - iteration):
            status = SolverStatus.STALLED
            message = (f"stopped after {iteration} iterations at residual {residual:.3g}: at "
                       f"its rate over the last {window} it would not reach "
                       f"{options.tolerance:.3g} within {options.max_iterations}")
            break
        iteration += 1
        merit = alart_curnier_system(r, u, mu, nb, rho_n, rho_t, rho_b, phi, A, B, True)
        if W_dense is not None:
            d = _regularised_direction_dense(W_dense, nb, rho_b, A, B, phi, residual, J_dense)
        else:
            J = (_block_diagonal(nb, np.zeros(nb), A)
                 + _block_diagonal(nb, rho_b, B) @ W).tocsc()
            d = _regularised_direction(J, phi, residual)
        step_ok = d is not None
        if step_ok:
            step = 1.0
            step_ok = False
            for _ in range(MAX_HALVINGS):
                r_try = r + step * d
                u_try = W_product @ r_try + q
                merit_try = alart_curnier_system(r_try, u_try, mu, nb, rho_n, rho_t, rho_b,
                                                 phi_try, A_try, B_try, False)
                if merit_try <= (1.0 - 2.0 * ARMIJO * step) * merit:
                    step_ok = True
                    break
                step *= 0.5
        u_next = None
        if step_ok:
            r = r_try
            u_next = u_try  # = W r + q, the same expression measure() evaluates
        else:
            # rescue: a few NSGS sweeps from the current iterate
            rescues += 1
            if rescues > MAX_RESCUES and residual >= best_residual:
                status = SolverStatus.STALLED
                message = f"no descent direction after {rescues} NSGS rescues"
                break
            u_tmp = np.empty(m)
            nsgs_kernel(W.indptr, W.indices, W.data, q, mu, nb, bilateral_operator_of(problem),
                        r, u_tmp, LOCAL_KIND["ac"], options.tolerance, use_max, RESCUE_SWEEPS,
                        options.local_tolerance, options.local_max_iterations, RESCUE_SWEEPS,
                        np.full(RESCUE_SWEEPS, np.nan), 0, 0, np.bool_(False))
        u, residual_q, residual_max, residual = measure(r, u_next)
        best_residual = min(best_residual, residual)
        history.append(residual)
    if status is SolverStatus.MAX_ITERATIONS:
        message = (f"{options.max_iterations} Newton iterations done, residual {residual:.3g}"
                   f" > {options.tolerance:.3g}")
    # r, u and both residuals are those of the last measure() (every exit follows one)
    return SolverResult(
        r=r, u=u, iterations=int(iteration), residual=float(residual),
        residual_q=float(residual_q), residual_max=float(residual_max),
        converged=status is SolverStatus.CONVERGED, status=status, method="newton-ac",
        message=message + (f" ({rescues} NSGS rescues)" if rescues else ""),
        history=np.array(history),
    )
