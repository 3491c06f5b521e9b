"""Proximal-point Newton on a dense one-step problem: the hybrid chain's attempt after its Newton
attempts (from NSGS's end, the warm start and zero) failed (``StepperSettings.proximal_rescue``).

The C-60's problems that the chain leaves unconverged have a rank-deficient Delassus operator
(the redundant contacts of a bearing's two rings: rank 43-48 of 52-64 rows on ``c60-trip``,
``tools/unconverged_steps.py``), where Newton's direction crawls and NSGS stops at a floor. The
proximal-point iteration solves instead a sequence of problems whose operator W + rho I is
positive definite,

    r_{k+1} solves (W + rho I, q - rho r_k, mu),

each by the semismooth Newton kernel started from r_k. Its velocity (W + rho I) r_{k+1} + q -
rho r_k is W r_{k+1} + q + rho (r_{k+1} - r_k): a fixed point solves the original problem, and
the iterate is judged on the original problem's residual (Rockafellar's proximal point
algorithm; Carpentier et al. 2024, arXiv 2405.17020, use it for ill-conditioned Delassus
operators of rigid contact). rho = ``relative_weight`` x the largest diagonal entry of W (a
contact's own compliance), small enough that the fixed point is reached in a few outer
iterations, large enough to lift the rank deficiency above round-off.
"""

from __future__ import annotations

import numpy as np

from clearbench.kernels.jit import njit
from clearbench.ref_solver.dense_kernels import residuals, roundoff_floor_dense
from clearbench.ref_solver.fc3d_newton_dense import newton_dense_kernel

#: The default relative weight (``StepperSettings.proximal_rescue``): on c60-trip's four
#: unconverged problems at 1 us it reaches the fixed point in 2-4 outer iterations, to
#: residuals of 2.5e-14 to 9.6e-13 (docs/reference-solver-speed.md, "A proximal-point rescue").
DEFAULT_RELATIVE_WEIGHT = 1e-8
#: Outer (proximal) iterations at most: on c60-trip's four unconverged problems at 1 us the
#: fixed point is reached in 2-4 (rho = 1e-8 x the largest diagonal entry of W).
PROXIMAL_OUTER_ITERATIONS = 10
#: Each subproblem is solved to this fraction of the tolerance, so that its error does not
#: hold the outer iteration above the tolerance.
INNER_TOLERANCE_FACTOR = 1e-2
#: The Newton kernel's stall test off (as ``compiled.contact_solve.NO_STALL``).
_NO_STALL = np.int64(0)


@njit(cache=True)
def proximal_newton_dense(W, q, mu, n_bilateral, r0, relative_weight, tolerance, use_max,
                          inner_iterations, use_floor, local_tolerance, local_max_iterations,
                          history, outer_iterations):
    """Proximal-point Newton (module docstring) on (W (m, m), q (m,), mu (nc,), n_bilateral)
    from ``r0`` (m,) (not modified): at most ``outer_iterations`` (the chain passes
    ``PROXIMAL_OUTER_ITERATIONS``) outer iterations of at most ``inner_iterations`` Newton
    iterations each. ``history`` (>= inner_iterations,): scratch.

    Returns (r (m,), u = W r + q (m,), Newton iterations summed over the outer iterations,
    the original problem's residual |F| / |q|, the same / max(|q|, |r|, |u|), the one of the
    two ``use_max`` tests, converged): converged when the tested residual is at most
    ``tolerance`` or, with ``use_floor``, its round-off floor.
    """
    m = q.size
    scale = 0.0
    for i in range(m):
        scale = max(scale, W[i, i])
    weight = relative_weight * scale
    shifted_operator = W.copy()
    for i in range(m):
        shifted_operator[i, i] += weight
    r = r0.copy()
    u = np.empty(m)
    shifted_q = np.empty(m)
    iterations = 0
    residual_q = residual_max = residual = np.inf
    for _ in range(outer_iterations):
        for i in range(m):
            shifted_q[i] = q[i] - weight * r[i]
        _, inner, _, _, _, _, _, _ = newton_dense_kernel(
            shifted_operator, shifted_q, mu, n_bilateral, r, u,
            tolerance * INNER_TOLERANCE_FACTOR, use_max, inner_iterations, use_floor,
            _NO_STALL, _NO_STALL, local_tolerance, local_max_iterations, history,
            np.bool_(False))
        iterations += inner
        u = W @ r + q
        _, residual_q, residual_max = residuals(r, u, q, mu, n_bilateral)
        residual = residual_max if use_max else residual_q
        if residual <= tolerance or (
                use_floor and residual <= roundoff_floor_dense(W, r, u, q, mu, use_max)):
            return r, u, iterations, residual_q, residual_max, residual, True
    return r, u, iterations, residual_q, residual_max, residual, False
