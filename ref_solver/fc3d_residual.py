"""Natural-map residual of the frictional contact problem, and the cone projection it uses.

Per contact i (rows N, T1, T2), with the modified velocity û_i = u_i + [mu_i |u_Ti|, 0, 0]:

    F_i(r) = r_i - P_{K_i}(r_i - û_i),        K_i = {|r_T| <= mu_i r_N},

and per bilateral row b: F_b = r_b - (r_b - u_b) = u_b. F = 0 exactly at a solution. The
residual is |F| (2-norm over all rows), normalised as in :class:`Normalisation`. The per-contact
formula is the one of Siconos's ``fc3d_unitary_compute_and_add_error`` (rho = 1).
"""

from __future__ import annotations

import math

import numpy as np
import scipy.sparse as sp
from numba import njit

from clearbench.ref_solver.contact_problem import Normalisation


@njit(cache=True, inline="always")
def project_on_cone(x0: float, x1: float, x2: float, mu: float) -> tuple[float, float, float]:
    """Euclidean projection of x = (x_N, x_T1, x_T2) on K = {|x_T| <= mu x_N}."""
    norm_t = math.hypot(x1, x2)
    # x0 >= 0 matters for mu = 0, where K is the ray {x_T = 0, x_N >= 0}: without it a point
    # (x_N < 0, 0, 0) passes as inside K, since 0 <= 0 * x_N = -0.0 holds in IEEE arithmetic.
    if x0 >= 0.0 and norm_t <= mu * x0:  # inside K
        return x0, x1, x2
    if mu * norm_t <= -x0:  # inside the polar cone -K*: projection is the apex
        return 0.0, 0.0, 0.0
    a = (x0 + mu * norm_t) / (1.0 + mu * mu)
    s = mu * a / norm_t
    return a, s * x1, s * x2


@njit(cache=True, inline="always")
def contact_natural_map(
    r0: float, r1: float, r2: float, u0: float, u1: float, u2: float, mu: float
) -> tuple[float, float, float]:
    """F_i = r - P_K(r - (u + [mu |u_T|, 0, 0])) for one contact."""
    p0, p1, p2 = project_on_cone(r0 - u0 - mu * math.hypot(u1, u2), r1 - u1, r2 - u2, mu)
    return r0 - p0, r1 - p1, r2 - p2


@njit(cache=True)
def natural_map_squared(r: np.ndarray, u: np.ndarray, mu: np.ndarray, n_bilateral: int) -> float:
    """|F|^2 for given r, u (u must be W r + q); shapes (m,), (m,), (nc,)."""
    total = 0.0
    for b in range(n_bilateral):
        total += u[b] * u[b]
    for i in range(mu.size):
        k = n_bilateral + 3 * i
        f0, f1, f2 = contact_natural_map(r[k], r[k + 1], r[k + 2], u[k], u[k + 1], u[k + 2], mu[i])
        total += f0 * f0 + f1 * f1 + f2 * f2
    return total


@njit(cache=True)
def csr_matvec_plus(
    indptr: np.ndarray, indices: np.ndarray, data: np.ndarray, x: np.ndarray, q: np.ndarray,
    out: np.ndarray,
) -> None:
    """out = A x + q for A in CSR arrays (in place)."""
    for row in range(q.size):
        acc = q[row]
        for k in range(indptr[row], indptr[row + 1]):
            acc += data[k] * x[indices[k]]
        out[row] = acc


@njit(cache=True)
def normalised(abs_residual: float, norm_q: float, norm_r: float, norm_u: float,
               use_max: bool) -> float:
    """Divide |F| by |q| (use_max False) or max(|q|, |r|, |u|); a zero denominator gives |F|."""
    denominator = max(norm_q, norm_r, norm_u) if use_max else norm_q
    if denominator > 0.0:
        return abs_residual / denominator
    return abs_residual


def roundoff_floor(W_abs, r: np.ndarray, u: np.ndarray, q: np.ndarray, mu: np.ndarray,
                   use_max: bool) -> float:
    """Bound on the rounding error of the normalised residual evaluated at ``r``.

    u = W r + q computed in floating point is off by at most gamma_(m+1) (|W| |r| + |q|) per
    row (Higham, *Accuracy and Stability of Numerical Algorithms*, 2002, Sec. 3.5, with
    gamma_n = n eps / (1 - n eps)); the modified velocity u + [mu |u_T|, 0, 0] carries at most
    (1 + mu) times that, the projection on the cone does not enlarge it (non-expansive), and
    forming r - P(.) adds 2 eps |r|. A residual below this bound cannot be told from zero: at
    the exact solution the computed residual may be this large.

    Parameters
    ----------
    W_abs : ndarray or scipy.sparse matrix, shape (m, m)
        |W|, elementwise.
    r, u, q : ndarray, shape (m,)
        Impulses, their velocities W r + q, the free velocities.
    mu : ndarray, shape (nc,)
    use_max : bool
        The normalisation of the residual it is compared with (as :func:`normalised`).
    """
    velocity_error = np.asarray(W_abs @ np.abs(r)).ravel() + np.abs(q)
    return floor_of_velocity_error(math.sqrt(velocity_error.dot(velocity_error)), r, u, q, mu,
                                   use_max)


