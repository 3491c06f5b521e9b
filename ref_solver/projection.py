"""Multipliers of the position-projection stage: a small mixed LCP solved by an active set.

The projection of the combined scheme is the quadratic program

    min 1/2 dxi^T M dxi   s.t.   h + J dxi = 0 (joints),   g + G dxi >= 0 (active contacts),

whose dual is the mixed LCP  w = W delta + b,  w_E = 0,  0 <= w_I  perp  delta_I >= 0, with
W = H M^-1 H^T, b = (h, g). Redundant constraints (the two bearing rings of a clearance joint,
closed kinematic loops) make W singular; the correction dxi = M^-1 H^T delta is unique all the
same. An active-set method with minimum-norm least-squares solves handles that exactly where a
projected Gauss–Seidel crawls. Sizes here are tens of rows, so dense SVD solves are cheap.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class ProjectionSolve:
    """Multipliers ``delta`` (m,), the constraint values after the linear correction
    ``w = W delta + b`` (m,), iterations, and whether the active set settled."""

    delta: np.ndarray
    w: np.ndarray
    iterations: int
    converged: bool


def solve_projection(W: np.ndarray, b: np.ndarray, n_equal: int, tolerance: float,
                     max_iterations: int = 50) -> ProjectionSolve:
    """Active-set solve of the mixed LCP of the projection stage.

    Parameters
    ----------
    W : (m, m) symmetric positive semi-definite [L per multiplier unit]
    b : (m,) constraint values (joint violations, then contact gaps) [L]
    n_equal : int
        Leading equality rows.
    tolerance : float
        Feasibility tolerance on w [L].
    """
    m = b.shape[0]
    unilateral = np.arange(n_equal, m)
    active = np.zeros(m, dtype=bool)
    active[:n_equal] = True
    active[unilateral] = b[unilateral] < 0.0
    delta = np.zeros(m)
    for iteration in range(1, max_iterations + 1):
        delta[:] = 0.0
        idx = np.nonzero(active)[0]
        if idx.size:
            solution, *_ = np.linalg.lstsq(W[np.ix_(idx, idx)], -b[idx], rcond=1e-12)
            delta[idx] = solution
        # Drop unilateral rows that pull (negative multiplier), most negative first.
        pulling = [i for i in idx if i >= n_equal and delta[i] < 0.0]
        if pulling:
            active[min(pulling, key=lambda i: delta[i])] = False
            continue
        w = W @ delta + b
        violated = [i for i in unilateral if not active[i] and w[i] < -tolerance]
        if not violated:
            return ProjectionSolve(delta, w, iteration, True)
        active[min(violated, key=lambda i: w[i])] = True
    return ProjectionSolve(delta, W @ delta + b, max_iterations, False)
