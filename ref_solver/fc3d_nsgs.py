"""Nonsmooth Gauss–Seidel (NSGS) over contacts, with an exact local solver per contact.

One sweep: the bilateral rows are solved exactly for the current contact impulses
(r_b = -W_bb^-1 (q_b + W_bc r_c), W_bb factorised once), then each contact in turn solves its
3x3 problem u_i = W_ii r_i + (q_i + sum_{j != i} W_ij r_j) with the others frozen
(:func:`fc3d_local.solve_local`). W is walked in CSR form, so a sweep costs O(nnz(W)) plus the
local solves. The natural-map residual (one more pass over W) is evaluated every
``residual_check_interval`` sweeps.
"""

from __future__ import annotations

import logging
import math

import numpy as np
import scipy.sparse as sp
from numba import njit

from .contact_problem import ContactProblem, Normalisation, SolverOptions, SolverResult, SolverStatus
from .fc3d_local import LOCAL_FAILED, LOCAL_KIND, N_MAT, N_VEC, solve_local
from .fc3d_residual import csr_matvec_plus, natural_map_squared, normalised, residual_both

logger = logging.getLogger(__name__)

_STATUS_CODES = (
    SolverStatus.CONVERGED,
    SolverStatus.MAX_ITERATIONS,
    SolverStatus.STALLED,
    SolverStatus.NUMERICAL_FAILURE,
)


def diagonal_blocks(W_csr: sp.csr_matrix, n_bilateral: int, n_contacts: int) -> np.ndarray:
    """The (nc, 3, 3) diagonal blocks W_ii of the contact rows."""
    blocks = np.zeros((n_contacts, 3, 3))
    _extract_blocks(W_csr.indptr, W_csr.indices, W_csr.data, n_bilateral, blocks)
    return blocks


@njit(cache=True)
def _extract_blocks(indptr, indices, data, n_bilateral, blocks):
    for i in range(blocks.shape[0]):
        k = n_bilateral + 3 * i
        for a in range(3):
            row = k + a
            for p in range(indptr[row], indptr[row + 1]):
                col = indices[p]
                if k <= col < k + 3:
                    blocks[i, a, col - k] += data[p]


def bilateral_solve_operator(W_dense_bb: np.ndarray) -> np.ndarray:
    """Dense operator S with r_b = S rhs solving W_bb r_b = rhs (pseudo-inverse if singular).

    Redundant bilateral rows (a singular W_bb) get the minimum-norm impulses.
    """
    if W_dense_bb.size == 0:
        return np.zeros((0, 0))
    condition = np.linalg.cond(W_dense_bb)
    if np.isfinite(condition) and condition < 1e12:
        return np.linalg.inv(W_dense_bb)
    logger.info("bilateral block ill-conditioned (cond %.3g): using its pseudo-inverse", condition)
    return np.linalg.pinv(W_dense_bb, rcond=1e-12)


