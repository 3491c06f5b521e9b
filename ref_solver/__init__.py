"""Nonsmooth Moreau--Jean reference solver (no scene, engine or report imports).

One-step contact solvers (public API)::

    from clearbench.ref_solver import ContactProblem, SolverOptions, solve_contact_problem
"""

from clearbench.ref_solver.contact_problem import (
    ContactProblem,
    Normalisation,
    SolverOptions,
    SolverResult,
    SolverStatus,
)
from clearbench.ref_solver.fc3d_residual import natural_map_residual
from clearbench.ref_solver.fc3d_solve import solve_contact_problem
from clearbench.ref_solver.mlcp import MLCPResult, solve_mlcp

__all__ = [
    "ContactProblem",
    "MLCPResult",
    "Normalisation",
    "SolverOptions",
    "SolverResult",
    "SolverStatus",
    "natural_map_residual",
    "solve_contact_problem",
    "solve_mlcp",
]