@njit(cache=True)
def floor_of_velocity_error(velocity_error: float, r: np.ndarray, u: np.ndarray,
                            q: np.ndarray, mu: np.ndarray, use_max: bool) -> float:
    """The bound of :func:`roundoff_floor` from the 2-norm ``velocity_error`` of
    |W| |r| + |q| (m,): the one formula of the sparse, dense and CSR floors."""
    m = q.size
    eps = 2.220446049250313e-16
    gamma = (m + 1) * eps / (1.0 - (m + 1) * eps)
    largest_mu = 0.0
    for i in range(mu.size):
        largest_mu = max(largest_mu, mu[i])
    norm_r = math.sqrt(np.dot(r, r))
    bound = (1.0 + largest_mu) * gamma * velocity_error + 2.0 * eps * norm_r
    return normalised(bound, math.sqrt(np.dot(q, q)), norm_r, math.sqrt(np.dot(u, u)), use_max)


@njit(cache=True)
def roundoff_floor_csr(indptr: np.ndarray, indices: np.ndarray, data: np.ndarray,
                       r: np.ndarray, u: np.ndarray, q: np.ndarray, mu: np.ndarray,
                       use_max: bool) -> float:
    """:func:`roundoff_floor` for W in CSR arrays (indptr (m + 1,), indices, data), without
    forming |W|."""
    total = 0.0
    for row in range(q.size):
        acc = 0.0
        for k in range(indptr[row], indptr[row + 1]):
            acc += abs(data[k]) * abs(r[indices[k]])
        acc += abs(q[row])
        total += acc * acc
    return floor_of_velocity_error(math.sqrt(total), r, u, q, mu, use_max)


@njit(cache=True)
def hopeless(earlier: float, now: float, window: int, tolerance: float, left: int) -> bool:
    """True when going on from ``now`` at the mean rate of the last ``window`` iterations (from
    ``earlier``) would not bring the residual to ``tolerance`` within the ``left`` iterations
    the cap allows (no decrease at all counts as hopeless). Used by
    ``SolverOptions.stall_window``."""
    if now <= tolerance:
        return False
    if not now < earlier:
        return True
    rate = math.log(now / earlier) / window  # < 0: log of the mean factor per iteration
    return math.log(tolerance / now) / rate > left


def abs_operator_of(problem) -> np.ndarray | sp.csr_matrix:
    """|W| of ``problem`` (dense or CSR as its W), computed once per problem."""
    return problem.derived("abs_W", lambda p: abs(p.W))


def floor_message(residual: float, floor: float, tolerance: float) -> str:
    """What a result accepted on :func:`roundoff_floor` says."""
    return (f"converged to round-off: residual {residual:.3g} > tolerance {tolerance:.3g} "
            f"but below its rounding-error bound {floor:.3g}")


def residual_both(
    r: np.ndarray, u: np.ndarray, q: np.ndarray, mu: np.ndarray, n_bilateral: int
) -> tuple[float, float, float]:
    """Return (|F|, |F|/|q|, |F|/max(|q|,|r|,|u|)) for r and u = W r + q."""
    abs_residual = math.sqrt(natural_map_squared(r, u, mu, n_bilateral))
    # sqrt(v . v) is what np.linalg.norm computes for a real vector, without its ~2 us of
    # Python dispatch (this runs once per Newton iteration)
    norm_q, norm_r, norm_u = math.sqrt(q.dot(q)), math.sqrt(r.dot(r)), math.sqrt(u.dot(u))
    return (
        abs_residual,
        normalised(abs_residual, norm_q, norm_r, norm_u, False),
        normalised(abs_residual, norm_q, norm_r, norm_u, True),
    )


def natural_map_residual(
    W, q: np.ndarray, mu: np.ndarray, r: np.ndarray, n_bilateral: int = 0,
    normalisation: str | Normalisation = "max",
) -> float:
    """Normalised natural-map residual of r for the problem (W, q, mu, n_bilateral).

    Parameters
    ----------
    W : ndarray or scipy.sparse matrix, shape (m, m)
    q : ndarray, shape (m,)
    mu : ndarray, shape (nc,)
    r : ndarray, shape (m,)
        Candidate impulses.
    n_bilateral : int
        Number of leading equality rows (their residual is u_b).
    normalisation : {"max", "q"} or Normalisation
        "max": |F| / max(|q|, |r|, |u|) (Siconos's ``fc3d_compute_error`` with norm = |q|);
        "q": |F| / |q|. A zero denominator returns |F| unnormalised.

    Returns
    -------
    float
        The dimensionless residual; 0 at an exact solution.
    """
    normalisation = Normalisation(normalisation)
    q = np.asarray(q, dtype=np.float64)
    r = np.asarray(r, dtype=np.float64)
    mu = np.asarray(mu, dtype=np.float64)
    W = W if sp.issparse(W) else np.asarray(W, dtype=np.float64)
    u = np.asarray(W @ r, dtype=np.float64).ravel() + q
    _, rel_q, rel_max = residual_both(r, u, q, mu, int(n_bilateral))
    return rel_max if normalisation is Normalisation.MAX else rel_q
