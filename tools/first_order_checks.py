"""Given-data estimates of first-order Sobol' indices side by side, from a campaign's CSV.

For each input x_i of one output y, six estimates of S1_i = Var E[y | x_i] / Var y from the
same runs: SALib's delta-method estimator on all the runs (the campaign report's S1) and as
``SALib.analyze.delta.analyze`` returns it (on one bootstrap resample of the runs, drawn with
the campaign's seed), SALib's
RBD-FAST (each with its bootstrap half-width), the squared standardised regression coefficient
(S1 for a linear response of independent inputs), a cubic regression of y on x_i alone, and
20 equal-count bins of x_i (the between-bin variance less its expected value under no effect,
(bins - 1) Var y / n). They disagree where one estimator is biased or noisy; the metamodel
campaign's report compares its S1 with the campaign report's.

    .venv/bin/python -m tools.first_order_checks c60-paper FC-3 [--csv FILE]
    .venv/bin/python -m tools.first_order_checks c60-paper all \\
        --metamodel reports/campaigns/c60-paper-metamodel.json
    .venv/bin/python -m tools.first_order_checks --linear-test

``--linear-test``: the delta-method estimator on one resample and on all the runs, and
RBD-FAST, on a linear response of 7 standard normal inputs (exact S1 = a_i^2 / sum a^2), 1,024
runs, over 200 random designs and 200 scrambled Sobol' designs; then on Ishigami's function
(a = 7, b = 0.1, inputs uniform on [-pi, pi]; exact S1 0.3139, 0.4424, 0), with how often each
estimator's own 95 % interval holds the exact value (about 5 minutes).
"""

from __future__ import annotations

import argparse
import json

import numpy as np
import pandas as pd

from clearbench.harness.studies.campaign.definition import load_campaign
from clearbench.harness.studies.campaign.statistics import (
    first_order_classes,
    sensitivities,
)

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


def grouped_share(conditional_mean, classes: int, grid: int = 600_000) -> float:
    """Var of the means of ``conditional_mean`` (a function of the input's quantile u in
    (0, 1)) over ``classes`` equal-probability classes, over its own variance: the share of
    an exact first-order index that a between-class estimator with that many classes keeps."""
    values = conditional_mean((np.arange(grid) + 0.5) / grid)
    means = [part.mean() for part in np.array_split(values, classes)]
    return float(np.var(means) / np.var(values)) if np.var(values) > 0 else 0.0


