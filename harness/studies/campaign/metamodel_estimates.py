"""What a campaign's metamodel says about an output, with bootstrap intervals over the design.

From a fitted metamodel f of one output (:mod:`.metamodel`):

- mean: of f, exact for a chaos expansion (its first coefficient), over ``EVALUATION_POINTS``
  scrambled Sobol' points of the inputs' law for kriging (their integration error is far below
  the intervals);
- sigma: the output is read as y = f(x) + e, with e the part f does not explain
  (uncorrelated with f): sigma^2 = Var f + Var e. With Q2 near 1 the second term vanishes;
  with a rough response (contacts that switch) it is what a smooth metamodel cannot carry, and
  leaving it out would understate sigma by the factor sqrt(Q2). Var e is estimated by
  :func:`unexplained_variance`: for a chaos, the fit's own mean squared residual on the
  design, not the validation's PRESS / n (which counts the coefficients' estimation error a
  second time: see there);
- Cp and Cpk from that mean and sigma (the study's Eq. 29, as the sampling campaign's);
- Sobol' indices as shares of that variance: first-order S1_i = Var E[f | x_i] / sigma^2 and
  total ST_i (exact for a chaos expansion, from its coefficients; by pick-freeze estimators on
  ``EVALUATION_POINTS`` / 4 pairs for kriging: Saltelli 2010 for S1, Jansen for ST), so S1 is
  comparable with a given-data estimate of the output's own S1; the interaction share 1 - sum
  S1 splits into the metamodel's interactions and the unexplained share Var e / sigma^2
  (which may belong to any input's ST: the ST stated are the metamodel's).

Each interval is the 2.5 and 97.5 % percentiles over ``bootstrap`` replicates: the design's
runs drawn with replacement, the metamodel refitted with the same kind and settings, every
figure computed again. It is the figures' uncertainty from the finite design, not from the
metamodel's misfit, which Q2 states.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from clearbench.harness.studies.campaign.definition import CampaignDefinition
from clearbench.harness.studies.campaign.designs import to_law, unit_points
from clearbench.harness.studies.campaign.metamodel import (
    CHAOS,
    ChaosBasis,
    FittedModel,
    refit,
)
from clearbench.harness.studies.campaign.statistics import CONFIDENCE, Interval

#: The figures' method, part of the key under which a stage's fits are kept beside the store:
#: changed whenever an estimator here changes, so a resumed campaign refits with the new one.
FIGURES_METHOD = "sigma: Var f + fit residual (chaos), PRESS / n (kriging)"

#: Points of the inputs' law on which a metamodel is evaluated (mean, sigma, pick-freeze).
EVALUATION_POINTS = 2**14


def law_points(definition: CampaignDefinition, count: int, seed: int,
               dimension_factor: int = 1) -> np.ndarray:
    """``count`` scrambled Sobol' points of the inputs' law, shape (count, d *
    ``dimension_factor``): each block of d columns follows the law (pick-freeze takes two)."""
    d = definition.dimension
    u = unit_points("sobol", seed, d * dimension_factor, 0, count)
    laws = list(definition.inputs) * dimension_factor
    return np.column_stack([to_law(law, u[:, k]) for k, law in enumerate(laws)])


def pick_freeze(predict, a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """First-order (Saltelli 2010) and total (Jansen) Sobol' indices (d,) of ``predict`` from
    two independent samples ``a``, ``b`` (N, d) of the inputs' law."""
    fa, fb = predict(a), predict(b)
    # centred: an output far from zero (10.7 mm with a sigma of 0.07 mm) would otherwise
    # multiply the estimator's noise by mean / sigma
    centre = float(np.mean(np.concatenate([fa, fb])))
    fa, fb = fa - centre, fb - centre
    variance = float(np.var(np.concatenate([fa, fb])))
    d = a.shape[1]
    first, total = np.empty(d), np.empty(d)
    for i in range(d):
        ab = a.copy()
        ab[:, i] = b[:, i]
        fab = predict(ab) - centre
        first[i] = float(np.mean(fb * (fab - fa))) / variance
        total[i] = 0.5 * float(np.mean((fa - fab) ** 2)) / variance
    return first, total


@dataclass(frozen=True)
class Estimates:
    """An output's figures from one metamodel: mean, sigma [output unit], Cp, Cpk (None without
    limits), S1 and ST (d,) and the unexplained share, all as shares of sigma^2."""

    mean: float
    sigma: float
    cp: float | None
    cpk: float | None
    s1: np.ndarray
    st: np.ndarray
    unexplained: float

    @property
    def interaction(self) -> float:
        """Share of the variance not carried by single inputs: 1 - sum S1 (the metamodel's
        interactions and the unexplained share)."""
        return 1.0 - float(np.sum(self.s1))


def estimates_of(predictor, kind: str, points: np.ndarray, pairs: tuple[np.ndarray, np.ndarray],
                 lower: float | None, upper: float | None,
                 residual_variance: float = 0.0) -> Estimates:
    """Figures of one fitted ``predictor`` (ChaosPredictor or KrigingPredictor);
    ``residual_variance`` [output unit^2] is the variance it leaves unexplained (Var e,
    :func:`unexplained_variance`)."""
    if kind == CHAOS:
        mean, explained = predictor.moments()
        s1, st = predictor.sobol()
    else:
        values = predictor.predict(points)
        mean, explained = float(np.mean(values)), float(np.var(values, ddof=1))
        s1, st = pick_freeze(predictor.predict, *pairs)
    total = explained + residual_variance
    sigma = math.sqrt(total)
    share = explained / total if total > 0 else math.nan
    cp = cpk = None
    if lower is not None and upper is not None and sigma > 0:
        cp = (upper - lower) / (6 * sigma)
        cpk = min(upper - mean, mean - lower) / (3 * sigma)
    return Estimates(mean, sigma, cp, cpk, share * np.asarray(s1), share * np.asarray(st),
                     1.0 - share)


