"""Why an Exudyn solve stopped, read from the solver's ``conv`` and ``it`` structures.

Exudyn's own ``GetErrorString`` (EXUDYN ``CSolverBase.cpp``) prints two of its flags inverted:
"Newton did not converged" when ``conv.newtonConverged`` is True and "discontinuous iteration
was not successful" when ``conv.discontinuousIterationSuccessful`` is True. The flags
themselves are right, and they say which of the three loops of a step failed last
(``CSolverBase::DiscontinuousIteration`` and ``SolveSteps``):

- Newton: ``newtonConverged`` False; Exudyn then sets ``discontinuousIterationSuccessful``
  True ("the fault of Newton, not of discontinuous iteration");
- the discontinuous (contact and friction switching) iteration: Newton converged and the
  switching error ``discontinuousIterationError`` stayed above its tolerance;
- step reduction: ``stepReductionFailed`` True when the step could not be reduced further
  (the minimum step reached, or ``adaptiveStep`` off) after one of the two above failed.

:func:`failure_reason` states them with the step size, the residual and the tolerances, in the
model's units (force for the residual, time for the step).
"""

from __future__ import annotations

__all__ = ["failed_loop", "failure_reason"]


def failed_loop(conv) -> str:
    """'newton', 'discontinuous' or 'other': which iteration of the last attempted step failed
    (``conv``: the solver's ``conv`` structure after a failed solve)."""
    if conv.linearSolverFailed or conv.massMatrixNotInvertible:
        return "other"
    if not conv.newtonConverged:
        return "newton"
    if not conv.discontinuousIterationSuccessful:
        return "discontinuous"
    return "other"


def failure_reason(solver, settings) -> str:
    """One sentence: which loop failed, at which step size, with which residual or switching
    error against which tolerance, and whether step reduction was exhausted.

    Parameters
    ----------
    solver : exudyn.MainSolverImplicitSecondOrder
        After ``SolveSteps`` returned False or raised.
    settings : exudyn.SimulationSettings
        The settings of that solve (tolerances; the minimum step [T]).
    """
    conv, it = solver.conv, solver.it
    ti = settings.timeIntegration
    step = f"step size {it.currentStepSize:.3g}"
    parts = []
    loop = failed_loop(conv)
    if conv.linearSolverFailed:
        parts.append(f"linear solver failed (Jacobian singular) at {step}")
    if conv.massMatrixNotInvertible:
        parts.append(f"mass matrix not invertible at {step}")
    if loop == "newton":
        how = "diverged" if conv.newtonSolutionDiverged else "did not converge"
        parts.append(
            f"Newton {how} at {step}: residual {conv.residual:.4g} (force units) against the "
            f"absolute tolerance {ti.newton.absoluteTolerance:.3g} and the relative "
            f"{ti.newton.relativeTolerance:.3g}, contractivity {conv.contractivity:.6g}, "
            f"{ti.newton.maxIterations} iterations at most")
    elif loop == "discontinuous":
        parts.append(
            f"discontinuous (contact/friction switching) iteration did not converge at {step}: "
            f"switching error {conv.discontinuousIterationError:.4g} against its tolerance "
            f"{ti.discontinuous.iterationTolerance:.3g} after "
            f"{ti.discontinuous.maxIterations} iterations (Newton converged)")
    if conv.stepReductionFailed:
        if ti.adaptiveStep:
            parts.append(f"step reduction reached the minimum step size "
                         f"{ti.minimumStepSize:.3g}")
        else:
            parts.append("no step reduction (adaptive_step off)")
    if conv.stopNewton:
        parts.append("Newton stopped")
    if not parts:
        parts.append("no solver flag set (a user function or an internal exception)")
    return "; ".join(parts)
