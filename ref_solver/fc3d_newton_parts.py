"""Kernels of the semismooth Newton method shared by its Python driver (:mod:`fc3d_newton`)
and its compiled dense form (:mod:`fc3d_newton_dense`): the Alart–Curnier system of the whole
problem, its dense Jacobian, the scalings, and the method's constants."""

from __future__ import annotations

import numpy as np
from numba import njit

from clearbench.ref_solver.fc3d_local import alart_curnier

ARMIJO = 1e-4
MAX_HALVINGS = 30
RESCUE_SWEEPS = 10
MAX_RESCUES = 50
DELTA_MIN = 1e-12
DENSE_LIMIT = 100  # rows; below, dense LU beats scipy.sparse overhead
DELTA_MAX = 1e-3


@njit(cache=True)
def alart_curnier_system(
    r: np.ndarray, u: np.ndarray, mu: np.ndarray, n_bilateral: int, rho_n: np.ndarray,
    rho_t: np.ndarray, rho_b: np.ndarray, phi: np.ndarray, A: np.ndarray, B: np.ndarray,
    want_jacobian: bool,
) -> float:
    """Phi (m,) and the contact blocks A, B (nc, 3, 3) of its Jacobian; returns 0.5 |Phi|^2."""
    merit = 0.0
    for b in range(n_bilateral):
        phi[b] = rho_b[b] * u[b]
        merit += phi[b] * phi[b]
    for i in range(mu.size):
        k = n_bilateral + 3 * i
        alart_curnier(r[k:k + 3], u[k:k + 3], mu[i], rho_n[i], rho_t[i], phi[k:k + 3], A[i],
                      B[i], want_jacobian)
        merit += phi[k] ** 2 + phi[k + 1] ** 2 + phi[k + 2] ** 2
    return 0.5 * merit


@njit(cache=True)
def dense_jacobian(W: np.ndarray, n_bilateral: int, rho_b: np.ndarray, A: np.ndarray,
                   B: np.ndarray, delta: float, J: np.ndarray) -> None:
    """J = A + B W + delta I as a dense (m, m) array (A, B block diagonal, W dense)."""
    m = W.shape[0]
    for b in range(n_bilateral):
        for col in range(m):
            J[b, col] = rho_b[b] * W[b, col]
        J[b, b] += delta
    for i in range(A.shape[0]):
        k = n_bilateral + 3 * i
        for a in range(3):
            for col in range(m):
                J[k + a, col] = B[i, a, 0] * W[k, col] + B[i, a, 1] * W[k + 1, col] \
                    + B[i, a, 2] * W[k + 2, col]
            for c in range(3):
                J[k + a, k + c] += A[i, a, c]
            J[k + a, k + a] += delta


@njit(cache=True)
def contact_scalings(blocks: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """rho_N = 1 / W_ii[N, N], rho_T = 1 / max(W_ii[T1, T1], W_ii[T2, T2]) per contact, (nc,)
    each (1 where the diagonal entry is not positive; rho_T falls back to rho_N)."""
    nc = blocks.shape[0]
    rho_n = np.ones(nc)
    rho_t = np.ones(nc)
    for i in range(nc):
        w_nn = blocks[i, 0, 0]
        w_tt = max(blocks[i, 1, 1], blocks[i, 2, 2])
        if w_nn > 0.0:
            rho_n[i] = 1.0 / w_nn
        rho_t[i] = 1.0 / w_tt if w_tt > 0.0 else rho_n[i]
    return rho_n, rho_t


@njit(cache=True)
def bilateral_scalings(w_bb: np.ndarray) -> np.ndarray:
    """rho_b = 1 / W_bb (1 where not positive), (nb,)."""
    rho_b = np.ones(w_bb.size)
    for b in range(w_bb.size):
        if w_bb[b] > 0.0:
            rho_b[b] = 1.0 / w_bb[b]
    return rho_b
