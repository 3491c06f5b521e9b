"""The C-60 contact problem every attempt of the hybrid chain but the proximal rescue leaves
unconverged (``c60-trip``'s step 16240 at 1 us, rank 43 of 52 rows), and the reference stepper
and compiled chain that solve it, shared by the tests of the chain's settings."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from clearbench.adapters.base import RunSettings
from clearbench.adapters.reference.build import build
from clearbench.adapters.reference.engine import create
from clearbench.ref_solver.compiled.contact_solve import NO_NEWTON_FIRST, solve
from clearbench.ref_solver.compiled.system_arrays import compile_system, history_length
from clearbench.ref_solver.contact_problem import ContactProblem
from clearbench.scenarios.library import get_scene

FIXTURE = Path(__file__).parent / "data" / "c60_trip_unconverged_problem.npz"


def load_problem() -> tuple[ContactProblem, np.ndarray]:
    """(the problem, its recorded warm start r0 (m,))."""
    with np.load(FIXTURE) as data:
        return (ContactProblem(data["W"], data["q"], data["mu"], int(data["n_bilateral"])),
                data["r0"].copy())


def reference_stepper(**options):
    """A reference stepper of the default preset with ``options`` (its system is any scene's:
    ``_solve`` reads only the settings)."""
    scene = get_scene("pendulum")
    settings = create("default").run_settings(scene, RunSettings(options=options))
    return build(scene, settings, python_step=False).stepper


def compiled_solve(stepper, contact_problem: ContactProblem, r0: np.ndarray):
    """The compiled chain with ``stepper``'s settings on the problem: (r, iterations, residual,
    converged)."""
    _, settings = compile_system(stepper)
    return solve(np.asarray(contact_problem.W), contact_problem.q, contact_problem.mu,
                 np.int64(contact_problem.n_bilateral), r0, settings,
                 np.array([NO_NEWTON_FIRST], dtype=np.int64),
                 np.empty(history_length(settings)))
