"""Siconos's fc3d solvers (NSGS with Alart–Curnier local Newton, NSN-AC) on a ContactProblem.

Parent side of :mod:`.worker.fc3d`; everything runs in a separate Debian Python process
(see :mod:`.run`). Used to validate our solvers side by side with Siconos.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from clearbench.adapters.siconos.run import WorkerStatus, run_worker
from clearbench.ref_solver.contact_problem import ContactProblem

WORKER_SCRIPT = Path(__file__).parent / "worker" / "fc3d.py"

#: Siconos solvers exposed here: our name -> worker name.
SICONOS_SOLVERS = {"siconos-nsgs-ac": "nsgs-ac", "siconos-nsn-ac": "nsn-ac"}

#: Above this many rows the worker uses Siconos's sparse-block storage.
_DENSE_LIMIT = 150


@dataclass(frozen=True, eq=False)
class SiconosSolveResult:
    """Outcome of a Siconos solve.

    ``status`` is the worker status ("ok", "failed", "crashed", "timed_out", "unavailable");
    when it is "ok", ``converged`` is Siconos's verdict (info == 0) and ``error`` its own
    residual |F| / max(|q|, |r|, |u|). ``wall_time`` (s) is the fastest of ``solves`` runs of
    allocating the output arrays r, u and calling ``fc3d_driver`` (our solvers allocate their
    outputs inside the timed call); ``driver_time`` the fastest ``fc3d_driver`` call alone.
    """

    solver: str
    status: str
    converged: bool = False
    r: np.ndarray | None = None
    u: np.ndarray | None = None
    iterations: int = 0
    error: float = float("nan")
    wall_time: float = float("nan")
    driver_time: float = float("nan")
    solves: int = 0
    storage: str = ""
    message: str = ""


def _matrix_inputs(problem: ContactProblem) -> dict:
    if problem.n_bilateral:
        raise ValueError("Siconos's FrictionContactProblem has no bilateral rows")
    W = problem.W_csr()
    return {"W_indptr": W.indptr.astype(np.int64), "W_indices": W.indices.astype(np.int64),
            "W_data": W.data, "q": problem.q, "mu": problem.mu}


def solve_with_siconos(
    problem: ContactProblem, solver: str = "siconos-nsgs-ac", tolerance: float = 1e-8,
    max_iterations: int = 10_000, storage: str = "auto", r0: np.ndarray | None = None,
    timeout: float = 600.0, repeat: int = 1, min_time: float = 0.0,
) -> SiconosSolveResult:
    """Solve ``problem`` (no bilateral rows) with a Siconos solver in a worker process.

    Parameters
    ----------
    solver : "siconos-nsgs-ac" or "siconos-nsn-ac"
    tolerance : Siconos's tolerance, on |F| / max(|q|, |r|, |u|).
    storage : "dense", "sparse-block" or "auto" (sparse-block above 150 rows).
    timeout : process wall-clock limit, seconds.
    repeat : solve at least this many times from the same start; the fastest wall time is
        reported.
    min_time : keep solving (at most 1000 solves) until the solves total this many seconds
        (steadier minima for microsecond solves).
    """
    if solver not in SICONOS_SOLVERS:
        raise ValueError(f"solver must be one of {sorted(SICONOS_SOLVERS)}, got {solver!r}")
    if storage == "auto":
        storage = "dense" if problem.size <= _DENSE_LIMIT else "sparse-block"
    inputs = _matrix_inputs(problem)
    inputs.update(mode="solve", solver=SICONOS_SOLVERS[solver], storage=storage,
                  tolerance=float(tolerance), max_iterations=int(max_iterations),
                  repeat=int(repeat), min_time=float(min_time))
    if r0 is not None:
        inputs["r0"] = np.asarray(r0, dtype=np.float64)
    outcome = run_worker(WORKER_SCRIPT, inputs, timeout=timeout)
    if outcome.status is not WorkerStatus.OK:
        return SiconosSolveResult(solver, outcome.status.value, storage=storage,
                                  message=outcome.message)
    out = outcome.outputs
    return SiconosSolveResult(
        solver=solver, status="ok", converged=int(out["info"]) == 0, r=out["r"], u=out["u"],
        iterations=int(out["iterations"]), error=float(out["error"]),
        wall_time=float(out["wall_time"]), driver_time=float(out["driver_time"]),
        solves=int(out["solves"]), storage=storage,
    )


def siconos_compute_error(problem: ContactProblem, r: np.ndarray, timeout: float = 120.0) -> float:
    """Siconos's ``fc3d_compute_error`` of r (normalised by max(|q|, |r|, |u|)).

    Raises RuntimeError if the worker does not answer (use ``siconos_available`` first).
    """
    inputs = _matrix_inputs(problem)
    inputs.update(mode="error", r=np.asarray(r, dtype=np.float64))
    outcome = run_worker(WORKER_SCRIPT, inputs, timeout=timeout)
    if outcome.status is not WorkerStatus.OK:
        raise RuntimeError(f"Siconos worker {outcome.status.value}: {outcome.message}")
    return float(outcome.outputs["error"])


def siconos_read_text_file(path: str | Path, timeout: float = 120.0) -> dict[str, np.ndarray]:
    """Siconos's own reading of a Siconos text problem file: {"W" (m, m) dense, "q", "mu"}.

    Raises RuntimeError if the worker does not answer.
    """
    outcome = run_worker(WORKER_SCRIPT, {"mode": "read", "path": str(Path(path).resolve())},
                         timeout=timeout)
    if outcome.status is not WorkerStatus.OK:
        raise RuntimeError(f"Siconos worker {outcome.status.value}: {outcome.message}")
    return {key: outcome.outputs[key] for key in ("W", "q", "mu")}
