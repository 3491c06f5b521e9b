"""Capability statistics of a campaign's outputs, with confidence intervals, and sensitivities.

Definitions (the study's Appendix A, with USL and LSL the specification limits, m the mean
and s the standard deviation of the output over the samples):

- Cp = (USL - LSL) / (6 s): the tolerance range against the spread;
- Cpk = min(USL - m, m - LSL) / (3 s) (Eq. 29): the spread and the shift together;
- Cc = (m - (USL + LSL) / 2) / ((USL - LSL) / 2) (Eq. 30, the nominal taken at the middle of
  the limits): the centring, signed (> 0 shifted towards USL);
- PPM: parts per million outside [LSL, USL], counted in the sample (with its Clopper-Pearson
  95 % upper bound) and from the fitted normal law.

Confidence intervals (95 %): the mean from Student's t, the standard deviation from the
chi-square law, Cp from the latter, Cpk from Bissell's normal approximation
(SE^2 = 1/(9n) + Cpk^2/(2(n-1))). :func:`runs_needed` inverts the last for a wanted half-width.

Sensitivities (:func:`sensitivities`): standardised regression coefficients (SRC) of a linear
least-squares fit of the output on the inputs, with the fit's R^2. Where R^2 is close to 1 the
response is near linear and SRC^2 is each input's share of the variance (first-order Sobol'
index); the first-order indices S1 are also estimated from the same given data, with no
special design and no linearity, by the estimator of SALib's delta method
(``SALib.analyze.delta.sobol_first``): the between-class variance of the output over
equal-count classes of the input's rank, over the output's variance.

That estimator is taken here on all the runs, with SALib's number of classes and SALib's
half-width (1.96 standard deviations of the estimator over bootstrap resamples of the runs).
``SALib.analyze.delta.analyze`` returns instead its value on one bootstrap resample of the runs:
a point estimate with 1.35 to 1.7 times the scatter on random runs, and a floor above the
index of an input that does little (on 200 designs of 1,024 runs of a linear response, 0.013
for an index of 0.003, against 0.008 on all the runs: ``python -m tools.first_order_checks
--linear-test``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import stats

#: Confidence level of every interval.
CONFIDENCE = 0.95


@dataclass(frozen=True)
class Interval:
    """A value with its confidence interval."""

    value: float
    low: float
    high: float


@dataclass(frozen=True)
class Capability:
    """Summary of one output over the ok samples (units: the output's, indices unitless).

    ``cp``, ``cpk``, ``cc`` and the PPM figures are None when the output has no limits.
    """

    count: int
    mean: Interval
    sigma: Interval
    minimum: float
    maximum: float
    cp: Interval | None
    cpk: Interval | None
    cc: float | None
    ppm_observed: float | None
    ppm_observed_upper: float | None
    ppm_normal: float | None


def _t_interval(values: np.ndarray) -> Interval:
    n = len(values)
    mean = float(np.mean(values))
    if n < 2:
        return Interval(mean, math.nan, math.nan)
    half = stats.t.ppf(0.5 + CONFIDENCE / 2, n - 1) * np.std(values, ddof=1) / math.sqrt(n)
    return Interval(mean, mean - half, mean + half)


def _sigma_interval(values: np.ndarray) -> Interval:
    n = len(values)
    if n < 2:
        return Interval(math.nan, math.nan, math.nan)
    sigma = float(np.std(values, ddof=1))
    alpha = 1 - CONFIDENCE
    low = sigma * math.sqrt((n - 1) / stats.chi2.ppf(1 - alpha / 2, n - 1))
    high = sigma * math.sqrt((n - 1) / stats.chi2.ppf(alpha / 2, n - 1))
    return Interval(sigma, low, high)


def cpk_standard_error(cpk: float, count: int) -> float:
    """Bissell's standard error of an estimated Cpk from ``count`` normal samples."""
    return math.sqrt(1.0 / (9.0 * count) + cpk**2 / (2.0 * (count - 1)))


def runs_needed(cpk: float, half_width: float) -> int:
    """Samples for a 95 % interval of Cpk of +- ``half_width`` (Bissell's approximation)."""
    z = stats.norm.ppf(0.5 + CONFIDENCE / 2)
    return int(math.ceil((z / half_width) ** 2 * (1.0 / 9.0 + cpk**2 / 2.0))) + 1


def capability(values, lower: float | None = None, upper: float | None = None) -> Capability:
    """Capability of the finite ``values`` (n,) against [lower, upper] (both or neither)."""
    values = np.asarray(values, dtype=float)
    values = values[np.isfinite(values)]
    n = len(values)
    if n == 0:
        nan = Interval(math.nan, math.nan, math.nan)
        return Capability(0, nan, nan, math.nan, math.nan, None, None, None, None, None, None)
    mean = _t_interval(values)
    sigma = _sigma_interval(values)
    cp = cpk = cc = ppm = ppm_upper = ppm_normal = None
    if lower is not None and upper is not None and n >= 2 and sigma.value > 0:
        width = upper - lower
        cp = Interval(width / (6 * sigma.value), width / (6 * sigma.high),
                      width / (6 * sigma.low))
        value = min(upper - mean.value, mean.value - lower) / (3 * sigma.value)
        half = stats.norm.ppf(0.5 + CONFIDENCE / 2) * cpk_standard_error(value, n)
        cpk = Interval(value, value - half, value + half)
        cc = (mean.value - 0.5 * (upper + lower)) / (0.5 * width)
        outside = int(np.count_nonzero((values < lower) | (values > upper)))
        ppm = 1e6 * outside / n
        # Clopper-Pearson upper bound (one-sided); every sample outside: the bound is 1
        ppm_upper = 1e6 * (float(stats.beta.ppf(CONFIDENCE, outside + 1, n - outside))
                           if outside < n else 1.0)
        ppm_normal = 1e6 * float(stats.norm.cdf(lower, mean.value, sigma.value)
                                 + stats.norm.sf(upper, mean.value, sigma.value))
    return Capability(n, mean, sigma, float(np.min(values)), float(np.max(values)), cp, cpk,
                      cc, ppm, ppm_upper, ppm_normal)


@dataclass(frozen=True)
class Sensitivity:
    """Which input drives an output: per input (d,) SRC, SALib's first-order index S1 and its
    confidence half-width; R^2 of the linear fit."""

    names: tuple[str, ...]
    src: np.ndarray
    r_squared: float
    s1: np.ndarray
    s1_confidence: np.ndarray


#: Bootstrap resamples of the runs for S1's half-width (SALib's delta method's default).
S1_RESAMPLES = 100


def first_order_classes(runs: int) -> int:
    """The equal-count classes of an input's rank over which SALib's delta method estimates
    S1 from ``runs`` runs (``SALib.analyze.delta``, 1.6: 6 classes at 1,024 runs, at most 48)."""
    exponent = 2.0 / (7.0 + np.tanh((1500.0 - runs) / 500.0))
    return int(np.round(min(int(np.ceil(runs**exponent)), 48)))


def first_order_indices(inputs: np.ndarray, output: np.ndarray,
                        seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """S1 of ``output`` (n,) on each column of ``inputs`` (n, d), each (d,), with its 95 %
    half-width: SALib's delta-method estimator on all the runs; the half-width over
    :data:`S1_RESAMPLES` bootstrap resamples drawn with ``seed``."""
    from SALib.analyze.delta import sobol_first  # lazily: only campaign reports need SALib

    n, d = inputs.shape
    edges = np.linspace(0.0, n, first_order_classes(n) + 1)
    s1 = np.array([sobol_first(output, inputs[:, i], edges) for i in range(d)])
    draws = np.random.default_rng(seed).integers(n, size=(S1_RESAMPLES, n))
    replicates = np.array([[sobol_first(output[r], inputs[r, i], edges) for i in range(d)]
                           for r in draws])
    half = float(stats.norm.ppf(0.5 + CONFIDENCE / 2.0)) * replicates.std(axis=0, ddof=1)
    return s1, half


def sensitivities(inputs: np.ndarray, output: np.ndarray, names,
                  seed: int = 0) -> Sensitivity:
    """SRC and first-order indices of ``output`` (n,) on ``inputs`` (n, d).

    Rows with a non-finite output are left out; ``seed`` draws the bootstrap resamples of
    S1's half-width (the values themselves do not depend on it).
    """
    inputs = np.asarray(inputs, dtype=float)
    output = np.asarray(output, dtype=float)
    keep = np.isfinite(output)
    x, y = inputs[keep], output[keep]
    d = x.shape[1]
    nan = np.full(d, np.nan)
    if len(y) < d + 2 or np.std(y) == 0:
        return Sensitivity(tuple(names), nan, math.nan, nan, nan)
    xs = (x - x.mean(axis=0)) / np.where(x.std(axis=0) > 0, x.std(axis=0), 1.0)
    ys = (y - y.mean()) / y.std()
    design = np.column_stack([np.ones(len(ys)), xs])
    coefficients, *_ = np.linalg.lstsq(design, ys, rcond=None)
    residual = ys - design @ coefficients
    r_squared = 1.0 - float(residual @ residual) / float(ys @ ys)
    s1, half = first_order_indices(x, y, seed)
    return Sensitivity(tuple(names), coefficients[1:], r_squared, s1, half)


def running_moments(values) -> tuple[np.ndarray, np.ndarray]:
    """Mean and standard deviation of the first k values, k = 1..n (each (n,)); the standard
    deviation is NaN for k = 1."""
    values = np.asarray(values, dtype=float)
    k = np.arange(1, len(values) + 1)
    mean = np.cumsum(values) / k
    square = np.cumsum(values**2) / k
    variance = np.where(k > 1, (square - mean**2) * k / np.maximum(k - 1, 1), np.nan)
    return mean, np.sqrt(np.maximum(variance, 0.0))