def known_response_test(designs: int = 200, runs: int = 1024) -> None:
    """Print three given-data S1 estimators over ``designs`` designs of ``runs`` each, against
    the exact S1 of a linear response of 7 standard normal inputs and of Ishigami's function:
    SALib's delta-method estimator on one bootstrap resample of the runs (as
    ``SALib.analyze.delta.analyze`` returns it), the same estimator on all the runs (the
    campaign report's S1), and RBD-FAST; for each, its mean, its standard deviation over the
    designs, and the share of designs whose interval (S1 +- its half-width) holds the exact
    value."""
    from SALib.analyze import rbd_fast  # lazily, as statistics.sensitivities does
    from SALib.analyze.delta import sobol_first
    from scipy import stats  # lazily: only this test needs normal quantiles
    from scipy.stats import qmc

    weights = np.array([1.0, 0.8, 0.7, 0.6, 0.9, 0.3, 0.1])
    # E[y | x_i] as a function of x_i's quantile u (constants dropped)
    normal = stats.norm.ppf

    def angle(u):
        """The quantile ``u`` of a uniform input on [-pi, pi]."""
        return np.pi * (2.0 * u - 1.0)

    def sobol_normal(rng):
        """A scrambled Sobol' design of standard normal inputs (the campaigns' design)."""
        return normal(qmc.Sobol(len(weights), scramble=True, seed=rng).random(runs))

    cases = [
        ("linear", len(weights), lambda rng: rng.standard_normal((runs, len(weights))),
         lambda x: x @ weights, weights**2 / np.sum(weights**2), [normal] * len(weights)),
        ("linear, scrambled Sobol' design", len(weights), sobol_normal,
         lambda x: x @ weights, weights**2 / np.sum(weights**2), [normal] * len(weights)),
        ("ishigami", 3, lambda rng: rng.uniform(-np.pi, np.pi, (runs, 3)),
         lambda x: (np.sin(x[:, 0]) + 7.0 * np.sin(x[:, 1]) ** 2
                    + 0.1 * x[:, 2] ** 4 * np.sin(x[:, 0])),
         np.array([0.3139, 0.4424, 0.0]),
         [lambda u: np.sin(angle(u)), lambda u: np.sin(angle(u)) ** 2, lambda u: 0.0 * u]),
    ]
    classes = first_order_classes(runs)
    edges = np.linspace(0.0, runs, classes + 1)
    print(f"SALib's delta method groups each input into {classes} equal-count classes at {runs} "
          "runs; 'grouped': the exact S1 seen through such classes")
    rng = np.random.default_rng(0)
    for label, dimension, draw, response, exact, conditional_means in cases:
        grouped = exact * np.array([grouped_share(g, classes) for g in conditional_means])
        names = [f"x{i}" for i in range(dimension)]
        problem = {"num_vars": dimension, "names": names,
                   "bounds": [[-5.0, 5.0]] * dimension}
        resampled, full, half, fast, fast_half = [], [], [], [], []
        for design in range(designs):
            x = draw(rng)
            y = response(x)
            found = sensitivities(x, y, names, seed=design + 1)
            full.append(found.s1)
            half.append(found.s1_confidence)
            resample = rng.integers(runs, size=runs)
            resampled.append([sobol_first(y[resample], x[resample, i], edges)
                              for i in range(dimension)])
            analysed = rbd_fast.analyze(problem, x, y, seed=design + 1)
            fast.append(analysed["S1"])
            fast_half.append(analysed["S1_conf"])
        print(f"{label}: {runs} runs, {designs} designs; mean, sd over the designs, share of "
              "intervals holding the exact value")
        print(f"{'input':<7}{'exact':>7}{'grouped':>8}{'one resample':>20}{'all runs':>20}"
              f"{'RBD-FAST':>20}")
        columns = [(np.array(resampled), np.array(half)), (np.array(full), np.array(half)),
                   (np.array(fast), np.array(fast_half))]
        for i, name in enumerate(names):
            cells = "".join(
                f"{values[:, i].mean():>8.3f}{values[:, i].std():>6.3f}"
                f"{np.mean(np.abs(values[:, i] - exact[i]) <= halves[:, i]):>6.2f}"
                for values, halves in columns)
            print(f"{name:<7}{exact[i]:>7.3f}{grouped[i]:>8.3f}{cells}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("campaign", nargs="?")
    parser.add_argument("output", nargs="?")
    parser.add_argument("--csv", default=None,
                        help="the campaign's CSV (default reports/campaigns/CAMPAIGN.csv)")
    parser.add_argument("--metamodel", default=None, metavar="JSON",
                        help="a metamodel campaign's report JSON: its S1 intervals beside, "
                        "OUTPUT 'all' for each output it holds")
    parser.add_argument("--linear-test", action="store_true",
                        help="SALib's estimators on a linear response and Ishigami's function")
    args = parser.parse_args()
    if args.linear_test:
        known_response_test()
        return
    if args.output is None:
        parser.error("CAMPAIGN and OUTPUT are needed (or --linear-test)")
    definition = load_campaign(args.campaign)
    table = pd.read_csv(args.csv or f"reports/campaigns/{args.campaign}.csv")
    metamodel = None
    if args.metamodel:
        with open(args.metamodel, encoding="utf-8") as handle:
            reported = json.load(handle)["outputs"]
        metamodel = {entry["name"]: entry["s1"] for entry in reported}
    for output in (metamodel or {}) if args.output == "all" else [args.output]:
        compare_output(definition, table, output, None if metamodel is None
                       else metamodel[output])


def compare_output(definition, table: pd.DataFrame, output: str, metamodel_s1) -> None:
    """Print the five estimates of each input's S1 for ``output``; with ``metamodel_s1`` (a
    list of {value, low, high} per input), the metamodel's interval, and a mark where an
    estimate's interval (S1 +- its half-width) does not overlap it."""
    from SALib.analyze import rbd_fast  # lazily, as statistics.sensitivities does

    table = table[(table["status"] == "ok") & np.isfinite(table[output])]
    names = [law.name for law in definition.inputs]
    x = table[names].to_numpy(float)
    y = table[output].to_numpy(float)
    bounds = np.column_stack([x.min(axis=0), x.max(axis=0)])
    salib = sensitivities(x, y, names, seed=definition.seed)
    problem = {"num_vars": len(names), "names": names, "bounds": bounds.tolist()}
    fast = rbd_fast.analyze(problem, x, y, seed=definition.seed)
    from SALib.analyze import delta

    analysed = delta.analyze(problem, x, y, num_resamples=100, seed=definition.seed,
                             method="sobol")
    print(f"{output} on {len(y)} runs; linear R^2 {salib.r_squared:.3f}"
          + ("; * : no overlap with the metamodel's interval" if metamodel_s1 else ""))
    print(f"{'input':<8}{'delta, all runs':>19}{'delta.analyze':>19}{'RBD-FAST':>19}"
          f"{'SRC^2':>8}{'cubic':>8}{'bins':>8}" + (f"{'metamodel':>24}" if metamodel_s1 else ""))
    for i, name in enumerate(names):
        estimates = [(salib.s1[i], salib.s1_confidence[i]),
                     (analysed["S1"][i], analysed["S1_conf"][i]),
                     (fast["S1"][i], fast["S1_conf"][i])]
        marks, interval = ["", "", ""], ""
        if metamodel_s1:
            low, high = metamodel_s1[i]["low"], metamodel_s1[i]["high"]
            marks = [" " if value + half >= low and value - half <= high else "*"
                     for value, half in estimates]
            interval = (f"{metamodel_s1[i]['value']:>10.3f} [{low:.3f}, {high:.3f}]")
        cells = "".join(f"{value:>10.3f} +- {half:.3f}{mark}"
                        for (value, half), mark in zip(estimates, marks, strict=True))
        print(f"{name:<8}{cells}{salib.src[i] ** 2:>8.3f}{cubic_share(x[:, i], y):>8.3f}"
              f"{binned_share(x[:, i], y):>8.3f}{interval}")


if __name__ == "__main__":
    main()
