"""Probability of an output outside its specification limits, from its metamodel: FORM and
importance sampling around FORM's design point, and the points where true runs check them.

The output is read as y = f(x) + sigma_e z, with f the metamodel, sigma_e the root mean square
of its validation residuals and z a standard normal variable independent of the inputs x (the
part of the output f does not explain: leaving it out would make the tails of a rough response
too thin). For each limit, the event {y < LSL} or {y > USL}:

- **FORM**: the most probable failure point u* (the design point: the point of the event
  closest to the origin in the standard normal space of (x, z), by OpenTURNS' iso-probabilistic
  transformation of the truncated normal or uniform inputs), the reliability index beta = |u*|
  and P_FORM = Phi(-beta) (exact for a limit-state linear in the standard space);
- **importance sampling**: OpenTURNS' post-analytical importance sampling, normal draws
  centred on u*, until the estimate's coefficient of variation is ``TARGET_CV`` or
  ``MAXIMUM_DRAWS`` metamodel evaluations are spent; its 95 % interval is p (1 +- 1.96 CV).

PPM = 1e6 (P_lower + P_upper). The metamodel is cheap, so probabilities of 1e-6 and below are
within reach where plain Monte Carlo on the true model would need ~1e8 runs for a CV of 10 %.

:func:`confirmation_points` gives the inputs of a few true runs along the ray through u*
(t u*, t around 1): their outputs say whether the metamodel holds where the estimate comes from.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from clearbench.harness.studies.campaign.metamodel import FittedModel, _ot

#: Wanted coefficient of variation of the importance-sampling estimate.
TARGET_CV = 0.05
#: Largest number of metamodel evaluations of one importance-sampling estimate.
MAXIMUM_DRAWS = 200_000
#: Draws per block of the importance sampling.
BLOCK = 2_000


@dataclass
class LimitEstimate:
    """One side's failure probability: FORM's and importance sampling's (with CV), the design
    point in the inputs' units (d,) and in the standard space (d + 1,: the inputs and z)."""

    side: str
    limit: float
    form: float
    beta: float
    origin_fails: bool
    importance: float
    importance_cv: float
    draws: int
    design_point: list[float] = field(default_factory=list)
    standard_point: list[float] = field(default_factory=list)
    note: str = ""


def _limit_state(fitted: FittedModel, residual_sigma: float, dimension: int):
    ot = _ot()

    def evaluate(sample):
        array = np.asarray(sample, float)
        return (fitted.predict(array[:, :dimension])
                + residual_sigma * array[:, dimension])[:, None]

    return ot.PythonFunction(dimension + 1, 1, func_sample=evaluate)


def extended_distribution(distribution):
    """The inputs' law with the unexplained part's standard normal z appended."""
    ot = _ot()
    marginals = [distribution.getMarginal(i) for i in range(distribution.getDimension())]
    return ot.JointDistribution(marginals + [ot.Normal(0.0, 1.0)])


def side_probability(fitted: FittedModel, distribution, side: str, limit: float,
                     seed: int = 0) -> LimitEstimate:
    """P(y < limit) (``side`` "lower") or P(y > limit) ("upper") of the metamodel's output."""
    ot = _ot()
    d = distribution.getDimension()
    extended = extended_distribution(distribution)
    function = _limit_state(fitted, fitted.residual_rms, d)
    output = ot.CompositeRandomVector(function, ot.RandomVector(extended))
    event = ot.ThresholdEvent(output, ot.Less() if side == "lower" else ot.Greater(), limit)
    solver = ot.Cobyla()
    solver.setMaximumCallsNumber(4000)
    solver.setMaximumConstraintError(1e-8 * max(abs(limit), 1.0))
    solver.setCheckStatus(False)   # judged below by the design point's own value
    form = ot.FORM(solver, event, extended.getMean())
    try:
        form.run()
    except RuntimeError as error:   # OpenTURNS: the design point is not on the limit
        return _monte_carlo(event, side, limit, seed,
                            f"FORM found no point on the limit ({str(error)[:120]})")
    result = form.getResult()
    point = np.asarray(result.getPhysicalSpaceDesignPoint(), float)
    value = float(function(list(point))[0])
    spread = max(abs(limit), 1.0)
    if not abs(value - limit) <= 1e-6 * spread:
        # no design point on the limit (an event the inputs and the unexplained part cannot
        # reach, or the optimiser out of calls): plain Monte Carlo on the metamodel
        return _monte_carlo(event, side, limit, seed,
                            f"FORM found no point on the limit (g = {value:.6g})")
    beta = float(result.getHasoferReliabilityIndex())
    origin_fails = bool(result.getIsStandardPointOriginInFailureSpace())
    if origin_fails:
        # the median inputs already fail: the event is not rare, FORM's tangent plane says
        # little about a probability near or above one half, and draws centred on u* miss
        # the bulk of the failure domain around the origin; plain Monte Carlo is accurate
        # at this probability with few draws
        return _monte_carlo(event, side, limit, seed,
                            f"the median inputs fail (beta {beta:.3g} from the failure side)",
                            form=float(result.getEventProbability()), beta=beta)
    probability = float(result.getEventProbability())
    ot.RandomGenerator.SetSeed(seed)
    estimate, cv, draws = _simulate(ot.PostAnalyticalImportanceSampling(result))
    return LimitEstimate(
        side=side, limit=float(limit), form=probability, beta=beta, origin_fails=origin_fails,
        importance=estimate, importance_cv=cv, draws=draws,
        design_point=list(np.asarray(result.getPhysicalSpaceDesignPoint(), float)[:d]),
        standard_point=list(np.asarray(result.getStandardSpaceDesignPoint(), float)))


