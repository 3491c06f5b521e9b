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

from clearbench.ref_solver.contact_problem import (
    ContactProblem,
    SolverOptions,
    SolverResult,
    SolverStatus,
)
from clearbench.ref_solver.dense_kernels import (
    BILATERAL_CONDITION_LIMIT,
    bilateral_block_operator,
)
from clearbench.ref_solver.fc3d_local import LOCAL_FAILED, LOCAL_KIND, N_MAT, N_VEC, solve_local
from clearbench.ref_solver.fc3d_residual import (
    csr_matvec_plus,
    floor_message,
    hopeless,
    natural_map_squared,
    normalised,
    roundoff_floor_csr,
)

logger = logging.getLogger(__name__)

_STATUS_CODES = (
    SolverStatus.CONVERGED,
    SolverStatus.MAX_ITERATIONS,
    SolverStatus.STALLED,
    SolverStatus.NUMERICAL_FAILURE,
    SolverStatus.CONVERGED,
)
#: :func:`nsgs_kernel`'s code of a residual accepted on its round-off floor.
ROUNDOFF_CODE = 4
_NO_OPERATOR = np.zeros((0, 0))
_METHOD_NAMES = {name: f"nsgs-{name}" for name in LOCAL_KIND}


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
    """Dense operator S with r_b = S rhs solving W_bb r_b = rhs (pseudo-inverse if singular):
    :func:`dense_kernels.bilateral_block_operator`.

    Redundant bilateral rows (a singular W_bb) get the minimum-norm impulses.
    """
    if W_dense_bb.size == 0:
        return np.zeros((0, 0))
    operator, pseudo = bilateral_block_operator(
        np.ascontiguousarray(W_dense_bb, dtype=np.float64))
    if pseudo:
        logger.info("bilateral block ill-conditioned (cond >= %.0e): using its pseudo-inverse",
                    BILATERAL_CONDITION_LIMIT)
    return operator


def bilateral_operator_of(problem: ContactProblem) -> np.ndarray:
    """The (nb, nb) operator of :func:`bilateral_solve_operator` for ``problem``, computed once
    per problem (shared by every solve of it); a (0, 0) array without bilateral rows."""
    return problem.derived("bilateral_solve_operator", _compute_bilateral_operator)


def _compute_bilateral_operator(problem: ContactProblem) -> np.ndarray:
    nb = problem.n_bilateral
    if nb == 0:
        return _NO_OPERATOR
    W = problem.W
    block = W[:nb, :nb].toarray() if sp.issparse(W) else W[:nb, :nb]
    return bilateral_solve_operator(block)


@njit(cache=True)
def nsgs_kernel(
    indptr: np.ndarray, indices: np.ndarray, data: np.ndarray, q: np.ndarray, mu: np.ndarray,
    n_bilateral: int, bilateral_operator: np.ndarray, r: np.ndarray, u: np.ndarray, kind: int,
    tolerance: float, use_max: bool, max_sweeps: int, local_tolerance: float,
    local_max_iterations: int, check_interval: int, history: np.ndarray, stall_window: int,
    stall_after: int, use_floor: bool,
) -> tuple[int, int, float, float, int, int]:
    """Run NSGS sweeps on r (in place); u receives W r + q at the last residual check.

    W is given by its CSR arrays (indptr (m + 1,), indices, data); its (3, 3) diagonal contact
    blocks are extracted here (one pass over the contact rows). The last sweep is always
    checked. With ``use_floor``, every check above the tolerance also tests the residual against
    its round-off floor (:func:`fc3d_residual.roundoff_floor`), as the Newton kernels do at each
    iteration: a residual the sweeps cannot tell from zero ends the solve (code 4) instead of
    sweeping on to the cap. Returns (status code: 0 converged / 1 max iterations / 2 stalled /
    3 non-finite / 4 converged to round-off, sweeps done,
    |F| / |q|, |F| / max(|q|, |r|, |u|) (NaN when non-finite), local failures in the last sweep,
    number of checks). ``history`` (>= max_sweeps,) receives the residual in the tested
    normalisation (``use_max``) of each check.
    """
    nc = mu.size
    blocks = np.zeros((nc, 3, 3))
    _extract_blocks(indptr, indices, data, n_bilateral, blocks)
    vec = np.zeros((N_VEC, 3))
    mat = np.zeros((N_MAT, 3, 3))
    ql = np.zeros(3)
    ri = np.zeros(3)
    rhs = np.zeros(n_bilateral)
    norm_q = math.sqrt(np.dot(q, q))
    abs_residual = np.inf
    norm_r = 0.0
    norm_u = 0.0
    failures = 0
    n_checks = 0
    status = 1  # max iterations, unless the loop ends otherwise
    sweeps = max_sweeps
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
        if (sweep + 1) % check_interval == 0 or sweep == max_sweeps - 1:
            csr_matvec_plus(indptr, indices, data, r, q, u)
            abs_residual = math.sqrt(natural_map_squared(r, u, mu, n_bilateral))
            norm_r = math.sqrt(np.dot(r, r))
            norm_u = math.sqrt(np.dot(u, u))
            if not math.isfinite(abs_residual + norm_r + norm_u):
                return 3, sweep + 1, np.nan, np.nan, failures, n_checks
            residual = normalised(abs_residual, norm_q, norm_r, norm_u, use_max)
            history[n_checks] = residual
            n_checks += 1
            if residual <= tolerance:
                status, sweeps = 0, sweep + 1
                break
            if use_floor and residual <= roundoff_floor_csr(indptr, indices, data, r, u, q, mu,
                                                            use_max):
                status, sweeps = ROUNDOFF_CODE, sweep + 1
                break
            if 0 < stall_window < n_checks and n_checks >= stall_after and hopeless(
                    history[n_checks - 1 - stall_window], residual,
                    stall_window * check_interval, tolerance, max_sweeps - sweep - 1):
                status, sweeps = 2, sweep + 1
                break
    return (status, sweeps, normalised(abs_residual, norm_q, norm_r, norm_u, False),
            normalised(abs_residual, norm_q, norm_r, norm_u, True), failures, n_checks)


