"""Cost of one NSGS sweep per contact (microseconds), on the shipped FCLIB problems.

Usage: .venv/bin/python benchmarks/bench_fc3d_sweep.py [--sweeps N] [--repeat K]

Runs N sweeps from r = 0 with the tolerance set out of reach, so that exactly N sweeps are done,
in two settings: the residual evaluated only after the last sweep ("sweep only") and after
every sweep ("with check", the solver's default). Prints time / (sweeps done * contacts), the
fastest of K runs; the whole call is timed, so tiny problems include the Python call
overhead. Numbers only: nothing is asserted (the target is <= 5 us per contact per sweep).
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from clearbench.harness.fclib.problems import (
    UnsupportedProblemError,
    load_problem,
    shipped_problem_files,
)
from clearbench.ref_solver import ContactProblem, SolverOptions, solve_contact_problem


def time_sweeps(problem: ContactProblem, sweeps: int, check_interval: int, local: str,
                repeat: int) -> float:
    """Fastest wall time (s) per sweep of up to ``sweeps`` NSGS sweeps from zero.

    A problem solved exactly (residual 0) stops early: the time is divided by the sweeps done.
    """
    options = SolverOptions(tolerance=1e-300, max_iterations=sweeps, local_solver=local,
                            residual_check_interval=check_interval)
    best = np.inf
    for _ in range(repeat):
        start = time.perf_counter()
        result = solve_contact_problem(problem, options)
        best = min(best, (time.perf_counter() - start) / result.iterations)
    return best


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sweeps", type=int, default=200)
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()
    warm = load_problem(shipped_problem_files()[0]).problem
    for local in ("ac", "fb", "projection"):  # compile the kernels before timing
        time_sweeps(warm, 2, 1, local, 1)
    print(f"{'problem':44s} {'contacts':>8s} {'nnz(W)/row':>10s} {'local':>10s} "
          f"{'sweep only':>11s} {'with check':>11s}   [us per contact per sweep]")
    for path in shipped_problem_files():
        try:
            problem = load_problem(path).problem
        except UnsupportedProblemError:
            continue
        nc = problem.n_contacts
        nnz_row = problem.W_csr().nnz / problem.size
        for local in ("ac", "fb", "projection"):
            only = time_sweeps(problem, args.sweeps, args.sweeps, local, args.repeat)
            check = time_sweeps(problem, args.sweeps, 1, local, args.repeat)
            scale = 1e6 / nc
            print(f"{path.name:44s} {nc:8d} {nnz_row:10.1f} {local:>10s} "
                  f"{only * scale:11.3f} {check * scale:11.3f}")


if __name__ == "__main__":
    main()
