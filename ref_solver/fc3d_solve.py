"""Entry point of the one-step contact solvers: :func:`solve_contact_problem`."""

from __future__ import annotations

import numpy as np

from clearbench.ref_solver.contact_problem import ContactProblem, SolverOptions, SolverResult
from clearbench.ref_solver.fc3d_newton import solve_newton
from clearbench.ref_solver.fc3d_nsgs import solve_nsgs


def solve_contact_problem(
    problem: ContactProblem, options: SolverOptions | None = None,
    r0: np.ndarray | None = None,
) -> SolverResult:
    """Solve the one-step frictional contact problem with bilateral rows.

    Parameters
    ----------
    problem : ContactProblem
        W (m, m), q (m,), mu (nc,), n_bilateral; see :mod:`contact_problem`.
    options : SolverOptions, optional
        Method ("nsgs" or "newton"), tolerance on the natural-map residual in the chosen
        normalisation (default |F| / max(|q|, |r|, |u|)), iteration cap, local solver.
    r0 : ndarray, shape (m,), optional
        Warm start (impulses); zeros if omitted. Not modified.

    Returns
    -------
    SolverResult
        Never raises on non-convergence: ``converged`` is False and ``status`` says why.
    """
    options = SolverOptions() if options is None else options
    if options.method == "newton":
        return solve_newton(problem, options, r0)
    return solve_nsgs(problem, options, r0)
