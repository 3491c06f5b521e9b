"""The metamodel's sigma on a rough response of known sigma: the bias of each estimate of
Var e (docs/campaigns.md, "The figures").

A response of 7 standard normal inputs with a quarter of its variance rough
(:func:`rough_response`, Q2 about 0.74 as FC-1's on the C-60) is fitted on many designs of
256 runs. For each, sigma = sqrt(Var f + Var e) with Var e taken as the validation's PRESS / n
(5-fold) or as the fit's own mean squared residual (:func:`unexplained_variance`), and the
design's plain sample sigma. Printed: the mean of each over the response's exact sigma (from
10^6 draws) and its standard error.

    .venv/bin/python -m tools.sigma_estimator_bias [--chaos-designs 120] [--kriging-designs 16]

(kriging takes about 15 s a design; 0 skips it.)
"""

from __future__ import annotations

import argparse
import math

import numpy as np

from clearbench.harness.studies.campaign.definition import parse_campaign
from clearbench.harness.studies.campaign.metamodel import (
    CHAOS,
    KRIGING,
    ChaosBasis,
    cross_validated,
    fit_kriging,
    folds_of,
    input_distribution,
)
from clearbench.harness.studies.campaign.metamodel_estimates import (
    EVALUATION_POINTS,
    unexplained_variance,
)

INPUTS = 7
RUNS = 256


def rough_response(x: np.ndarray) -> np.ndarray:
    """A response of 7 normal inputs with a quarter of its variance rough (a sine too fast and a
    switch too sharp for a chaos of degree 2): Q2 about 0.74, FC-1's on the C-60."""
    smooth = x @ np.array([1.0, 0.8, 0.7, 0.6, 0.3, 0.2, 0.1]) + 0.3 * x[:, 0] * x[:, 1] \
        + 0.2 * x[:, 2] ** 2
    return smooth + 1.3 * (np.sin(4 * x[:, 0] + 3 * x[:, 3])
                           + 0.7 * np.sign(x[:, 1] - x[:, 4]))


def normal_basis() -> ChaosBasis:
    """The chaos basis of 7 standard normal inputs (bounded at +-8 sigma, as a campaign file
    states them)."""
    inputs = [{"name": f"x{i}", "parameter": f"x{i}", "law": "normal", "mean": 0.0,
               "sigma": 1.0, "lower": -8.0, "upper": 8.0} for i in range(INPUTS)]
    definition = parse_campaign({
        "name": "rough", "scene": "pendulum", "engine": "mujoco", "design": "sobol",
        "samples": RUNS, "seed": 3, "method": "metamodel", "metamodel": {"batch": RUNS},
        "inputs": inputs, "outputs": [{"name": "y", "output": "angle", "statistic": "final"}]})
    return ChaosBasis(input_distribution(definition))


def sigma_ratios(kind: str, designs: int, exact: float, rng) -> dict[str, list[float]]:
    """Per estimate, sigma / ``exact`` on each of ``designs`` designs of RUNS runs."""
    basis = normal_basis() if kind == CHAOS else None
    points = rng.standard_normal((EVALUATION_POINTS, INPUTS))
    ratios = {"Var f + PRESS / n": [], "Var f + the fit's residual": [], "sample sigma": []}
    for design in range(designs):
        x = rng.standard_normal((RUNS, INPUTS))
        y = rough_response(x)
        fit = (lambda a, b: basis.fit(a, b, 2)) if kind == CHAOS else fit_kriging
        validation = cross_validated(fit, x, y, folds_of(RUNS, "k-fold", 5, design))
        press = float(np.mean((y - validation) ** 2))
        model = fit(x, y)
        if kind == CHAOS:
            explained = model.moments()[1]
            residual = unexplained_variance(CHAOS, model, x, y, math.sqrt(press))
        else:   # the fit's residual of an interpolating kriging (0 on its design)
            explained = float(np.var(model.predict(points), ddof=1))
            residual = float(np.mean((y - model.predict(x)) ** 2))
        ratios["Var f + PRESS / n"].append(math.sqrt(explained + press) / exact)
        ratios["Var f + the fit's residual"].append(math.sqrt(explained + residual) / exact)
        ratios["sample sigma"].append(float(np.std(y, ddof=1)) / exact)
    return ratios


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--chaos-designs", type=int, default=120)
    parser.add_argument("--kriging-designs", type=int, default=16)
    args = parser.parse_args()
    rng = np.random.default_rng(0)
    exact = float(np.std(rough_response(rng.standard_normal((10**6, INPUTS)))))
    for kind, designs in ((CHAOS, args.chaos_designs), (KRIGING, args.kriging_designs)):
        if designs < 1:
            continue
        for label, values in sigma_ratios(kind, designs, exact, rng).items():
            values = np.array(values)
            error = values.std(ddof=1) / math.sqrt(len(values))
            print(f"{kind:<8} {designs:>4} designs  {label:<28} sigma / exact "
                  f"{values.mean():.4f} (standard error {error:.4f})")


if __name__ == "__main__":
    main()
