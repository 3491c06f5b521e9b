"""Metamodels of a campaign's outputs: functional chaos (sparse, by least-angle regression)
and kriging from OpenTURNS, each validated by Q2, the better one kept per output.

For one output y (n,) of the design's inputs x (n, d):

- **functional chaos**: a polynomial expansion orthonormal for the inputs' law (the truncated
  normal or uniform marginals, by OpenTURNS' adaptive Stieltjes recurrences), total degree
  1..``max_degree``, the terms chosen by least-angle regression (LARS) and the corrected
  leave-one-out error; the degree with the best Q2 is kept;
- **kriging**: a Gaussian process with a constant trend and a Matern 5/2 covariance, on inputs
  and output scaled to unit spread, its scales and amplitude fitted by maximum likelihood.

Q2 = 1 - sum_i (y_i - y_hat_(-i))^2 / sum_i (y_i - mean y)^2, with y_hat_(-i) the prediction of
the metamodel fitted without point i's fold (``k-fold``) or without point i alone
(``leave-one-out``). The whole fit (degree, LARS selection, likelihood) is redone for each fold,
so Q2 judges the procedure, not one fitted model. The accuracy criterion of a campaign is Q2 >=
its ``q2`` for every output.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from clearbench.harness.studies.campaign.definition import CampaignDefinition, InputLaw

#: Kinds of metamodel.
CHAOS, KRIGING = "chaos", "kriging"


def _ot():
    import openturns as ot  # lazily: only metamodel campaigns need OpenTURNS

    ot.Log.Show(ot.Log.NONE)
    return ot


def marginal(law: InputLaw):
    """The OpenTURNS distribution of one input law (truncated normal or uniform)."""
    ot = _ot()
    if law.law == "uniform":
        return ot.Uniform(law.lower, law.upper)
    return ot.TruncatedNormal(law.mean, law.sigma, law.lower, law.upper)


def input_distribution(definition: CampaignDefinition):
    """The joint law of the inputs (independent marginals), as an OpenTURNS distribution."""
    ot = _ot()
    return ot.JointDistribution([marginal(law) for law in definition.inputs])


@dataclass
class FittedModel:
    """One output's metamodel.

    Attributes
    ----------
    kind : ``chaos`` or ``kriging``.
    degree : total degree of the chaos (0 for kriging).
    q2 : validation Q2 of this kind and settings on the design.
    residual_rms : root mean square of the validation residuals [output unit].
    predictions : validation predictions y_hat_(-i) (n,) [output unit].
    model : the fitted OpenTURNS result (chaos: FunctionalChaosResult; kriging: the fitted
        predictor's data).
    candidates : Q2 of every candidate tried, by label (``chaos-3``, ``kriging``).
    """

    kind: str
    degree: int
    q2: float
    residual_rms: float
    predictions: np.ndarray
    model: object
    candidates: dict = field(default_factory=dict)

    def predict(self, x: np.ndarray) -> np.ndarray:
        """Predictions at ``x`` (m, d) [output unit], shape (m,)."""
        return self.model.predict(np.asarray(x, dtype=float))


class ChaosPredictor:
    """A sparse functional chaos expansion of one output."""

    def __init__(self, result):
        self.result = result
        self.function = result.getMetaModel()

    def predict(self, x: np.ndarray) -> np.ndarray:
        return np.asarray(self.function(x), dtype=float)[:, 0]

    def moments(self) -> tuple[float, float]:
        """Mean and variance of the expansion over the inputs' law (exact for it)."""
        ot = _ot()
        vector = ot.FunctionalChaosRandomVector(self.result)
        return float(vector.getMean()[0]), float(vector.getCovariance()[0, 0])

    def sobol(self) -> tuple[np.ndarray, np.ndarray]:
        """First-order and total Sobol' indices (d,) of the expansion (exact for it)."""
        ot = _ot()
        indices = ot.FunctionalChaosSobolIndices(self.result)
        d = self.function.getInputDimension()
        return (np.array([indices.getSobolIndex(i) for i in range(d)]),
                np.array([indices.getSobolTotalIndex(i) for i in range(d)]))


class KrigingPredictor:
    """A kriging (Gaussian process) predictor of one output on scaled inputs and output."""

    def __init__(self, function, x_shift, x_scale, y_shift, y_scale, covariance):
        self.function = function
        self.x_shift, self.x_scale = x_shift, x_scale
        self.y_shift, self.y_scale = y_shift, y_scale
        self.covariance = covariance

    def predict(self, x: np.ndarray) -> np.ndarray:
        scaled = (np.asarray(x, dtype=float) - self.x_shift) / self.x_scale
        return self.y_shift + self.y_scale * np.asarray(self.function(scaled), float)[:, 0]


class ChaosBasis:
    """The orthonormal polynomial basis of the inputs' law (its recurrences computed once)."""

    def __init__(self, distribution):
        ot = _ot()
        self.distribution = distribution
        self.dimension = distribution.getDimension()
        factories = [ot.StandardDistributionPolynomialFactory(distribution.getMarginal(i))
                     for i in range(self.dimension)]
        self.enumerate = ot.LinearEnumerateFunction(self.dimension)
        self.basis = ot.OrthogonalProductPolynomialFactory(factories, self.enumerate)

    def fit(self, x: np.ndarray, y: np.ndarray, degree: int) -> ChaosPredictor:
        """Sparse chaos of total degree ``degree`` fitted on ``x`` (n, d), ``y`` (n,)."""
        ot = _ot()
        size = self.enumerate.getBasisSizeFromTotalDegree(degree)
        selection = ot.LeastSquaresMetaModelSelectionFactory(ot.LARS(),
                                                            ot.CorrectedLeaveOneOut())
        strategy = ot.LeastSquaresStrategy(selection)
        algorithm = ot.FunctionalChaosAlgorithm(
            ot.Sample(np.asarray(x, float)), ot.Sample(np.asarray(y, float)[:, None]),
            self.distribution, ot.FixedStrategy(self.basis, size), strategy)
        algorithm.run()
        return ChaosPredictor(algorithm.getResult())


def fit_kriging(x: np.ndarray, y: np.ndarray, covariance=None,
                optimise: bool = True) -> KrigingPredictor:
    """Kriging of ``y`` (n,) on ``x`` (n, d): constant trend, Matern 5/2 covariance on inputs
    and output scaled to unit spread; ``covariance`` (a fitted model) with ``optimise`` False
    keeps its parameters (the bootstrap refits with the design's hyperparameters)."""
    ot = _ot()
    x = np.asarray(x, float)
    y = np.asarray(y, float)
    x_shift, x_scale = x.mean(axis=0), np.where(x.std(axis=0) > 0, x.std(axis=0), 1.0)
    y_shift, y_scale = float(y.mean()), float(y.std()) or 1.0
    d = x.shape[1]
    if covariance is None:
        covariance = ot.MaternModel([1.0] * d, [1.0], 2.5)
    algorithm = ot.KrigingAlgorithm(ot.Sample((x - x_shift) / x_scale),
                                    ot.Sample(((y - y_shift) / y_scale)[:, None]),
                                    covariance, ot.ConstantBasisFactory(d).build())
    algorithm.setOptimizeParameters(optimise)
    if optimise:
        bounds = ot.Interval([1e-2] * d, [1e2] * d)
        algorithm.setOptimizationBounds(bounds)
    algorithm.run()
    result = algorithm.getResult()
    return KrigingPredictor(result.getMetaModel(), x_shift, x_scale, y_shift, y_scale,
                            result.getCovarianceModel())


def folds_of(n: int, validation: str, folds: int, seed: int) -> list[np.ndarray]:
    """Index sets left out in turn: ``leave-one-out`` (n sets of one) or ``k-fold`` (``folds``
    sets of a random partition drawn from ``seed``)."""
    if validation == "leave-one-out" or folds >= n:
        return [np.array([i]) for i in range(n)]
    order = np.random.default_rng(seed).permutation(n)
    return [np.sort(part) for part in np.array_split(order, folds)]


def q2_score(y: np.ndarray, predictions: np.ndarray) -> float:
    """Q2 of validation ``predictions`` (n,) of ``y`` (n,): 1 - PRESS / total sum of squares."""
    y = np.asarray(y, float)
    total = float(np.sum((y - y.mean()) ** 2))
    if total == 0:
        return math.nan
    return 1.0 - float(np.sum((y - predictions) ** 2)) / total


def cross_validated(fit, x: np.ndarray, y: np.ndarray, parts: list[np.ndarray]) -> np.ndarray:
    """Predictions y_hat_(-i) (n,): ``fit(x, y)`` -> predictor, refitted without each part;
    NaN for a part whose fit fails (too few points for the basis: the candidate's Q2 is then
    NaN and it is not chosen)."""
    predictions = np.empty(len(y))
    for part in parts:
        keep = np.ones(len(y), bool)
        keep[part] = False
        try:
            predictions[part] = fit(x[keep], y[keep]).predict(x[part])
        except (TypeError, RuntimeError, ValueError, np.linalg.LinAlgError):
            # OpenTURNS raises its InvalidArgumentException (a null eigenvalue of a basis
            # larger than the points) as a TypeError
            predictions[part] = np.nan
    return predictions


def choose_metamodel(x: np.ndarray, y: np.ndarray, basis: ChaosBasis | None,
                     candidates=(CHAOS, KRIGING), max_degree: int = 4,
                     validation: str = "k-fold", folds: int = 5, seed: int = 0
                     ) -> FittedModel:
    """Fit every candidate on ``x`` (n, d), ``y`` (n,), validate each, keep the best Q2.

    Chaos degrees are tried from 1 up to ``max_degree`` and stop after two degrees without a
    better Q2. Returns the chosen model refitted on the whole design, with every candidate's
    Q2.
    """
    x = np.asarray(x, float)
    y = np.asarray(y, float)
    parts = folds_of(len(y), validation, folds, seed)
    tried: dict[str, tuple[float, np.ndarray, int]] = {}
    if CHAOS in candidates and basis is not None:
        best, worse = -math.inf, 0
        for degree in range(1, max_degree + 1):
            if basis.enumerate.getBasisSizeFromTotalDegree(degree) > 20 * len(y):
                break
            predictions = cross_validated(lambda a, b, k=degree: basis.fit(a, b, k), x, y,
                                          parts)
            score = q2_score(y, predictions)
            tried[f"{CHAOS}-{degree}"] = (score, predictions, degree)
            if score > best:
                best, worse = score, 0
            else:
                worse += 1
                if worse >= 2:
                    break
    if KRIGING in candidates:
        predictions = cross_validated(fit_kriging, x, y, parts)
        tried[KRIGING] = (q2_score(y, predictions), predictions, 0)
    if not tried:
        raise ValueError("no metamodel candidate to fit")
    label = max(tried, key=lambda k: -math.inf if math.isnan(tried[k][0]) else tried[k][0])
    if math.isnan(tried[label][0]):
        raise ValueError(f"no metamodel could be validated on {len(y)} points "
                         f"(tried {', '.join(tried)})")
    score, predictions, degree = tried[label]
    kind = KRIGING if label == KRIGING else CHAOS
    model = fit_kriging(x, y) if kind == KRIGING else basis.fit(x, y, degree)
    rms = float(np.sqrt(np.mean((y - predictions) ** 2)))
    return FittedModel(kind, degree, score, rms, predictions, model,
                       {k: v[0] for k, v in tried.items()})


def refit(fitted: FittedModel, basis: ChaosBasis | None, x: np.ndarray,
          y: np.ndarray) -> ChaosPredictor | KrigingPredictor:
    """The same kind and settings refitted on other data (a bootstrap replicate): the chaos
    with its degree (LARS reselects the terms), the kriging with its fitted covariance on the
    distinct points."""
    if fitted.kind == CHAOS:
        return basis.fit(x, y, fitted.degree)
    _, first = np.unique(x, axis=0, return_index=True)
    return fit_kriging(x[first], y[first], covariance=fitted.model.covariance, optimise=False)
