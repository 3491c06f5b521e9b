"""Siconos worker: solve one frictional contact problem with Siconos's fc3d solvers.

Runs under Debian's /usr/bin/python3 with a clean environment (Siconos 4.4 imports only with
Debian's numpy); it imports nothing from clearbench and needs only numpy and siconos.

Protocol (files, never stdout, which Siconos fills with noise):

    /usr/bin/python3 fc3d.py INPUT.npz OUTPUT.npz

INPUT.npz holds ``W_indptr``, ``W_indices``, ``W_data`` (CSR of W, shape (m, m)), ``q`` (m,),
``mu`` (nc,), ``mode`` ("solve", "error" or "read"), and for "solve": ``solver`` ("nsgs-ac" or
"nsn-ac"), ``storage`` ("dense" or "sparse-block"), ``tolerance``, ``max_iterations``, optional
``r0`` (m,) warm start and ``repeat`` (solve that many times, report the fastest); for
"error": ``r`` (m,) whose residual Siconos evaluates. Mode "read" takes only ``path`` (a
Siconos text file) and returns Siconos's reading of it: ``W`` (dense), ``q``, ``mu``.

OUTPUT.npz holds ``ok`` (bool), ``message``, and for "solve": ``r``, ``u``, ``info`` (Siconos's
return code, 0 = converged), ``iterations``, ``error`` (Siconos's own residual,
|F| / max(|q|, |r|, |u|)), ``wall_time`` (seconds: allocation of the output arrays r, u plus
``fc3d_driver``, fastest run), ``driver_time`` (``fc3d_driver`` alone, fastest run) and
``solves`` (runs done: at least ``repeat``, more while they total less than the optional
``min_time`` seconds, at most MAX_REPEAT); for "error": ``error`` from
``fc3d_compute_error(problem, r, u, tol, options, |q|)``.
"""

import os
import sys
import tempfile
import time
import traceback

import numpy as np

MAX_REPEAT = 1000  # cap on the solves of one timing (see ``min_time``)


def _csr_to_dense(indptr, indices, data, m):
    dense = np.zeros((m, m))
    for row in range(m):
        cols = indices[indptr[row]:indptr[row + 1]]
        dense[row, cols] += data[indptr[row]:indptr[row + 1]]
    return dense


