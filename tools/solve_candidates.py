"""Candidate one-step contact solves measured on a run's recorded problems, beside the chain.

    .venv/bin/python -m tools.contact_problems record c60-on --dt 0.004 \\
        --option activation=held --save on_4us.npz
    .venv/bin/python -m tools.solve_candidates on_4us.npz [--candidate NAME ...]

Each candidate solves every problem of the recording (``tools/contact_problems.py``) from the
recorded warm start, in order; it is judged on the same residual as the reference's solvers
(:func:`ref_solver.dense_kernels.residuals`, the recorded run's normalisation and tolerance, a
residual under its round-off floor counting as converged, as the chain does). Candidates:

- ``chain``: the reference's compiled hybrid chain (what a run does today);
- ``chain-cap:N``: the chain with its two last attempts (NSGS to the full cap, 10,000 sweeps
  by default) capped at N sweeps;
- ``newton``: the chain's semismooth Newton alone, from the warm start (200 iterations);
- ``newton>chain[-N]``: that Newton (at most N iterations, default 200), then, where it did
  not converge, the chain from the warm start with its memory cleared;
- ``newton>prox:W:N[:from-newton]>chain``: that Newton; where it did not converge,
  proximal-point Newton of weight W, at most N outer iterations of at most 50 Newton
  iterations each, from the warm start (or from Newton's end); where that did not converge
  either, the chain (``...>chain-cap:N``: the chain of ``chain-cap:N``);
- ``proximal-W``: proximal-point Newton (``ref_solver/fc3d_proximal.py``) from the warm
  start with the relative weight W (e.g. ``proximal-1e-6``);
- ``admm``: ADMM on the cone complementarity problem with De Saxce's correction and an adaptive
  penalty (Carpentier, Le Lidec, Montaut et al. 2024, arXiv 2405.17020, Algorithm 1 with its
  "linear" update rule of rho), to the tolerance, at most ``ADMM_ITERATIONS`` iterations;
- ``admm+newton``: the ADMM to ``POLISH_AT`` times the tolerance's square root (a loose
  solution), then the semismooth Newton from there to the tolerance.

Unconverged: the residual above the tolerance and above its round-off floor as
:func:`ref_solver.dense_kernels.roundoff_floor_dense` bounds it; the chain accepts some of
these (residuals up to about 5e-12 on NSGS's own floor estimate), so the count of those more
than ``FAR_FACTOR`` times the tolerance away is printed too. Printed per candidate: the
replay's wall time (compiled kernels, the compile paid before the clock by a first solve),
the problems left unconverged, the iterations (each method's own:
sweeps, Newton or ADMM iterations, not of equal cost: the wall time is the comparable figure)
and their heavy tail. Run the candidates of one comparison in one command, with ``--repeat``:
the machine is shared, and only ratios measured side by side, interleaved, mean anything.
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np
from numba import njit

from clearbench.ref_solver.compiled.contact_solve import (
    HYBRID_NEWTON_ITERATIONS,
    NO_NEWTON_FIRST,
    _newton,
    solve,
)
from clearbench.ref_solver.compiled.system_arrays import compile_system, history_length
from clearbench.ref_solver.dense_kernels import residuals, roundoff_floor_dense
from clearbench.ref_solver.fc3d_proximal import PROXIMAL_OUTER_ITERATIONS, proximal_newton_dense
from clearbench.ref_solver.fc3d_residual import project_on_cone
from tools.contact_problems import HEAVY, _model, problems, recorded_options

#: The ADMM's iteration cap (each iteration: products with (W + (rho + eta) I)^-1 and with W,
#: both (m, m), and a projection per contact).
ADMM_ITERATIONS = 5000
#: ``admm+newton`` hands over to Newton once the residual is under this factor times the
#: square root of the tolerance (1e-6 for the default tolerance 1e-12).
POLISH_AT = 1.0
#: The ADMM's proximal weight eta, relative to W's largest diagonal entry: keeps
#: W + (rho + eta) I positive definite on the C-60's rank-deficient operators.
ADMM_PROXIMAL = 1e-8
#: The penalty's update (the paper's "linear" rule): rho times or over ``ADMM_RHO_FACTOR`` when
#: the primal residual exceeds ``ADMM_RHO_BALANCE`` times the dual one, or the reverse.
ADMM_RHO_FACTOR = 10.0
ADMM_RHO_BALANCE = 10.0
#: Newton's cap, as the chain's Newton attempts (``contact_solve._newton`` runs it).
NEWTON_ITERATIONS = HYBRID_NEWTON_ITERATIONS
NEWTON_CAP = np.int64(NEWTON_ITERATIONS)
#: An unconverged result this many times the tolerance away counts as failed outright: the
#: chain itself accepts residuals up to about 5e-12 (four to five times the default 1e-12) on
#: NSGS's round-off floor, a looser estimate than the dense one this tool judges with.
FAR_FACTOR = 10.0
#: The candidates run when none is named.
DEFAULT_CANDIDATES = ("chain", "newton", "proximal-1e-8", "proximal-1e-6")


@njit(cache=False)
def _shifted_inverse(W, shift):
    """(W + shift I)^-1: W (m, m) is not symmetric (the iteration matrix's gyroscopic part
    makes it so, by about 5e-6 of its largest entry on the C-60), so no Cholesky factor."""
    A = W.copy()
    for i in range(W.shape[0]):
        A[i, i] += shift
    return np.linalg.inv(A)


@njit(cache=False)
def admm(W, q, mu, nb, r0, tolerance, use_max, max_iterations, stop_at):
    """ADMM with De Saxce's correction (module docstring) from ``r0`` (m,): (r, iterations,
    residual in the tested normalisation). Stops when the tested residual is at most
    ``stop_at`` or under its round-off floor."""
    m = q.size
    nc = mu.size
    scale = 0.0
    for i in range(m):
        scale = max(scale, W[i, i])
    eta = ADMM_PROXIMAL * scale
    # The spectral rule's start: rho = sqrt(l_min l_max) with l_min floored at eta (the
    # operator's smallest eigenvalue is ~0 on rank-deficient problems).
    eigen = np.linalg.eigvalsh(0.5 * (W + W.T))
    rho = math.sqrt(max(eigen[0], eta) * max(eigen[-1], eta))
    inverse = _shifted_inverse(W, rho + eta)
    r = r0.copy()
    z = r0.copy()
    for i in range(nc):
        k = nb + 3 * i
        z[k], z[k + 1], z[k + 2] = project_on_cone(z[k], z[k + 1], z[k + 2], mu[i])
    y = np.zeros(m)
    u = W @ z + q
    s = np.zeros(m)
    rhs = np.empty(m)
    residual = np.inf
    for it in range(1, max_iterations + 1):
        for i in range(nc):
            k = nb + 3 * i
            s[k] = mu[i] * math.hypot(u[k + 1], u[k + 2])
        for i in range(m):
            rhs[i] = rho * z[i] - y[i] + eta * r[i] - q[i] - s[i]
        r[:] = inverse @ rhs
        primal = 0.0
        dual = 0.0
        for i in range(m):
            rhs[i] = r[i] + y[i] / rho
        for b in range(nb):
            dual += (rho * (rhs[b] - z[b])) ** 2
            z[b] = rhs[b]
        for i in range(nc):
            k = nb + 3 * i
            p0, p1, p2 = project_on_cone(rhs[k], rhs[k + 1], rhs[k + 2], mu[i])
            dual += (rho * (p0 - z[k])) ** 2 + (rho * (p1 - z[k + 1])) ** 2 + (
                rho * (p2 - z[k + 2])) ** 2
            z[k], z[k + 1], z[k + 2] = p0, p1, p2
        for i in range(m):
            y[i] += rho * (r[i] - z[i])
            primal += (r[i] - z[i]) ** 2
        u = W @ z + q
        _, residual_q, residual_max = residuals(z, u, q, mu, nb)
        residual = residual_max if use_max else residual_q
        if residual <= stop_at or residual <= roundoff_floor_dense(W, z, u, q, mu, use_max):
            return z, it, residual
        primal = math.sqrt(primal)
        dual = math.sqrt(dual)
        if primal > ADMM_RHO_BALANCE * dual:
            rho *= ADMM_RHO_FACTOR
            inverse = _shifted_inverse(W, rho + eta)
        elif dual > ADMM_RHO_BALANCE * primal:
            rho /= ADMM_RHO_FACTOR
            inverse = _shifted_inverse(W, rho + eta)
    return z, max_iterations, residual


def _judged(W, q, mu, nb, r, tolerance, use_max) -> tuple[float, bool]:
    u = W @ r + q
    _, residual_q, residual_max = residuals(r, u, q, mu, nb)
    residual = residual_max if use_max else residual_q
    floor = roundoff_floor_dense(W, r, u, q, mu, use_max)
    return residual, bool(residual <= tolerance or residual <= floor)


def run_candidate(name: str, cases, cfg) -> dict:
    history = np.empty(history_length(cfg))
    memory = np.array([NO_NEWTON_FIRST], dtype=np.int64)
    tol, use_max = cfg.tolerance, cfg.use_max

    chain_cfg = cfg
    if "chain-cap:" in name:
        chain_cfg = cfg._replace(max_iterations=int(name.split("chain-cap:")[1]))

    def one(W, q, mu, nb, r0):
        if name == "chain" or name.startswith("chain-cap:"):
            r, its, _, _ = solve(W, q, mu, np.int64(nb), r0, chain_cfg, memory, history)
            return r, its
        if name.startswith("newton>prox"):
            # newton>prox:WEIGHT:OUTER[:from-newton]>chain
            fields = name.split(">")[1].split(":")
            weight, outer = float(fields[1]), int(fields[2])
            r, its, _, _ = _newton(W, q, mu, np.int64(nb), r0, NEWTON_CAP, False, cfg, history)
            if _judged(W, q, mu, nb, r, tol, use_max)[1]:
                return r, its
            start = r if fields[-1] == "from-newton" else r0
            r, _, its2, _, _, _, ok = proximal_newton_dense(
                W, q, mu, np.int64(nb), start, weight, tol, use_max, np.int64(50),
                cfg.roundoff_floor, cfg.local_tolerance, cfg.local_max_iterations, history,
                np.int64(outer))
            its += its2
            if ok:
                return r, its
            memory[0] = NO_NEWTON_FIRST
            r, its2, _, _ = solve(W, q, mu, np.int64(nb), r0, chain_cfg, memory, history)
            return r, its + its2
        if name.startswith("newton>chain"):
            cap = int(name.split("-")[1]) if "-" in name else NEWTON_ITERATIONS
            r, its, _, _ = _newton(W, q, mu, np.int64(nb), r0, np.int64(cap), False, cfg,
                                   history)
            if _judged(W, q, mu, nb, r, tol, use_max)[1]:
                return r, its
            memory[0] = NO_NEWTON_FIRST
            r, its2, _, _ = solve(W, q, mu, np.int64(nb), r0, cfg, memory, history)
            return r, its + its2
        if name == "newton":
            r, its, _, _ = _newton(W, q, mu, np.int64(nb), r0, NEWTON_CAP, False, cfg, history)
            return r, its
        if name.startswith("proximal-"):
            r, _, its, _, _, _, _ = proximal_newton_dense(
                W, q, mu, np.int64(nb), r0, float(name.split("-", 1)[1]), tol, use_max,
                np.int64(NEWTON_ITERATIONS), cfg.roundoff_floor, cfg.local_tolerance,
                cfg.local_max_iterations, history, np.int64(PROXIMAL_OUTER_ITERATIONS))
            return r, its
        if name == "admm":
            r, its, _ = admm(W, q, mu, np.int64(nb), r0, tol, use_max,
                             np.int64(ADMM_ITERATIONS), tol)
            return r, its
        if name == "admm+newton":
            r, its, res = admm(W, q, mu, np.int64(nb), r0, tol, use_max,
                               np.int64(ADMM_ITERATIONS), POLISH_AT * math.sqrt(tol))
            if res > tol:
                r, its2, _, _ = _newton(W, q, mu, np.int64(nb), r, NEWTON_CAP, False, cfg,
                                        history)
                its += its2
            return r, its
        raise SystemExit(f"unknown candidate {name!r}")

    _, W, q, mu, nb, r0, _ = cases[0]
    one(np.ascontiguousarray(W), q, mu, nb, r0)  # compile before the clock
    memory[0] = NO_NEWTON_FIRST
    iterations = np.zeros(len(cases), dtype=np.int64)
    converged = np.zeros(len(cases), dtype=bool)
    results = []
    started = time.perf_counter()
    for k, (_, W, q, mu, nb, r0, _) in enumerate(cases):
        r, iterations[k] = one(np.ascontiguousarray(W), q, mu, nb, r0)
        results.append(r)
    seconds = time.perf_counter() - started
    largest = 0.0
    far = 0
    for k, ((_, W, q, mu, nb, _, _), r) in enumerate(zip(cases, results, strict=True)):
        residual, converged[k] = _judged(W, q, mu, nb, r, tol, use_max)
        if not converged[k]:
            largest = max(largest, residual)
            far += int(residual > FAR_FACTOR * tol)
    return {"seconds": seconds, "iterations": iterations, "converged": converged,
            "largest_unconverged": largest, "far": far, "results": results}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("file", nargs="+", help="recordings of tools.contact_problems")
    parser.add_argument("--repeat", type=int, default=1,
                        help="replays of each candidate, interleaved (candidate by candidate, "
                        "round after round); the median time is printed, with the range")
    parser.add_argument("--candidate", action="append", default=None,
                        help="chain, newton, proximal-W, admm, admm+newton (repeatable; "
                        "default: chain, newton, proximal at 1e-8 and 1e-6)")
    args = parser.parse_args()
    names = args.candidate or list(DEFAULT_CANDIDATES)
    for path in args.file:
        with np.load(path) as handle:
            data = {name: handle[name] for name in handle.files}
        model = _model(str(data["scene"]), float(data["time_step"]), recorded_options(data))
        _, cfg = compile_system(model.stepper)
        cases = problems(data)
        rows = data["rows"]
        print(f"{path}: {data['scene']}, step {float(data['time_step']):g}, options "
              f"{recorded_options(data)}; {len(cases)} problems of {rows.min()}-{rows.max()} "
              f"rows (median {np.median(rows):.0f}); tolerance {cfg.tolerance:g}")
        print(f"| candidate | replay [s], median (range) | unconverged (largest residual) | "
              f"of which > {FAR_FACTOR:g} x tolerance | iterations | median / 99 % / largest | "
              f"problems >= {HEAVY} |")
        print("|---|---|---|---|---|---|---|")
        rounds = [[run_candidate(name, cases, cfg) for name in names]
                  for _ in range(max(args.repeat, 1))]
        for k, name in enumerate(names):
            out = rounds[0][k]
            seconds = [done[k]["seconds"] for done in rounds]
            its = out["iterations"]
            p50, p99 = np.percentile(its, [50, 99])
            bad = int((~out["converged"]).sum())
            print(f"| {name} | {np.median(seconds):.3f} ({min(seconds):.3f}-{max(seconds):.3f}) "
                  f"| {bad} ({out['largest_unconverged']:.1e}) | {out['far']} | {its.sum()} | "
                  f"{p50:.0f} / {p99:.0f} / {its.max()} | {int((its >= HEAVY).sum())} |",
                  flush=True)

if __name__ == "__main__":
    main()
