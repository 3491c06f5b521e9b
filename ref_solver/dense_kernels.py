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


#: The bilateral block is inverted when its 2-norm condition number is under this, else
#: pseudo-inverted (rcond ``BILATERAL_RCOND``): redundant bilateral rows (a singular block)
#: get the minimum-norm impulses.
BILATERAL_CONDITION_LIMIT = 1e12
BILATERAL_RCOND = 1e-12


@njit(cache=True)
def _norm_1(A: np.ndarray) -> float:
    """The 1-norm (largest column sum of magnitudes) of A (n, n)."""
    largest = 0.0
    for j in range(A.shape[1]):
        column = 0.0
        for i in range(A.shape[0]):
            column += abs(A[i, j])
        largest = max(largest, column)
    return largest


@njit(cache=True)
def bilateral_block_operator(block: np.ndarray) -> tuple[np.ndarray, bool]:
    """(S (n, n), pseudo): S solves block r_b = rhs as r_b = S rhs; the inverse of ``block``
    (n, n) when its 2-norm condition number is under ``BILATERAL_CONDITION_LIMIT``, else its
    pseudo-inverse (``pseudo`` True).

    The decision is the one of the condition number by SVD, without the SVD where cheaper
    bounds settle it: with the inverse at hand, cond_1 = |A|_1 |A^-1|_1 satisfies
    cond_1 / n <= cond_2 <= n cond_1, so cond_1 under limit / (2 n) proves cond_2 under the
    limit and cond_1 over 2 n limit proves it over (the factor 2 covers the computed
    inverse's error, relative cond_2 x machine epsilon <= 1e-4 where the decision is made).
    Only a block between the two bounds (or one whose inverse fails or is not finite) has its
    SVD computed. The inverse returned is ``np.linalg.inv``'s either way.
    """
    n = block.shape[0]
    if n == 0:
        return np.zeros((0, 0)), False
    inverse = np.zeros((n, n))
    inverted = True
    try:
        inverse = np.linalg.inv(block)
    except Exception:  # exactly singular to LAPACK
        inverted = False
    if inverted:
        condition_1 = _norm_1(block) * _norm_1(inverse)
        if condition_1 < BILATERAL_CONDITION_LIMIT / (2.0 * n):
            return inverse, False
        if not condition_1 > 2.0 * n * BILATERAL_CONDITION_LIMIT:
            condition = np.linalg.cond(block)
            if math.isfinite(condition) and condition < BILATERAL_CONDITION_LIMIT:
                return inverse, False
    return np.linalg.pinv(block, rcond=BILATERAL_RCOND), True


@njit(cache=True)
def bilateral_operator_dense(W: np.ndarray, n_bilateral: int) -> np.ndarray:
    """:func:`bilateral_block_operator` of the leading (nb, nb) block of a dense W."""
    if n_bilateral == 0:
        return np.zeros((0, 0))
    block = np.ascontiguousarray(W[:n_bilateral, :n_bilateral])
    return bilateral_block_operator(block)[0]
