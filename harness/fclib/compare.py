"""Run our contact solvers and Siconos's side by side on FCLIB problems; performance profiles.

Every answer is judged by the same measure: our natural-map residual of the returned r, in
both normalisations; a run counts as solved when the residual in the chosen normalisation is
<= the tolerance. Siconos stops on its own measure |F| / max(|q|, |r|, |u|), which equals our
"max" normalisation (checked to round-off by the tests).
"""

from __future__ import annotations

import math
import time
from dataclasses import asdict, dataclass

import numpy as np

from clearbench.adapters.siconos.fc3d import SICONOS_SOLVERS, solve_with_siconos
from clearbench.adapters.siconos.run import siconos_available
from clearbench.harness.fclib.problems import LoadedProblem
from clearbench.ref_solver.contact_problem import ContactProblem, SolverOptions
from clearbench.ref_solver.fc3d_residual import residual_both
from clearbench.ref_solver.fc3d_solve import solve_contact_problem

#: Our solvers: name -> (method, local solver).
OUR_SOLVERS = {
    "nsgs-ac": ("nsgs", "ac"),
    "nsgs-fb": ("nsgs", "fb"),
    "nsgs-projection": ("nsgs", "projection"),
    "newton-ac": ("newton", "ac"),
}
ALL_SOLVERS = tuple(OUR_SOLVERS) + tuple(SICONOS_SOLVERS)

#: Siconos counterpart of each of our solvers, for the time ratio.
COUNTERPART = {
    "nsgs-ac": "siconos-nsgs-ac",
    "nsgs-fb": "siconos-nsgs-ac",
    "nsgs-projection": "siconos-nsgs-ac",
    "newton-ac": "siconos-nsn-ac",
}


@dataclass(frozen=True)
class CompareSettings:
    """Settings of a comparison run.

    tolerance: on the residual in ``normalisation`` ("q" or "max"); Siconos gets the same
    number on its own (max) measure. max_sweeps: NSGS cap (ours and Siconos's);
    max_newton: Newton cap (ours and Siconos's). repeat: each solve is repeated at least this
    many times and the fastest wall time kept; min_time (s): solves faster than that are
    repeated (up to MAX_REPEAT times) until they total min_time, on both sides, so that
    microsecond solves get a steady minimum. timeout: Siconos worker limit (s).
    """

    tolerance: float = 1e-8
    normalisation: str = "max"
    max_sweeps: int = 20_000
    max_newton: int = 500
    repeat: int = 3
    timeout: float = 300.0
    min_time: float = 0.2


#: Cap on the solves of one timing (the Siconos worker has the same cap).
MAX_REPEAT = 1000


@dataclass(frozen=True)
class RunRow:
    """One (problem, solver) run; times in seconds, residuals dimensionless.

    wall_time: fastest of ``solves`` solves. Ours: the call of ``solve_contact_problem`` (it
    allocates r, u and builds the result). Siconos's: allocating r, u plus ``fc3d_driver``;
    ``driver_time`` is Siconos's fastest ``fc3d_driver`` call alone (NaN for ours).
    """

    problem: str
    kind: str
    contacts: int
    solver: str
    iterations: int
    wall_time: float
    residual_q: float
    residual_max: float
    status: str
    solved: bool
    time_ratio: float = math.nan  # ours / Siconos counterpart, when both solved
    solves: int = 0
    driver_time: float = math.nan

    def as_dict(self) -> dict:
        return asdict(self)


def default_solvers(with_siconos: bool | None = None) -> list[str]:
    """nsgs-ac and newton-ac, plus Siconos NSGS-AC and NSN-AC when available."""
    solvers = ["nsgs-ac", "newton-ac"]
    if with_siconos is None:
        with_siconos = siconos_available()
    if with_siconos:
        solvers += list(SICONOS_SOLVERS)
    return solvers


def warm_up_jit() -> None:
    """Compile our numba kernels on a tiny problem so that timings exclude compilation."""
    problem = ContactProblem(np.eye(3) * 2.0 + 0.1, np.array([-1.0, 0.5, 0.2]), [0.3])
    for method, local in OUR_SOLVERS.values():
        solve_contact_problem(problem, SolverOptions(method=method, local_solver=local,
                                                     max_iterations=5))


def _judge(problem: ContactProblem, r: np.ndarray, settings: CompareSettings):
    u = problem.velocity(r)
    _, res_q, res_max = residual_both(r, u, problem.q, problem.mu, problem.n_bilateral)
    value = res_q if settings.normalisation == "q" else res_max
    return res_q, res_max, bool(value <= settings.tolerance)


