"""Exact solvers of the one-contact problem (3 unknowns), used by the Gauss–Seidel sweep.

Local problem of contact i once the others are frozen: u = Wl r + ql with Wl the (3, 3)
diagonal block of W and ql the free velocity plus the coupling, find r with
K* ∋ u + [mu |u_T|, 0, 0] ⊥ r ∈ K.

Strategy of :func:`solve_local` (kinds ``AC`` and ``FB``):

1. take-off: if ql_N >= 0, r = 0 is a solution (then û = ql + [mu |ql_T|, 0, 0] ∈ K*);
2. stick: if r = -Wl^-1 ql lies in K, it is a solution (u = 0);
3. slide: damped semismooth Newton on the Alart–Curnier function (or on the Fischer–Burmeister
   function of the second-order cone complementarity problem), Armijo line search on
   0.5 |Phi|^2, started from the warm start (FB: if it fails, AC Newton from where FB stopped,
   since FB loses its fast convergence at degenerate contacts); if it fails, Newton from a
   sliding guess, then
   projected fixed-point iterations and Newton again, then Newton on the other function (FB
   for AC, AC for FB). The best iterate (smallest natural-map residual) is kept.

Kind ``PROJECTION`` does one projection step r <- P_K(r - rho (u + [mu |u_T|, 0, 0])),
rho = 1 / Wl_NN, and nothing else (the "one projection per contact" variant of Siconos).

All functions are numba kernels working in caller-provided buffers: no allocation per contact.
``vec`` is a (N_VEC, 3) and ``mat`` an (N_MAT, 3, 3) scratch array.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from clearbench.ref_solver.fc3d_residual import contact_natural_map, project_on_cone

#: Local solver kinds (integers so that numba kernels can branch on them).
AC = 0
FB = 1
PROJECTION = 2
LOCAL_KIND = {"ac": AC, "fb": FB, "projection": PROJECTION}
#: ``want_jacobian`` flags as np.bool_ values: a literal True / False argument would compile
#: the local functions once for each.
_WITH, _WITHOUT = np.bool_(True), np.bool_(False)

N_VEC = 10
N_MAT = 8

# Rows of ``vec`` and ``mat`` (names for readability of the kernels).
_U, _PHI, _D, _RTRY, _UTRY, _PHITRY, _RBEST, _TMP, _TMP2, _TMP3 = range(10)
_A, _B, _J, _LU, _L1, _L2, _X, _Y = range(8)

#: Local solve outcome codes.
LOCAL_OK = 0
LOCAL_FAILED = 1

_FB_SMOOTHING = 1e-12  # relative smoothing of the FB Jacobian where sqrt(x^2 + y^2) is singular


def make_local_workspace() -> tuple[np.ndarray, np.ndarray]:
    """Scratch buffers (vec, mat) for the local kernels."""
    return np.zeros((N_VEC, 3)), np.zeros((N_MAT, 3, 3))


@njit(cache=True)
def solve3(A: np.ndarray, b: np.ndarray, x: np.ndarray, lu: np.ndarray) -> bool:
    """Solve the (3, 3) system A x = b by Gaussian elimination with partial pivoting.

    ``lu`` is a (3, 3) scratch array; returns False if A is (numerically) singular.
    """
    scale = 0.0
    for i in range(3):
        for j in range(3):
            lu[i, j] = A[i, j]
            scale = max(scale, abs(A[i, j]))
        x[i] = b[i]
    if not scale > 0.0:
        return False
    for k in range(3):
        pivot_row = k
        for i in range(k + 1, 3):
            if abs(lu[i, k]) > abs(lu[pivot_row, k]):
                pivot_row = i
        if abs(lu[pivot_row, k]) <= 1e-14 * scale:
            return False
        if pivot_row != k:
            for j in range(3):
                lu[k, j], lu[pivot_row, j] = lu[pivot_row, j], lu[k, j]
            x[k], x[pivot_row] = x[pivot_row], x[k]
        for i in range(k + 1, 3):
            factor = lu[i, k] / lu[k, k]
            for j in range(k, 3):
                lu[i, j] -= factor * lu[k, j]
            x[i] -= factor * x[k]
    for k in range(2, -1, -1):
        acc = x[k]
        for j in range(k + 1, 3):
            acc -= lu[k, j] * x[j]
        x[k] = acc / lu[k, k]
    return math.isfinite(x[0]) and math.isfinite(x[1]) and math.isfinite(x[2])


@njit(cache=True, inline="always")
def _velocity(Wl: np.ndarray, ql: np.ndarray, r: np.ndarray, u: np.ndarray) -> None:
    for i in range(3):
        u[i] = ql[i] + Wl[i, 0] * r[0] + Wl[i, 1] * r[1] + Wl[i, 2] * r[2]


@njit(cache=True)
def local_residual(r: np.ndarray, u: np.ndarray, ql: np.ndarray, mu: float) -> float:
    """Local natural-map residual |F_i| / max(|ql|, |r|, |u|) (|F_i| if all are 0)."""
    f0, f1, f2 = contact_natural_map(r[0], r[1], r[2], u[0], u[1], u[2], mu)
    scale = max(
        math.sqrt(ql[0] ** 2 + ql[1] ** 2 + ql[2] ** 2),
        math.sqrt(r[0] ** 2 + r[1] ** 2 + r[2] ** 2),
        math.sqrt(u[0] ** 2 + u[1] ** 2 + u[2] ** 2),
    )
    value = math.sqrt(f0 * f0 + f1 * f1 + f2 * f2)
    return value / scale if scale > 0.0 else value


@njit(cache=True)
def alart_curnier(
    r: np.ndarray, u: np.ndarray, mu: float, rho_n: float, rho_t: float,
    phi: np.ndarray, A: np.ndarray, B: np.ndarray, want_jacobian: bool,
) -> None:
    """Alart–Curnier function (Jean–Moreau variant of the disk radius) and its derivatives.

    Phi_N = r_N - max(0, s),  s = r_N - rho_n u_N,
    Phi_T = r_T - P_{D(0, mu max(0, s))}(r_T - rho_t u_T),
    so Phi = 0 iff (r, u) solves the contact law. With ``want_jacobian``, A = dPhi/dr and
    B = dPhi/du (one element of the generalised Jacobian), so J = A + B Wl.
    """
    s = r[0] - rho_n * u[0]
    active = s > 0.0
    radius = mu * s if active else 0.0
    phi[0] = r[0] - s if active else r[0]
    v1 = r[1] - rho_t * u[1]
    v2 = r[2] - rho_t * u[2]
    norm_v = math.hypot(v1, v2)
    inside = norm_v <= radius
    if inside:
        phi[1] = r[1] - v1
        phi[2] = r[2] - v2
    else:
        phi[1] = r[1] - radius * v1 / norm_v
        phi[2] = r[2] - radius * v2 / norm_v
    if not want_jacobian:
        return
    for i in range(3):
        for j in range(3):
            A[i, j] = 0.0
            B[i, j] = 0.0
    if active:
        B[0, 0] = rho_n
    else:
        A[0, 0] = 1.0
    if inside:
        B[1, 1] = rho_t
        B[2, 2] = rho_t
    else:
        e1 = v1 / norm_v
        e2 = v2 / norm_v
        ratio = radius / norm_v
        # d(P)/dv = ratio (I - e e^T); d(P)/dR = e; dR = mu [s > 0] (dr_N - rho_n du_N)
        p11 = ratio * (1.0 - e1 * e1)
        p12 = -ratio * e1 * e2
        p22 = ratio * (1.0 - e2 * e2)
        A[1, 1] = 1.0 - p11
        A[1, 2] = -p12
        A[2, 1] = -p12
        A[2, 2] = 1.0 - p22
        B[1, 1] = rho_t * p11
        B[1, 2] = rho_t * p12
        B[2, 1] = rho_t * p12
        B[2, 2] = rho_t * p22
        if active:
            A[1, 0] = -mu * e1
            A[2, 0] = -mu * e2
            B[1, 0] = mu * rho_n * e1
            B[2, 0] = mu * rho_n * e2


@njit(cache=True, inline="always")
def _jordan_sqrt(z0: float, z1: float, z2: float) -> tuple[float, float, float]:
    """Square root in the Jordan algebra of the Lorentz cone (z in the cone)."""
    norm_bar = math.hypot(z1, z2)
    lam1 = math.sqrt(max(z0 - norm_bar, 0.0))
    lam2 = math.sqrt(max(z0 + norm_bar, 0.0))
    w0 = 0.5 * (lam1 + lam2)
    if norm_bar > 0.0:
        c = 0.5 * (lam2 - lam1) / norm_bar
        return w0, c * z1, c * z2
    return w0, 0.0, 0.0


@njit(cache=True, inline="always")
def _arrow(a0: float, a1: float, a2: float, L: np.ndarray) -> None:
    """Arrow matrix L_a = [[a0, a_bar^T], [a_bar, a0 I]] of the Jordan product a o x."""
    L[0, 0] = a0
    L[0, 1] = a1
    L[0, 2] = a2
    L[1, 0] = a1
    L[1, 1] = a0
    L[1, 2] = 0.0
    L[2, 0] = a2
    L[2, 1] = 0.0
    L[2, 2] = a0


@njit(cache=True)
def fischer_burmeister(
    r: np.ndarray, u: np.ndarray, Wl: np.ndarray, mu: float,
    phi: np.ndarray, J: np.ndarray, mat: np.ndarray, vec: np.ndarray, want_jacobian: bool,
) -> None:
    """Fischer–Burmeister function of the contact law and its Jacobian J = dPhi/dr.

    With x = (mu r_N, r_T) and y = (û_N, mu û_T), û = u + [mu |u_T|, 0, 0], the law is the
    Lorentz-cone complementarity K_1 ∋ x ⊥ y ∈ K_1, and Phi = x + y - sqrt(x^2 + y^2)
    (Jordan algebra). The Jacobian uses sqrt of (x^2 + y^2 + eps e) when that is singular.
    """
    norm_ut = math.hypot(u[1], u[2])
    x0, x1, x2 = mu * r[0], r[1], r[2]
    y0, y1, y2 = u[0] + mu * norm_ut, mu * u[1], mu * u[2]
    z0 = x0 * x0 + x1 * x1 + x2 * x2 + y0 * y0 + y1 * y1 + y2 * y2
    z1 = 2.0 * (x0 * x1 + y0 * y1)
    z2 = 2.0 * (x0 * x2 + y0 * y2)
    w0, w1, w2 = _jordan_sqrt(z0, z1, z2)
    phi[0] = x0 + y0 - w0
    phi[1] = x1 + y1 - w1
    phi[2] = x2 + y2 - w2
    if not want_jacobian:
        return
    # dx/dr = diag(mu, 1, 1); dy/dr = S (I + mu e_N g^T) Wl, S = diag(1, mu, mu), g = (0, u_T/|u_T|)
    Dy = mat[_Y]
    g1 = u[1] / norm_ut if norm_ut > 0.0 else 0.0
    g2 = u[2] / norm_ut if norm_ut > 0.0 else 0.0
    for j in range(3):
        Dy[0, j] = Wl[0, j] + mu * (g1 * Wl[1, j] + g2 * Wl[2, j])
        Dy[1, j] = mu * Wl[1, j]
        Dy[2, j] = mu * Wl[2, j]
    eps = _FB_SMOOTHING * max(z0, 1e-300)
    w_min = w0 - math.hypot(w1, w2)
    if w_min * w_min < eps:
        w0, w1, w2 = _jordan_sqrt(z0 + 2.0 * eps, z1, z2)
    Lx = mat[_L1]
    Ly = mat[_L2]
    _arrow(x0, x1, x2, Lx)
    _arrow(y0, y1, y2, Ly)
    Lw = mat[_A]
    _arrow(w0, w1, w2, Lw)
    # M = Lx Dx + Ly Dy, then X = Lw^-1 M column by column; J = Dx + Dy - X
    col = vec[_TMP]
    sol = vec[_TMP2]
    for j in range(3):
        dxj = mu if j == 0 else 1.0
        for i in range(3):
            col[i] = (Lx[i, j] * dxj + Ly[i, 0] * Dy[0, j] + Ly[i, 1] * Dy[1, j]
                      + Ly[i, 2] * Dy[2, j])
        if not solve3(Lw, col, sol, mat[_LU]):
            sol[0] = 0.0
            sol[1] = 0.0
            sol[2] = 0.0
        for i in range(3):
            J[i, j] = Dy[i, j] - sol[i] + (dxj if i == j else 0.0)


@njit(cache=True)
def _merit_and_jacobian(
    kind: int, Wl: np.ndarray, ql: np.ndarray, mu: float, rho_n: float, rho_t: float,
    r: np.ndarray, u: np.ndarray, phi: np.ndarray, mat: np.ndarray, vec: np.ndarray,
    want_jacobian: bool,
) -> float:
    """Compute u, Phi (and J in mat[_J] if asked) at r; return 0.5 |Phi|^2."""
    _velocity(Wl, ql, r, u)
    if kind == FB:
        fischer_burmeister(r, u, Wl, mu, phi, mat[_J], mat, vec, want_jacobian)
    else:
        A = mat[_A]
        B = mat[_B]
        alart_curnier(r, u, mu, rho_n, rho_t, phi, A, B, want_jacobian)
        if want_jacobian:
            J = mat[_J]
            for i in range(3):
                for j in range(3):
                    J[i, j] = A[i, j] + B[i, 0] * Wl[0, j] + B[i, 1] * Wl[1, j] + B[i, 2] * Wl[2, j]
    return 0.5 * (phi[0] * phi[0] + phi[1] * phi[1] + phi[2] * phi[2])


@njit(cache=True)
def _newton(
    kind: int, Wl: np.ndarray, ql: np.ndarray, mu: float, rho_n: float, rho_t: float,
    r: np.ndarray, tolerance: float, max_iterations: int, vec: np.ndarray, mat: np.ndarray,
) -> float:
    """Damped semismooth Newton on the local function; r is updated in place.

    Returns the local natural-map residual at the final r.
    """
    u = vec[_U]
    phi = vec[_PHI]
    d = vec[_D]
    r_try = vec[_RTRY]
    u_try = vec[_UTRY]
    phi_try = vec[_PHITRY]
    merit = _merit_and_jacobian(kind, Wl, ql, mu, rho_n, rho_t, r, u, phi, mat, vec, _WITH)
    residual = local_residual(r, u, ql, mu)
    slow_steps = 0
    for _ in range(max_iterations):
        if residual <= tolerance or slow_steps >= 3:  # converged, or stagnating: let the
            break  # caller's fall-backs take over rather than crawl
        for i in range(3):
            vec[_TMP3, i] = -phi[i]
        if not solve3(mat[_J], vec[_TMP3], d, mat[_LU]):
            break
        step = 1.0
        accepted = False
        for _ls in range(30):
            for i in range(3):
                r_try[i] = r[i] + step * d[i]
            merit_try = _merit_and_jacobian(
                kind, Wl, ql, mu, rho_n, rho_t, r_try, u_try, phi_try, mat, vec, _WITHOUT
            )
            if merit_try <= (1.0 - 2e-4 * step) * merit:
                accepted = True
                break
            step *= 0.5
        if not accepted:
            break
        for i in range(3):
            r[i] = r_try[i]
        merit = _merit_and_jacobian(kind, Wl, ql, mu, rho_n, rho_t, r, u, phi, mat, vec, _WITH)
        previous = residual
        residual = local_residual(r, u, ql, mu)
        slow_steps = slow_steps + 1 if residual > 0.5 * previous else 0
    return residual


@njit(cache=True)
def _projection_step(
    Wl: np.ndarray, ql: np.ndarray, mu: float, rho: float, r: np.ndarray, u: np.ndarray
) -> None:
    """r <- P_K(r - rho (Wl r + ql + [mu |u_T|, 0, 0])) in place (u is scratch)."""
    _velocity(Wl, ql, r, u)
    norm_ut = math.hypot(u[1], u[2])
    p0, p1, p2 = project_on_cone(
        r[0] - rho * (u[0] + mu * norm_ut), r[1] - rho * u[1], r[2] - rho * u[2], mu
    )
    r[0] = p0
    r[1] = p1
    r[2] = p2


@njit(cache=True)
def _keep_best(r: np.ndarray, residual: float, best: np.ndarray, best_residual: float) -> float:
    if residual < best_residual:
        for i in range(3):
            best[i] = r[i]
        return residual
    return best_residual


@njit(cache=True)
def solve_local(
    kind: int, Wl: np.ndarray, ql: np.ndarray, mu: float, r: np.ndarray,
    tolerance: float, max_iterations: int, vec: np.ndarray, mat: np.ndarray,
) -> int:
    """Solve the one-contact problem (Wl (3, 3), ql (3,), mu); r (3,) is warm start and output.

    Returns LOCAL_OK when the local natural-map residual |F_i| / max(|ql|, |r|, |u|) is
    <= tolerance, else LOCAL_FAILED (r is then the best iterate found). PROJECTION does a
    single step and always returns LOCAL_OK.
    """
    u = vec[_U]
    w_nn = Wl[0, 0]
    if kind == PROJECTION:
        rho = 1.0 / w_nn if w_nn > 0.0 else 1.0
        _projection_step(Wl, ql, mu, rho, r, u)
        return LOCAL_OK
    # 1. take-off
    if ql[0] >= 0.0:
        r[0] = 0.0
        r[1] = 0.0
        r[2] = 0.0
        return LOCAL_OK
    # 2. stick: r = -Wl^-1 ql inside K
    stick = vec[_TMP2]
    for i in range(3):
        vec[_TMP3, i] = -ql[i]
    stick_ok = solve3(Wl, vec[_TMP3], stick, mat[_LU])
    if stick_ok:
        if stick[0] >= 0.0 and math.hypot(stick[1], stick[2]) <= mu * stick[0]:
            for i in range(3):
                r[i] = stick[i]
            return LOCAL_OK
    # 3. slide: Newton from the warm start (or from the projected stick guess at r = 0)
    if r[0] <= 0.0 and stick_ok:
        p0, p1, p2 = project_on_cone(stick[0], stick[1], stick[2], mu)
        if p0 > 0.0:
            r[0] = p0
            r[1] = p1
            r[2] = p2
    rho_n = 1.0 / w_nn if w_nn > 0.0 else 1.0
    w_tt = max(Wl[1, 1], Wl[2, 2])
    rho_t = 1.0 / w_tt if w_tt > 0.0 else rho_n
    best = vec[_RBEST]
    residual = _newton(kind, Wl, ql, mu, rho_n, rho_t, r, tolerance, max_iterations, vec, mat)
    if residual <= tolerance:
        return LOCAL_OK
    best_residual = _keep_best(r, residual, best, np.inf)
    if kind == FB:  # FB loses its fast convergence at degenerate contacts: AC from there
        residual = _newton(np.int64(AC), Wl, ql, mu, rho_n, rho_t, r, tolerance, max_iterations,
                           vec, mat)
        best_residual = _keep_best(r, residual, best, best_residual)
        if best_residual <= tolerance:
            for i in range(3):
                r[i] = best[i]
            return LOCAL_OK
    # 4. second start: sliding against the tangential velocity that the normal impulse alone
    #    would leave, r = r_N (1, -mu e), r_N = -ql_N / W_NN
    if w_nn > 0.0:
        r[0] = -ql[0] / w_nn
        t1 = ql[1] + Wl[1, 0] * r[0]
        t2 = ql[2] + Wl[2, 0] * r[0]
        norm_t = math.hypot(t1, t2)
        r[1] = -mu * r[0] * t1 / norm_t if norm_t > 0.0 else 0.0
        r[2] = -mu * r[0] * t2 / norm_t if norm_t > 0.0 else 0.0
        residual = _newton(kind, Wl, ql, mu, rho_n, rho_t, r, tolerance, max_iterations, vec,
                           mat)
        best_residual = _keep_best(r, residual, best, best_residual)
        if best_residual <= tolerance:
            for i in range(3):
                r[i] = best[i]
            return LOCAL_OK
    # 5. fall-back: projected fixed-point iterations with a small step, then Newton again
    norm_w = 0.0
    for i in range(3):
        for j in range(3):
            norm_w += Wl[i, j] * Wl[i, j]
    rho = 1.0 / math.sqrt(norm_w) if norm_w > 0.0 else 1.0
    for _ in range(100):
        _projection_step(Wl, ql, mu, rho, r, u)
    _velocity(Wl, ql, r, u)
    best_residual = _keep_best(r, local_residual(r, u, ql, mu), best, best_residual)
    residual = _newton(kind, Wl, ql, mu, rho_n, rho_t, r, tolerance, max_iterations, vec, mat)
    best_residual = _keep_best(r, residual, best, best_residual)
    if best_residual > tolerance:  # still stuck: the other local function, from the best point
        for i in range(3):
            r[i] = best[i]
        other = np.int64(AC) if kind == FB else np.int64(FB)
        residual = _newton(other, Wl, ql, mu, rho_n, rho_t, r, tolerance, max_iterations, vec,
                           mat)
        best_residual = _keep_best(r, residual, best, best_residual)
    for i in range(3):
        r[i] = best[i]
    return LOCAL_OK if best_residual <= tolerance else LOCAL_FAILED