@njit(cache=True)
def nsgs_kernel(
    indptr: np.ndarray, indices: np.ndarray, data: np.ndarray, q: np.ndarray, mu: np.ndarray,
    n_bilateral: int, blocks: np.ndarray, bilateral_operator: np.ndarray, r: np.ndarray,
    u: np.ndarray, kind: int, tolerance: float, use_max: bool, max_sweeps: int,
    local_tolerance: float, local_max_iterations: int, check_interval: int,
    history: np.ndarray,
) -> tuple[int, int, float, int]:
    """Run NSGS sweeps on r (in place); u receives W r + q at the last residual check.

    Returns (status code: 0 converged / 1 max iterations / 3 NaN, sweeps done, residual in the
    requested normalisation, local failures in the last sweep). ``history`` (max_sweeps,)
    receives the residual at each check (NaN elsewhere).
    """
    m = q.size
    nc = mu.size
    vec = np.zeros((N_VEC, 3))
    mat = np.zeros((N_MAT, 3, 3))
    ql = np.zeros(3)
    ri = np.zeros(3)
    rhs = np.zeros(n_bilateral)
    norm_q = math.sqrt(np.sum(q * q))
    residual = np.inf
    failures = 0
    for sweep in range(max_sweeps):
        # bilateral rows, exact: W_bb r_b = -(q_b + W_bc r_c)
        if n_bilateral > 0:
            for row in range(n_bilateral):
                acc = q[row]
                for p in range(indptr[row], indptr[row + 1]):
                    col = indices[p]
                    if col >= n_bilateral:
                        acc += data[p] * r[col]
                rhs[row] = -acc
            for row in range(n_bilateral):
                acc = 0.0
                for col in range(n_bilateral):
                    acc += bilateral_operator[row, col] * rhs[col]
                r[row] = acc
        failures = 0
        for i in range(nc):
            k = n_bilateral + 3 * i
            for a in range(3):
                row = k + a
                acc = q[row]
                for p in range(indptr[row], indptr[row + 1]):
                    acc += data[p] * r[indices[p]]
                ql[a] = acc - (blocks[i, a, 0] * r[k] + blocks[i, a, 1] * r[k + 1]
                               + blocks[i, a, 2] * r[k + 2])
                ri[a] = r[k + a]
            code = solve_local(kind, blocks[i], ql, mu[i], ri, local_tolerance,
                               local_max_iterations, vec, mat)
            if code == LOCAL_FAILED:
                failures += 1
            r[k] = ri[0]
            r[k + 1] = ri[1]
            r[k + 2] = ri[2]
        last = sweep == max_sweeps - 1
        if (sweep + 1) % check_interval == 0 or last:
            csr_matvec_plus(indptr, indices, data, r, q, u)
            abs_residual = math.sqrt(natural_map_squared(r, u, mu, n_bilateral))
            if not math.isfinite(abs_residual):
                return 3, sweep + 1, np.nan, failures
            residual = normalised(abs_residual, norm_q, math.sqrt(np.sum(r * r)),
                                  math.sqrt(np.sum(u * u)), use_max)
            history[sweep] = residual
            if residual <= tolerance:
                return 0, sweep + 1, residual, failures
    if m == 0:
        return 0, 0, 0.0, 0
    return 1, max_sweeps, residual, failures


def solve_nsgs(
    problem: ContactProblem, options: SolverOptions, r0: np.ndarray | None = None
) -> SolverResult:
    """NSGS solve of ``problem``; see :func:`clearbench.ref_solver.solve_contact_problem`."""
    W = problem.W_csr()
    nb, nc = problem.n_bilateral, problem.n_contacts
    blocks = diagonal_blocks(W, nb, nc)
    operator = bilateral_solve_operator(problem.W_dense()[:nb, :nb] if nb else np.zeros((0, 0)))
    r = np.zeros(problem.size) if r0 is None else np.array(r0, dtype=np.float64, copy=True)
    if r.shape != (problem.size,):
        raise ValueError(f"r0 must have shape ({problem.size},), got {r.shape}")
    u = np.empty(problem.size)
    history = np.full(options.max_iterations, np.nan)
    use_max = Normalisation(options.normalisation) is Normalisation.MAX
    if problem.size == 0:
        return _result(problem, r, problem.q.copy(), 0, 0, 0, options, history, 0)
    code, sweeps, residual, failures = nsgs_kernel(
        W.indptr.astype(np.int64), W.indices.astype(np.int64), W.data, problem.q, problem.mu,
        nb, blocks, operator, r, u, LOCAL_KIND[options.local_solver], options.tolerance,
        use_max, options.max_iterations, options.local_tolerance,
        options.local_max_iterations, options.residual_check_interval, history,
    )
    return _result(problem, r, u, code, sweeps, residual, options, history, failures)


def _result(problem, r, u, code, sweeps, residual, options, history, failures) -> SolverResult:
    status = _STATUS_CODES[code]
    if status is SolverStatus.NUMERICAL_FAILURE:
        residual_q = residual_max = float("nan")
    else:
        u = problem.velocity(r)
        _, residual_q, residual_max = residual_both(r, u, problem.q, problem.mu, problem.n_bilateral)
    message = ""
    if status is SolverStatus.MAX_ITERATIONS:
        message = f"{sweeps} sweeps done, residual {residual:.3g} > {options.tolerance:.3g}"
    elif status is SolverStatus.NUMERICAL_FAILURE:
        message = f"non-finite residual after {sweeps} sweeps"
    return SolverResult(
        r=r, u=u, iterations=int(sweeps), residual=float(residual), residual_q=residual_q,
        residual_max=residual_max, converged=status is SolverStatus.CONVERGED, status=status,
        method=f"nsgs-{options.local_solver}", message=message, local_failures=int(failures),
        history=tuple(float(h) for h in history[:sweeps] if np.isfinite(h)),
    )