def _monte_carlo(event, side: str, limit: float, seed: int, note: str,
                 form: float = math.nan, beta: float = math.nan) -> LimitEstimate:
    """Plain Monte Carlo on the metamodel (``MAXIMUM_DRAWS`` draws at most, to the target
    CV), where FORM has no design point or the median inputs already fail (then FORM's own
    figures are kept beside it)."""
    ot = _ot()
    ot.RandomGenerator.SetSeed(seed)
    estimate, cv, draws = _simulate(
        ot.ProbabilitySimulationAlgorithm(event, ot.MonteCarloExperiment()))
    note += "; plain Monte Carlo on the metamodel"
    if estimate >= 1:   # the binomial rule of three bounds the probability
        note += f", all {draws} draws fail (P >= {1 - 3 / draws:.6g} at 95 %)"
    return LimitEstimate(side=side, limit=float(limit), form=form, beta=beta,
                         origin_fails=estimate > 0.5, importance=estimate, importance_cv=cv,
                         draws=draws, note=note)


def _simulate(algorithm) -> tuple[float, float, int]:
    """Run an OpenTURNS simulation ``algorithm`` in blocks of ``BLOCK`` draws to ``TARGET_CV``
    or ``MAXIMUM_DRAWS``: (probability, coefficient of variation, draws). The CV is nan when no
    draw fails and 0 when every draw does (no spread to estimate; OpenTURNS reports -1)."""
    algorithm.setBlockSize(BLOCK)
    algorithm.setMaximumOuterSampling(MAXIMUM_DRAWS // BLOCK)
    algorithm.setMaximumCoefficientOfVariation(TARGET_CV)
    algorithm.run()
    simulated = algorithm.getResult()
    estimate = float(simulated.getProbabilityEstimate())
    draws = int(simulated.getOuterSampling() * simulated.getBlockSize())
    if estimate <= 0:
        return estimate, math.nan, draws
    if estimate >= 1:
        return estimate, 0.0, draws
    return estimate, float(simulated.getCoefficientOfVariation()), draws


def confirmation_points(distribution, estimate: LimitEstimate, count: int,
                        spread: float = 0.1) -> np.ndarray:
    """Inputs (count, d) of true runs on the ray through the design point: t u* for t evenly
    in [1 - spread, 1 + spread] (t = 1 is the design point itself when ``count`` is odd),
    mapped back to the inputs' units; z is dropped (a true run has its own)."""
    d = distribution.getDimension()
    if count <= 0:
        return np.zeros((0, d))
    factors = ray_factors(count, spread)
    inverse = distribution.getInverseIsoProbabilisticTransformation()
    standard = np.asarray(estimate.standard_point[:d], float)
    return np.array([np.asarray(inverse(list(t * standard)), float) for t in factors])


def ray_factors(count: int, spread: float = 0.1) -> np.ndarray:
    """The factors t of :func:`confirmation_points` (count,)."""
    return np.linspace(1 - spread, 1 + spread, count) if count > 1 else np.ones(max(count, 0))


def failure_probability(fitted: FittedModel, distribution, lower: float | None,
                        upper: float | None, seed: int = 0) -> dict:
    """Both sides' estimates and the total in PPM (FORM's, importance sampling's with its CV
    and 95 % interval); an empty dict without limits."""
    if lower is None or upper is None:
        return {}
    sides = [side_probability(fitted, distribution, "lower", lower, seed),
             side_probability(fitted, distribution, "upper", upper, seed + 1)]
    total = sum(s.importance for s in sides)
    variance = sum((s.importance * s.importance_cv) ** 2 for s in sides
                   if s.importance > 0 and math.isfinite(s.importance_cv))
    cv = math.sqrt(variance) / total if total > 0 else math.nan
    half = 1.96 * math.sqrt(variance)
    return {"sides": sides, "ppm_form": 1e6 * sum(s.form for s in sides
                                                  if math.isfinite(s.form)),
            "ppm_importance": 1e6 * total, "importance_cv": cv,
            "ppm_importance_interval": [1e6 * max(total - half, 0.0), 1e6 * (total + half)]}