def _write_sparse_block_problem(path, indptr, indices, data, q, mu):
    """Write the problem in Siconos's text format with sparse-block (3x3) storage."""
    m = q.size
    nc = mu.size
    blocks = {}
    for row in range(m):
        for p in range(indptr[row], indptr[row + 1]):
            col = indices[p]
            key = (row // 3, col // 3)
            block = blocks.get(key)
            if block is None:
                block = blocks[key] = np.zeros((3, 3))
            block[row % 3, col % 3] += data[p]
    keys = sorted(blocks)
    row_pointer = [0]
    for block_row in range(nc):
        row_pointer.append(row_pointer[-1] + sum(1 for k in keys if k[0] == block_row))
    sizes = " ".join(str(3 * (i + 1)) for i in range(nc))
    lines = ["3", str(nc), "1", str(m), str(m), str(len(keys)), str(nc), str(nc), sizes, sizes,
             str(nc + 1), str(len(keys)), " ".join(str(v) for v in row_pointer),
             " ".join(str(k[1]) for k in keys)]
    for number, key in enumerate(keys):
        lines.append(str(number))
        lines.extend(f"{v:.17e}" for v in blocks[key].ravel(order="F"))
    lines.append(" ".join(f"{v:.17e}" for v in q))
    lines.append(" ".join(f"{v:.17e}" for v in mu))
    with open(path, "w") as handle:
        handle.write("\n".join(lines) + "\n")


def build_problem(sn, inputs, storage):
    indptr = inputs["W_indptr"].astype(np.int64)
    indices = inputs["W_indices"].astype(np.int64)
    data = inputs["W_data"].astype(np.float64)
    q = np.ascontiguousarray(inputs["q"], dtype=np.float64)
    mu = np.ascontiguousarray(inputs["mu"], dtype=np.float64)
    if storage == "dense":
        W = _csr_to_dense(indptr, indices, data, q.size)
        return sn.FrictionContactProblem(3, W, q, mu)
    fd, path = tempfile.mkstemp(suffix=".dat")
    os.close(fd)
    try:
        _write_sparse_block_problem(path, indptr, indices, data, q, mu)
        return sn.frictionContact_new_from_filename(path)
    finally:
        os.unlink(path)


def solve(sn, inputs):
    storage = str(inputs["storage"])
    solver = str(inputs["solver"])
    problem = build_problem(sn, inputs, storage)
    solver_ids = {"nsgs-ac": sn.SICONOS_FRICTION_3D_NSGS, "nsn-ac": sn.SICONOS_FRICTION_3D_NSN_AC}
    if solver not in solver_ids:
        raise ValueError(f"unknown solver {solver!r}")
    options = sn.SolverOptions(solver_ids[solver])
    options.iparam[sn.SICONOS_IPARAM_MAX_ITER] = int(inputs["max_iterations"])
    options.dparam[sn.SICONOS_DPARAM_TOL] = float(inputs["tolerance"])
    m = int(inputs["q"].size)
    r0 = np.array(inputs["r0"], dtype=np.float64) if "r0" in inputs.files else None
    repeat = max(int(inputs["repeat"]) if "repeat" in inputs.files else 1, 1)
    min_time = float(inputs["min_time"]) if "min_time" in inputs.files else 0.0
    wall_time = driver_time = float("inf")
    total = 0.0
    count = 0
    # same start each time; the fastest run is reported. At least ``repeat`` solves, more (up
    # to MAX_REPEAT) until they add up to ``min_time`` seconds.
    while count < repeat or (total < min_time and count < MAX_REPEAT):
        start = time.perf_counter()
        r = np.zeros(m) if r0 is None else r0.copy()  # output arrays: our solvers allocate
        u = np.zeros(m)  # theirs inside the timed call, so these are timed too
        driver_start = time.perf_counter()
        info = sn.fc3d_driver(problem, r, u, options)
        end = time.perf_counter()
        wall_time = min(wall_time, end - start)
        driver_time = min(driver_time, end - driver_start)
        total += end - start
        count += 1
    return {
        "r": r, "u": u, "info": int(info),
        "iterations": int(options.iparam[sn.SICONOS_IPARAM_ITER_DONE]),
        "error": float(options.dparam[sn.SICONOS_DPARAM_RESIDU]),
        "wall_time": wall_time, "driver_time": driver_time, "solves": count,
    }


def compute_error(sn, inputs):
    problem = build_problem(sn, inputs, "dense")
    r = np.ascontiguousarray(inputs["r"], dtype=np.float64)
    u = np.zeros_like(r)
    options = sn.SolverOptions(sn.SICONOS_FRICTION_3D_NSGS)
    norm_q = float(np.linalg.norm(inputs["q"]))
    _, error = sn.fc3d_compute_error(problem, r, u, 1e-30, options, norm_q)
    return {"error": float(error), "u": u}


def read_file(sn, inputs):
    """Siconos's own reading of a Siconos text file (dense W, q, mu) - to cross-check ours."""
    problem = sn.frictionContact_new_from_filename(str(inputs["path"]))
    matrix = problem.M
    m = int(matrix.size0)
    W = np.array([[sn.NM_get_value(matrix, i, j) for j in range(m)] for i in range(m)])
    return {"W": W, "q": np.array(problem.q), "mu": np.array(problem.mu)}


def main(argv):
    input_path, output_path = argv[1], argv[2]
    result = {"ok": False, "message": ""}
    try:
        import siconos.numerics as sn  # lazy: a missing Siconos is reported in the output file

        with np.load(input_path, allow_pickle=False) as inputs:
            mode = str(inputs["mode"])
            if mode == "solve":
                result.update(solve(sn, inputs))
            elif mode == "error":
                result.update(compute_error(sn, inputs))
            elif mode == "read":
                result.update(read_file(sn, inputs))
            else:
                raise ValueError(f"unknown mode {mode!r}")
        result["ok"] = True
    except Exception:  # reported through the output file, the parent decides
        result["message"] = traceback.format_exc()
    np.savez(output_path, **result)
    return 0 if result["ok"] else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv))