def unexplained_variance(kind: str, predictor, x: np.ndarray, y: np.ndarray,
                         validation_rms: float) -> float:
    """Var e [output unit^2], the variance of the part e of y = f(x) + e that the metamodel f
    (``predictor``, fitted on ``x`` (n, d), ``y`` (n,)) does not carry.

    Chaos (a least-squares fit of p terms, selected by LARS): the mean squared residual on the
    design, sum (y - f(x))^2 / n. It understates Var e by about p / n, while Var f overstates
    the smooth part's variance by about p / n Var e (the coefficients' estimation noise), so
    Var f + this is unbiased to first order. The validation's PRESS / n is larger than Var e
    by about p / n' (n' the runs of each refit) and would count the estimation noise twice:
    on a rough test function of 7 normal inputs at Q2 0.74 (256 runs, 120 designs), sigma from
    PRESS / n came out 1.7 % high (standard error 0.25 %), from this 0.3 % low (0.25 %)
    (``python -m tools.sigma_estimator_bias``;
    ``tests/test_metamodel.py::test_chaos_sigma_is_unbiased_on_a_rough_response``).

    Kriging interpolates its design (its residual there is 0), so there is no fit residual to
    take: ``validation_rms``^2 (PRESS / n), which errs high on a rough response
    (docs/campaigns.md states the measured bias).
    """
    if kind == CHAOS:
        return float(np.mean((np.asarray(y, float) - predictor.predict(x)) ** 2))
    return float(validation_rms) ** 2


def _percentiles(values: np.ndarray) -> tuple[float, float]:
    values = np.asarray(values, float)
    values = values[np.isfinite(values)]
    if len(values) < 2:
        return math.nan, math.nan
    tail = 100 * (1 - CONFIDENCE) / 2
    return float(np.percentile(values, tail)), float(np.percentile(values, 100 - tail))


@dataclass(frozen=True)
class BootstrapEstimates:
    """An output's figures with their bootstrap intervals; S1, ST per input."""

    mean: Interval
    sigma: Interval
    cp: Interval | None
    cpk: Interval | None
    s1: list[Interval]
    st: list[Interval]
    interaction: Interval
    unexplained: float
    replicates: int   # the bootstrap refits that succeeded

    def half_width(self, figure: str) -> float:
        """Largest half-width of the 95 % intervals of ``figure`` (mean, sigma, cpk, s1, st)
        [its unit]; NaN when the figure is not computed."""
        values = {"mean": [self.mean], "sigma": [self.sigma], "cpk": [self.cpk],
                  "s1": self.s1, "st": self.st}[figure]
        widths = [(v.high - v.low) / 2 for v in values if v is not None]
        return max(widths) if widths else math.nan


def bootstrap_estimates(fitted: FittedModel, basis: ChaosBasis | None, x: np.ndarray,
                        y: np.ndarray, definition: CampaignDefinition,
                        lower: float | None, upper: float | None, replicates: int,
                        seed: int) -> BootstrapEstimates:
    """The figures of ``fitted`` (fitted on ``x`` (n, d), ``y`` (n,)) with percentile
    intervals over ``replicates`` bootstrap refits (each replicate with its own unexplained
    variance, :func:`unexplained_variance` on the rows it drew)."""
    points = law_points(definition, EVALUATION_POINTS, seed + 1)
    both = law_points(definition, EVALUATION_POINTS // 4, seed + 2, dimension_factor=2)
    d = definition.dimension
    pairs = (both[:, :d], both[:, d:])
    residual = unexplained_variance(fitted.kind, fitted.model, x, y, fitted.residual_rms)
    central = estimates_of(fitted.model, fitted.kind, points, pairs, lower, upper, residual)
    rng = np.random.default_rng(seed)
    drawn = []
    for _ in range(replicates):
        rows = rng.integers(0, len(y), len(y))
        try:
            predictor = refit(fitted, basis, x[rows], y[rows])
        except (TypeError, RuntimeError, ValueError, np.linalg.LinAlgError):
            continue   # a replicate with too few distinct points for the basis: not counted
        drawn.append(estimates_of(
            predictor, fitted.kind, points, pairs, lower, upper,
            unexplained_variance(fitted.kind, predictor, x[rows], y[rows],
                                 fitted.residual_rms)))

    def interval(value, samples) -> Interval:
        low, high = _percentiles(samples)
        return Interval(float(value), low, high)

    return BootstrapEstimates(
        mean=interval(central.mean, [e.mean for e in drawn]),
        sigma=interval(central.sigma, [e.sigma for e in drawn]),
        cp=None if central.cp is None else interval(central.cp, [e.cp for e in drawn]),
        cpk=None if central.cpk is None else interval(central.cpk, [e.cpk for e in drawn]),
        s1=[interval(central.s1[i], [e.s1[i] for e in drawn]) for i in range(d)],
        st=[interval(central.st[i], [e.st[i] for e in drawn]) for i in range(d)],
        interaction=interval(central.interaction, [e.interaction for e in drawn]),
        unexplained=central.unexplained, replicates=len(drawn))
