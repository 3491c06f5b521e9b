"""The dense LU of Newton's direction (``dense_kernels.lu_solve``) against its version at a
baseline revision, side by side in one process.

    .venv/bin/python -m tools.lu_against_revision f6673e4 --sizes 10 31 52 120

Compiles the baseline's ``lu_solve`` from that revision's ``ref_solver/dense_kernels.py``
(``git show``), then for each size m: a random matrix (standard normal entries, 40 % of them
zero, 0.1 added to the diagonal; seed 1) and right-hand side, solved by both; checks that the
solutions and the factors are equal to the bit, and prints each side's time per solve [us]
(best of three passes of 2,000 solves, each on a fresh copy of the matrix) and their ratio.
"""

from __future__ import annotations

import argparse
import ast
import math
import subprocess
import time
from pathlib import Path

import numpy as np
from numba import njit

from clearbench.ref_solver.dense_kernels import lu_solve

REPOSITORY = Path(__file__).resolve().parents[1]


def baseline_lu_solve(revision: str):
    """``lu_solve`` as the baseline revision wrote it, compiled."""
    source = subprocess.run(["git", "show", f"{revision}:ref_solver/dense_kernels.py"],
                            cwd=REPOSITORY, check=True, capture_output=True, text=True).stdout
    node = next(n for n in ast.parse(source).body
                if isinstance(n, ast.FunctionDef) and n.name == "lu_solve")
    node.decorator_list = []
    namespace = {"np": np, "math": math}
    exec(compile(ast.Module([node], []), "baseline", "exec"), namespace)  # noqa: S102
    return njit(namespace["lu_solve"])


def _per_solve(solve, matrix, rhs, out, repeats=2000) -> float:
    best = math.inf
    for _ in range(3):
        started = time.perf_counter()
        for _ in range(repeats):
            solve(matrix.copy(), rhs, out)
        best = min(best, (time.perf_counter() - started) / repeats)
    return best * 1e6


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("revision")
    parser.add_argument("--sizes", type=int, nargs="+", default=[10, 31, 52, 120])
    args = parser.parse_args()
    baseline = baseline_lu_solve(args.revision)
    rng = np.random.default_rng(1)
    print(f"{'m':>4s} {'baseline [us]':>14s} {'this [us]':>10s} {'speed-up':>9s}  bitwise")
    for m in args.sizes:
        matrix = rng.standard_normal((m, m))
        matrix[rng.random((m, m)) < 0.4] = 0.0
        matrix += 0.1 * np.eye(m)
        rhs = rng.standard_normal(m)
        factors = [matrix.copy(), matrix.copy()]
        solutions = [np.empty(m), np.empty(m)]
        flags = [solve(f, rhs, x) for solve, f, x in zip((baseline, lu_solve), factors,
                                                         solutions, strict=True)]
        same = (flags[0] == flags[1] and np.array_equal(*solutions)
                and np.array_equal(*factors))
        base = _per_solve(baseline, matrix, rhs, solutions[0])
        this = _per_solve(lu_solve, matrix, rhs, solutions[1])
        print(f"{m:4d} {base:14.1f} {this:10.1f} {base / this:9.2f}  {'yes' if same else 'NO'}")


if __name__ == "__main__":
    main()
