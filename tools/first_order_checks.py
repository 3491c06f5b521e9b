"""Given-data estimates of first-order Sobol' indices side by side, from a campaign's CSV.

For each input x_i of one output y, four estimates of S1_i = Var E[y | x_i] / Var y from the
same runs: SALib's delta method (as the campaign report shows it), the squared standardised
regression coefficient (S1 for a linear response of independent inputs), a cubic regression
of y on x_i alone, and 20 equal-count bins of x_i (the between-bin variance less its expected
value under no effect, (bins - 1) Var y / n). They disagree where one estimator is biased or
noisy; the metamodel campaign's report compares its S1 with SALib's.

    .venv/bin/python -m tools.first_order_checks c60-paper FC-3 [--csv FILE]
"""

from __future__ import annotations

import argparse

import numpy as np
import pandas as pd

from clearbench.harness.studies.campaign.definition import load_campaign
from clearbench.harness.studies.campaign.statistics import sensitivities

BINS = 20


def cubic_share(x: np.ndarray, y: np.ndarray) -> float:
    """Var of the cubic least-squares fit of ``y`` (n,) on ``x`` (n,), over Var y."""
    z = (x - x.mean()) / x.std()
    design = np.vander(z, 4)
    coefficients, *_ = np.linalg.lstsq(design, y, rcond=None)
    return float(np.var(design @ coefficients) / np.var(y))


def binned_share(x: np.ndarray, y: np.ndarray, bins: int = BINS) -> float:
    """Between-bin variance of ``y`` over ``bins`` equal-count bins of ``x``, bias-corrected,
    over Var y."""
    parts = np.array_split(np.argsort(x), bins)
    means = np.array([y[p].mean() for p in parts])
    counts = np.array([len(p) for p in parts])
    between = float(np.sum(counts * (means - y.mean()) ** 2) / len(y))
    return (between - (bins - 1) / len(y) * float(np.var(y))) / float(np.var(y))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("campaign")
    parser.add_argument("output")
    parser.add_argument("--csv", default=None,
                        help="the campaign's CSV (default reports/campaigns/CAMPAIGN.csv)")
    args = parser.parse_args()
    definition = load_campaign(args.campaign)
    table = pd.read_csv(args.csv or f"reports/campaigns/{args.campaign}.csv")
    table = table[(table["status"] == "ok") & np.isfinite(table[args.output])]
    names = [law.name for law in definition.inputs]
    x = table[names].to_numpy(float)
    y = table[args.output].to_numpy(float)
    bounds = np.column_stack([x.min(axis=0), x.max(axis=0)])
    salib = sensitivities(x, y, names, bounds, seed=definition.seed)
    print(f"{args.output} on {len(y)} runs; linear R^2 {salib.r_squared:.3f}")
    print(f"{'input':<8}{'SALib delta':>18}{'SRC^2':>8}{'cubic':>8}{'bins':>8}")
    for i, name in enumerate(names):
        print(f"{name:<8}{salib.s1[i]:>10.3f} +- {salib.s1_confidence[i]:.3f}"
              f"{salib.src[i] ** 2:>8.3f}{cubic_share(x[:, i], y):>8.3f}"
              f"{binned_share(x[:, i], y):>8.3f}")


if __name__ == "__main__":
    main()
