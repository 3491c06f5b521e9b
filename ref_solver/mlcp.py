"""Mixed linear complementarity problem (MLCP) by projected Gauss–Seidel with an exact
equality block; used by the position-projection stage of the combined projection scheme.

Problem: w = A z + b with A (n, n), b (n,), and the first ``n_equality`` rows equalities
(z_e free, w_e = 0); the other rows complementarity conditions 0 <= z_i ⊥ w_i >= 0.

One sweep solves the equality rows exactly for the current inequality unknowns
(A_ee z_e = -(b_e + A_ei z_i), A_ee factorised once, pseudo-inverse if singular), then updates
each inequality unknown by z_i <- max(0, z_i - w_i / A_ii). Convergence is measured by the
natural-map residual F_e = w_e, F_i = z_i - max(0, z_i - w_i), normalised like the contact
residual (|F| / max(|b|, |z|, |w|) by default, or |F| / |b|).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from numba import njit

from clearbench.ref_solver.contact_problem import Normalisation, SolverStatus
from clearbench.ref_solver.fc3d_nsgs import bilateral_solve_operator
from clearbench.ref_solver.fc3d_residual import normalised


@dataclass(frozen=True, eq=False)
class MLCPResult:
    """Outcome of :func:`solve_mlcp`: z, w = A z + b (n,), sweeps, residuals and status.

    ``residual`` is in the requested normalisation; ``residual_b`` is |F| / |b| and
    ``residual_max`` is |F| / max(|b|, |z|, |w|).
    """

    z: np.ndarray
    w: np.ndarray
    iterations: int
    residual: float
    residual_b: float
    residual_max: float
    converged: bool
    status: SolverStatus
    message: str = ""


@njit(cache=True)
def _mlcp_residual_squared(z: np.ndarray, w: np.ndarray, n_equality: int) -> float:
    total = 0.0
    for i in range(n_equality):
        total += w[i] * w[i]
    for i in range(n_equality, z.size):
        f = z[i] - max(0.0, z[i] - w[i])
        total += f * f
    return total


@njit(cache=True)
def _pgs_kernel(indptr, indices, data, b, n_equality, diagonal, equality_operator, z, w,
                tolerance, use_max, max_sweeps):
    n = b.size
    rhs = np.zeros(n_equality)
    norm_b = math.sqrt(np.sum(b * b))
    residual = np.inf
    for sweep in range(max_sweeps):
        if n_equality > 0:
            for row in range(n_equality):
                acc = b[row]
                for p in range(indptr[row], indptr[row + 1]):
                    col = indices[p]
                    if col >= n_equality:
                        acc += data[p] * z[col]
                rhs[row] = -acc
            for row in range(n_equality):
                acc = 0.0
                for col in range(n_equality):
                    acc += equality_operator[row, col] * rhs[col]
                z[row] = acc
        for row in range(n_equality, n):
            acc = b[row]
            for p in range(indptr[row], indptr[row + 1]):
                acc += data[p] * z[indices[p]]
            if diagonal[row] > 0.0:
                z[row] = max(0.0, z[row] - acc / diagonal[row])
            else:  # no diagonal: the row can only be satisfied by w >= 0 with z = 0
                z[row] = 0.0
        for row in range(n):
            acc = b[row]
            for p in range(indptr[row], indptr[row + 1]):
                acc += data[p] * z[indices[p]]
            w[row] = acc
        abs_residual = math.sqrt(_mlcp_residual_squared(z, w, n_equality))
        if not math.isfinite(abs_residual):
            return 3, sweep + 1, np.nan
        residual = normalised(abs_residual, norm_b, math.sqrt(np.sum(z * z)),
                              math.sqrt(np.sum(w * w)), use_max)
        if residual <= tolerance:
            return 0, sweep + 1, residual
    return 1, max_sweeps, residual


def solve_mlcp(
    A, b: np.ndarray, n_equality: int, tolerance: float = 1e-10, max_iterations: int = 10_000,
    z0: np.ndarray | None = None, normalisation: str = "max",
) -> MLCPResult:
    """Solve the MLCP (A, b) whose first ``n_equality`` rows are equalities.

    Parameters
    ----------
    A : ndarray or scipy.sparse matrix, shape (n, n)
        Need not be symmetric; PGS converges for symmetric positive (semi)definite A and
        diagonally dominant A.
    b : ndarray, shape (n,)
    n_equality : int
        Number of leading equality rows (z free, w = 0).
    tolerance : float
        On the natural-map residual in ``normalisation`` ("max": |F| / max(|b|, |z|, |w|),
        "q": |F| / |b|).
    max_iterations : int
        Sweep cap; reaching it returns converged=False (never raises).
    z0 : ndarray, shape (n,), optional
        Warm start.
    """
    A_csr = sp.csr_matrix(A, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64).ravel()
    n = b.size
    if A_csr.shape != (n, n):
        raise ValueError(f"A must have shape ({n}, {n}), got {A_csr.shape}")
    if not 0 <= n_equality <= n:
        raise ValueError(f"n_equality must be in [0, {n}], got {n_equality}")
    use_max = Normalisation(normalisation) is Normalisation.MAX
    z = np.zeros(n) if z0 is None else np.array(z0, dtype=np.float64, copy=True)
    z[n_equality:] = np.maximum(z[n_equality:], 0.0)
    w = A_csr @ z + b
    operator = bilateral_solve_operator(A_csr[:n_equality, :n_equality].toarray())
    if n == 0:
        return MLCPResult(z, w, 0, 0.0, 0.0, 0.0, True, SolverStatus.CONVERGED)
    code, sweeps, residual = _pgs_kernel(
        A_csr.indptr.astype(np.int64), A_csr.indices.astype(np.int64), A_csr.data, b,
        int(n_equality), A_csr.diagonal().copy(), operator, z, w, float(tolerance), use_max,
        int(max_iterations),
    )
    status = {0: SolverStatus.CONVERGED, 1: SolverStatus.MAX_ITERATIONS,
              3: SolverStatus.NUMERICAL_FAILURE}[code]
    w = A_csr @ z + b
    abs_residual = math.sqrt(_mlcp_residual_squared(z, w, int(n_equality)))
    norms = (float(np.linalg.norm(b)), float(np.linalg.norm(z)), float(np.linalg.norm(w)))
    residual_b = normalised(abs_residual, *norms, False)
    residual_max = normalised(abs_residual, *norms, True)
    message = "" if status is SolverStatus.CONVERGED else (
        f"{sweeps} sweeps, residual {residual:.3g} > {tolerance:.3g}")
    return MLCPResult(z, w, int(sweeps), float(residual_max if use_max else residual_b),
                      float(residual_b), float(residual_max), status is SolverStatus.CONVERGED,
                      status, message)
