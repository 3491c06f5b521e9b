"""The one-step contact solve of ``MoreauJeanStepper._solve``, compiled: NSGS, Newton (with the
least-norm retry) or the ``hybrid`` chain, on a dense problem (W (m, m), q (m,), mu (nc,)).

The kernels are those of the Python path (:func:`fc3d_nsgs.nsgs_kernel`,
:func:`fc3d_newton_dense.newton_dense_kernel`); only the Python around them (options, result
objects, the chain's bookkeeping) is written here again, in numba. One difference: Newton
always takes the dense kernel, where the Python path takes its sparse driver above
``DENSE_LIMIT`` rows (the same direction and line search, assembled sparse): the results
agree to round-off.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from clearbench.ref_solver.contact_problem import _dense_to_csr
from clearbench.ref_solver.dense_kernels import bilateral_operator_dense
from clearbench.ref_solver.fc3d_newton_dense import CONVERGED, ROUNDOFF, newton_dense_kernel
from clearbench.ref_solver.fc3d_nsgs import ROUNDOFF_CODE as NSGS_ROUNDOFF
from clearbench.ref_solver.fc3d_nsgs import nsgs_kernel
from clearbench.ref_solver.fc3d_proximal import PROXIMAL_OUTER_ITERATIONS, proximal_newton_dense

#: Method codes of :class:`.system_arrays.LoopSettings` (``StepperSettings.method``).
METHOD_NSGS, METHOD_NEWTON, METHOD_HYBRID = 0, 1, 2
METHOD_CODES = {"nsgs": METHOD_NSGS, "newton": METHOD_NEWTON, "hybrid": METHOD_HYBRID}
#: ``newton_first`` codes: no Newton first, the regularised Newton, the least-norm Newton.
NO_NEWTON_FIRST, REGULARISED_FIRST, LEAST_NORM_FIRST = 0, 1, 2
#: Iteration cap of the hybrid chain's Newton attempts (as ``MoreauJeanStepper``).
HYBRID_NEWTON_ITERATIONS = 200
#: The solvers' stall test off (``stall_window``, ``stall_after``). Constants passed to a
#: kernel are typed as literals, and numba compiles a kernel once per distinct literal
#: argument: scalars reach the kernels as ``np.int64`` / ``np.bool_`` values, the types a call
#: from Python has, so that each kernel is compiled once.
NO_STALL = np.int64(0)
#: The proximal attempt's outer iterations, typed as the other scalars.
PROXIMAL_OUTER = np.int64(PROXIMAL_OUTER_ITERATIONS)


@njit(cache=True)
def _nsgs(csr, q, mu, n_bilateral, operator, r0, max_sweeps, cfg, history):
    """NSGS from ``r0`` (m,) (not modified), as :func:`fc3d_nsgs.solve_nsgs`: (r (m,), sweeps,
    residual, converged); a residual above the tolerance but under its round-off floor at a
    check counts as converged when ``cfg.roundoff_floor``."""
    r = r0.copy()
    u = np.empty(q.size)
    data, indices, indptr = csr
    code, sweeps, residual_q, residual_max, _, _ = nsgs_kernel(
        indptr, indices, data, q, mu, n_bilateral, operator, r, u, cfg.local_kind,
        cfg.tolerance, cfg.use_max, np.int64(max_sweeps), cfg.local_tolerance,
        cfg.local_max_iterations, cfg.check_interval, history, NO_STALL, NO_STALL,
        cfg.roundoff_floor)
    residual = residual_max if cfg.use_max else residual_q
    converged = code == 0 or code == NSGS_ROUNDOFF
    return r, sweeps, residual, converged


@njit(cache=True)
def _newton(w, q, mu, n_bilateral, r0, max_iterations, least_norm, cfg, history):
    """Semismooth Newton from ``r0`` (not modified), as :func:`fc3d_newton.solve_newton`:
    (r, iterations, residual, converged)."""
    r = r0.copy()
    u = np.empty(q.size)
    code, iterations, residual, _, _, _, _, _ = newton_dense_kernel(
        w, q, mu, n_bilateral, r, u, cfg.tolerance, cfg.use_max, np.int64(max_iterations),
        cfg.roundoff_floor, NO_STALL, NO_STALL, cfg.local_tolerance, cfg.local_max_iterations,
        history, np.bool_(least_norm))
    return r, iterations, residual, code == CONVERGED or code == ROUNDOFF


@njit(cache=True)
def solve(w, q, mu, n_bilateral, r0, cfg, newton_first, history):
    """The one-step problem by ``cfg.method`` from the warm start ``r0`` (m,).

    ``newton_first`` (1,) int64: the hybrid chain's memory of the Newton that solved the last
    problem (``NO_NEWTON_FIRST``, ``REGULARISED_FIRST``, ``LEAST_NORM_FIRST``), updated in
    place. ``history`` (>= every iteration cap,): scratch. Returns (r (m,), iterations summed
    over the attempts, residual, converged) of the attempt kept (``MoreauJeanStepper._solve``).
    """
    zeros = np.zeros(q.size)
    if cfg.method == METHOD_NEWTON:
        r, its, res, ok = _newton(w, q, mu, n_bilateral, r0, cfg.max_iterations, False, cfg,
                                  history)
        if ok:
            return r, its, res, ok
        r2, its2, res2, ok2 = _newton(w, q, mu, n_bilateral, r0, HYBRID_NEWTON_ITERATIONS,
                                      True, cfg, history)
        if ok2 or res2 < res:
            return r2, its + its2, res2, ok2
        return r, its + its2, res, ok
    csr = _dense_to_csr(w)
    operator = bilateral_operator_dense(w, n_bilateral)
    if cfg.method == METHOD_NSGS:
        return _nsgs(csr, q, mu, n_bilateral, operator, r0, cfg.max_iterations, cfg,
                     history)
    iterations = 0
    first = newton_first[0]
    best_r, best_residual, best_ok = r0, np.inf, False
    if first != NO_NEWTON_FIRST:
        best_r, its, best_residual, best_ok = _newton(
            w, q, mu, n_bilateral, r0, HYBRID_NEWTON_ITERATIONS, first == LEAST_NORM_FIRST,
            cfg, history)
        if best_ok:
            return best_r, its, best_residual, best_ok
        iterations = its
    r_nsgs, its, res_nsgs, ok_nsgs = _nsgs(csr, q, mu, n_bilateral, operator, r0,
                                           cfg.hybrid_sweeps, cfg, history)
    iterations += its
    if ok_nsgs:
        newton_first[0] = NO_NEWTON_FIRST
        return r_nsgs, iterations, res_nsgs, ok_nsgs
    if first == NO_NEWTON_FIRST or res_nsgs < best_residual:
        best_r, best_residual, best_ok = r_nsgs, res_nsgs, ok_nsgs
    # The attempts of the chain, in order (``MoreauJeanStepper._solve``): kind 0 regularised
    # Newton, 1 least-norm Newton, 2 NSGS for ``hybrid_last_sweeps`` sweeps, 3 proximal-point
    # Newton (skipped when ``cfg.proximal_rescue`` is 0); start 0 NSGS's end, 1 the warm
    # start, 2 zero.
    kinds = (0, 1, 0, 0, 3, 2, 2)
    starts = (0, 0, 1, 2, 1, 2, 0)
    for a in range(7):
        start = r_nsgs if starts[a] == 0 else (r0 if starts[a] == 1 else zeros)
        if kinds[a] == 3:
            if cfg.proximal_rescue <= 0.0:
                continue
            r, _, its, _, _, res, ok = proximal_newton_dense(
                w, q, mu, n_bilateral, start, cfg.proximal_rescue, cfg.tolerance, cfg.use_max,
                np.int64(HYBRID_NEWTON_ITERATIONS), cfg.roundoff_floor, cfg.local_tolerance,
                cfg.local_max_iterations, history, PROXIMAL_OUTER)
        elif kinds[a] == 2:
            r, its, res, ok = _nsgs(csr, q, mu, n_bilateral, operator, start,
                                    cfg.hybrid_last_sweeps, cfg, history)
        else:
            r, its, res, ok = _newton(w, q, mu, n_bilateral, start, HYBRID_NEWTON_ITERATIONS,
                                      kinds[a] == 1, cfg, history)
        iterations += its
        if ok or res < best_residual:
            best_r, best_residual, best_ok = r, res, ok
        if ok:
            if kinds[a] == 0:
                newton_first[0] = REGULARISED_FIRST
            elif kinds[a] == 1:
                newton_first[0] = LEAST_NORM_FIRST
            else:
                newton_first[0] = NO_NEWTON_FIRST
            break
    return best_r, iterations, best_residual, best_ok
