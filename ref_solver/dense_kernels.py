"""Compiled dense linear algebra and residual kernels shared by the compiled solvers.

Small dense problems (tens of rows): a product or a factorisation costs less than one call
into numpy from Python, so the compiled one-step solvers do them here, in loops, without
allocating beyond their outputs.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from clearbench.ref_solver.fc3d_residual import (
    floor_of_velocity_error,
    natural_map_squared,
    normalised,
)


@njit(cache=True)
def matvec_plus(W: np.ndarray, x: np.ndarray, q: np.ndarray, out: np.ndarray) -> None:
    """out = W x + q for a dense W (m, n), x (n,), q (m,) (in place)."""
    for i in range(q.size):
        acc = 0.0
        for j in range(x.size):
            acc += W[i, j] * x[j]
        out[i] = acc + q[i]


@njit(cache=True)
def lu_solve(A: np.ndarray, b: np.ndarray, x: np.ndarray) -> bool:
    """Solve A x = b (A (m, m), overwritten by its LU factors) by Gaussian elimination with
    partial pivoting, as LAPACK's gesv; False when a pivot is exactly zero or x is not finite
    (where ``numpy.linalg.solve`` raises or returns inf/nan)."""
    m = b.size
    # The pivot row's trailing part, copied: the update of a row then reads an array that is
    # not A, so the compiler vectorises it (2.3 times faster at m = 52, the C-60's problems);
    # every entry receives the same operations in the same order, so the factors are the same
    # to the bit.
    pivot_row = np.empty(m)
    for i in range(m):
        x[i] = b[i]
    for k in range(m):
        pivot = k
        largest = abs(A[k, k])
        for i in range(k + 1, m):
            if abs(A[i, k]) > largest:
                largest = abs(A[i, k])
                pivot = i
        if largest == 0.0:
            return False
        if pivot != k:
            for j in range(m):
                A[k, j], A[pivot, j] = A[pivot, j], A[k, j]
            x[k], x[pivot] = x[pivot], x[k]
        inverse = 1.0 / A[k, k]
        trailing = m - k - 1
        for j in range(trailing):
            pivot_row[j] = A[k, k + 1 + j]
        for i in range(k + 1, m):
            factor = A[i, k] * inverse
            if factor != 0.0:
                row = A[i, k + 1:]
                for j in range(trailing):
                    row[j] -= factor * pivot_row[j]
                x[i] -= factor * x[k]
    for k in range(m - 1, -1, -1):
        acc = x[k]
        for j in range(k + 1, m):
            acc -= A[k, j] * x[j]
        x[k] = acc / A[k, k]
        if not math.isfinite(x[k]):
            return False
    return True


@njit(cache=True)
def residuals(r: np.ndarray, u: np.ndarray, q: np.ndarray, mu: np.ndarray,
              n_bilateral: int) -> tuple[float, float, float]:
    """(|F|, |F| / |q|, |F| / max(|q|, |r|, |u|)) of r with u = W r + q (as
    :func:`fc3d_residual.residual_both`)."""
    abs_residual = math.sqrt(natural_map_squared(r, u, mu, n_bilateral))
    norm_q = math.sqrt(np.dot(q, q))
    norm_r = math.sqrt(np.dot(r, r))
    norm_u = math.sqrt(np.dot(u, u))
    return (abs_residual, normalised(abs_residual, norm_q, norm_r, norm_u, False),
            normalised(abs_residual, norm_q, norm_r, norm_u, True))


@njit(cache=True)
def roundoff_floor_dense(W: np.ndarray, r: np.ndarray, u: np.ndarray, q: np.ndarray,
                         mu: np.ndarray, use_max: bool) -> float:
    """:func:`fc3d_residual.roundoff_floor` for a dense W (m, m), without forming |W|."""
    m = q.size
    total = 0.0
    for i in range(m):
        acc = 0.0
        for j in range(m):
            acc += abs(W[i, j]) * abs(r[j])
        acc += abs(q[i])
        total += acc * acc
    return floor_of_velocity_error(math.sqrt(total), r, u, q, mu, use_max)


@njit(cache=True)
def bilateral_operator_dense(W: np.ndarray, n_bilateral: int) -> np.ndarray:
    """:func:`fc3d_nsgs.bilateral_solve_operator` of the leading (nb, nb) block of a dense W:
    its inverse when cond < 1e12, else its pseudo-inverse (rcond 1e-12)."""
    if n_bilateral == 0:
        return np.zeros((0, 0))
    block = np.ascontiguousarray(W[:n_bilateral, :n_bilateral])
    condition = np.linalg.cond(block)
    if math.isfinite(condition) and condition < 1e12:
        return np.linalg.inv(block)
    return np.linalg.pinv(block, rcond=1e-12)