def run_solver(loaded: LoadedProblem, solver: str, settings: CompareSettings) -> RunRow:
    """Solve ``loaded`` with ``solver`` (ours or Siconos's) and judge the answer."""
    problem = loaded.problem
    base = {"problem": loaded.name, "kind": loaded.kind, "contacts": problem.n_contacts,
            "solver": solver}
    if solver in OUR_SOLVERS:
        method, local = OUR_SOLVERS[solver]
        cap = settings.max_newton if method == "newton" else settings.max_sweeps
        options = SolverOptions(method=method, local_solver=local, tolerance=settings.tolerance,
                                normalisation=settings.normalisation, max_iterations=cap)
        best, total, count = math.inf, 0.0, 0
        result = None
        while count < max(settings.repeat, 1) or (total < settings.min_time
                                                   and count < MAX_REPEAT):
            # W's CSR form stays (built before timing, as Siconos's matrix is built before its
            # timer); whatever a solver derives from the problem (e.g. the bilateral operator)
            # is recomputed in every timed solve, as Siconos's driver redoes its set-up
            problem.forget_derived()
            start = time.perf_counter()
            result = solve_contact_problem(problem, options)
            elapsed = time.perf_counter() - start
            best, total, count = min(best, elapsed), total + elapsed, count + 1
        res_q, res_max, solved = _judge(problem, result.r, settings)
        return RunRow(**base, iterations=result.iterations, wall_time=best, residual_q=res_q,
                      residual_max=res_max, status=result.status.value, solved=solved,
                      solves=count)
    if solver in SICONOS_SOLVERS:
        cap = settings.max_newton if solver.endswith("nsn-ac") else settings.max_sweeps
        result = solve_with_siconos(problem, solver, tolerance=settings.tolerance,
                                    max_iterations=cap, timeout=settings.timeout,
                                    repeat=settings.repeat, min_time=settings.min_time)
        if result.status != "ok":
            return RunRow(**base, iterations=0, wall_time=math.nan, residual_q=math.nan,
                          residual_max=math.nan, status=result.status, solved=False)
        res_q, res_max, solved = _judge(problem, result.r, settings)
        status = "converged" if result.converged else "max_iterations"
        return RunRow(**base, iterations=result.iterations, wall_time=result.wall_time,
                      residual_q=res_q, residual_max=res_max, status=status, solved=solved,
                      solves=result.solves, driver_time=result.driver_time)
    raise ValueError(f"unknown solver {solver!r}; choose from {ALL_SOLVERS}")


def compare_problem(loaded: LoadedProblem, solvers: list[str],
                    settings: CompareSettings) -> list[RunRow]:
    """Run every solver on one problem and fill the ours/Siconos time ratios."""
    rows = {solver: run_solver(loaded, solver, settings) for solver in solvers}
    out = []
    for solver, row in rows.items():
        other = rows.get(COUNTERPART.get(solver, ""))
        if other is not None and row.solved and other.solved and other.wall_time > 0.0:
            row = RunRow(**{**row.as_dict(), "time_ratio": row.wall_time / other.wall_time})
        out.append(row)
    return out


def performance_profile(rows: list[RunRow]) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """Dolan–Moré profile: for tau on a grid, the fraction of problems each solver solves
    within tau times the fastest solver's time on that problem.

    Returns (tau (k,), {solver: fraction (k,)}). Problems no solver solves count as failures
    for all.
    """
    problems = sorted({row.problem for row in rows})
    solvers = list(dict.fromkeys(row.solver for row in rows))
    times = np.full((len(problems), len(solvers)), np.inf)
    for row in rows:
        if row.solved and math.isfinite(row.wall_time):
            times[problems.index(row.problem), solvers.index(row.solver)] = max(
                row.wall_time, 1e-9)
    best = times.min(axis=1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        ratios = np.where(np.isfinite(best), times / best, np.inf)
    finite = ratios[np.isfinite(ratios)]
    tau_max = max(2.0, float(finite.max()) * 1.5) if finite.size else 2.0
    tau = np.geomspace(1.0, tau_max, 400)
    fractions = {
        solver: (ratios[:, j][None, :] <= tau[:, None]).mean(axis=1)
        for j, solver in enumerate(solvers)
    }
    return tau, fractions


def plot_performance_profile(rows: list[RunRow], path, title: str = "") -> None:
    """Write the Dolan–Moré profile of ``rows`` as a PNG (matplotlib, Agg backend)."""
    import matplotlib  # lazy: matplotlib is loaded only when a figure is drawn

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    tau, fractions = performance_profile(rows)
    figure, axis = plt.subplots(figsize=(7, 4.5))
    for solver, fraction in fractions.items():
        axis.step(tau, fraction, where="post", label=solver)
    axis.set_xscale("log", base=2)
    axis.set_ylim(0.0, 1.05)
    axis.set_xlabel("tau (time / fastest time on the problem)")
    axis.set_ylabel("fraction of problems solved within tau")
    axis.set_title(title or "Performance profile")
    axis.grid(True, which="both", alpha=0.3)
    axis.legend(loc="lower right")
    figure.tight_layout()
    figure.savefig(path, dpi=120)
    plt.close(figure)