def solve_nsgs(
    problem: ContactProblem, options: SolverOptions, r0: np.ndarray | None = None
) -> SolverResult:
    """NSGS solve of ``problem``; see :func:`clearbench.ref_solver.solve_contact_problem`.

    The Python work around the compiled kernel is kept to a few microseconds (one kernel call,
    the bilateral operator cached on the problem), since the reference stepper solves many
    problems of a few contacts.
    """
    m = problem.q.size
    if r0 is None:
        r = np.zeros(m)
    else:
        r = np.array(r0, dtype=np.float64, copy=True)
        if r.shape != (m,):
            raise ValueError(f"r0 must have shape ({m},), got {r.shape}")
    method = _METHOD_NAMES[options.local_solver]
    if m == 0:
        return SolverResult(r, r.copy(), 0, 0.0, 0.0, 0.0, True, SolverStatus.CONVERGED, method)
    data, indices, indptr = problem.W_csr_arrays()
    u = np.empty(m)
    history = np.empty(options.max_iterations)  # untouched pages cost nothing
    use_max = options.use_max_normalisation
    nb = problem.n_bilateral
    code, sweeps, residual_q, residual_max, failures, n_checks = nsgs_kernel(
        indptr, indices, data, problem.q, problem.mu, nb,
        bilateral_operator_of(problem) if nb else _NO_OPERATOR, r, u,
        LOCAL_KIND[options.local_solver],
        options.tolerance, use_max, options.max_iterations, options.local_tolerance,
        options.local_max_iterations, options.residual_check_interval, history,
        options.stall_window, options.stall_after, np.bool_(options.roundoff_floor),
    )
    if code == 0:
        return SolverResult(r, u, sweeps, residual_max if use_max else residual_q, residual_q,
                            residual_max, True, SolverStatus.CONVERGED, method, "", failures,
                            history[:n_checks].copy())
    status = _STATUS_CODES[code]
    residual = residual_max if use_max else residual_q
    if code == ROUNDOFF_CODE:
        floor = roundoff_floor_csr(indptr, indices, data, r, u, problem.q, problem.mu, use_max)
        return SolverResult(r, u, sweeps, residual, residual_q, residual_max, True,
                            SolverStatus.CONVERGED, method,
                            floor_message(residual, floor, options.tolerance), failures,
                            history[:n_checks].copy())
    if status is SolverStatus.MAX_ITERATIONS:
        message = f"{sweeps} sweeps done, residual {history[n_checks - 1]:.3g} > " \
                  f"{options.tolerance:.3g}"
    elif status is SolverStatus.STALLED:
        message = (f"stopped after {sweeps} sweeps at residual {history[n_checks - 1]:.3g}: "
                   f"at its rate over the last {options.stall_window} checks it would not "
                   f"reach {options.tolerance:.3g} within the {options.max_iterations} sweeps")
    else:
        message = f"non-finite residual after {sweeps} sweeps"
    return SolverResult(
        r=r, u=u, iterations=sweeps, residual=residual_max if use_max else residual_q,
        residual_q=residual_q, residual_max=residual_max, converged=False, status=status,
        method=method, message=message, local_failures=failures,
        history=history[:n_checks].copy(),
    )
