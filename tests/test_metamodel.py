"""Metamodel campaigns: the file's [metamodel] table, the LHS design, Q2, the estimates of
functions with known answers (Ishigami's Sobol' indices, a linear model's failure
probability), and the adaptive campaign on Dask, resumed after a SIGKILL mid-batch with no run
made twice."""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import tomli_w
from scipy import stats

from clearbench.harness.run.store import ResultsStore
from clearbench.harness.studies.campaign.adaptive import (
    design_table,
    load_state,
    run_metamodel_campaign,
)
from clearbench.harness.studies.campaign.definition import (
    SHIPPED,
    CampaignError,
    load_campaign,
    parse_campaign,
)
from clearbench.harness.studies.campaign.designs import sample_inputs
from clearbench.harness.studies.campaign.execution import plan_samples
from clearbench.harness.studies.campaign.metamodel import (
    ChaosBasis,
    FittedModel,
    choose_metamodel,
    folds_of,
    input_distribution,
    q2_score,
)
from clearbench.harness.studies.campaign.metamodel_estimates import (
    bootstrap_estimates,
    pick_freeze,
    unexplained_variance,
)
from clearbench.harness.studies.campaign.rare_events import failure_probability
from tests.test_campaign import (
    campaign_command,
    kill_after,
    pendulum_campaign,
    recorded_keys,
)
from tools.sigma_estimator_bias import rough_response

ROOT = Path(__file__).resolve().parent.parent


def function_campaign(inputs: list[dict], samples: int = 64, design: str = "sobol",
                      **metamodel) -> dict:
    """A metamodel campaign over ``inputs`` whose outputs the tests compute themselves (the
    scene is only there to validate the file)."""
    return {"name": "function", "scene": "pendulum", "engine": "mujoco", "design": design,
            "samples": samples, "seed": 3, "method": "metamodel",
            "metamodel": {"batch": samples, **metamodel}, "inputs": inputs,
            "outputs": [{"name": "y", "output": "angle", "statistic": "final"}]}


def uniform(name: str, lower: float, upper: float) -> dict:
    return {"name": name, "parameter": name, "law": "uniform", "lower": lower, "upper": upper}


def standard_normal(name: str) -> dict:
    # bounded at +-8 sigma: the truncation moves a tail probability by < 1e-15
    return {"name": name, "parameter": name, "law": "normal", "mean": 0.0, "sigma": 1.0,
            "lower": -8.0, "upper": 8.0}


# ---------------------------------------------------------------------- the campaign file
@pytest.mark.parametrize(("change", "field"), [
    ({"method": "kriging"}, "method"),
    ({"metamodel": {"batch": 0}}, "metamodel.batch"),
    ({"metamodel": {"initial": 100}}, "metamodel.initial"),
    ({"metamodel": {"candidates": ["neural"]}}, "metamodel.candidates"),
    ({"metamodel": {"validation": "bootstrap"}}, "metamodel.validation"),
    ({"metamodel": {"q2": 1.5}}, "metamodel.q2"),
    ({"metamodel": {"targets": {"median": 0.1}}}, "metamodel.targets.median"),
    ({"metamodel": {"targets": {"s1": -0.1}}}, "metamodel.targets.s1"),
    ({"metamodel": {"colour": 1}}, "metamodel.colour"),
    ({"design": "corners"}, "design"),
])
def test_bad_metamodel_values_are_refused_naming_the_field(change, field):
    data = {**function_campaign([uniform("a", 0, 1)], samples=8), **change}
    with pytest.raises(CampaignError) as error:
        parse_campaign(data)
    assert error.value.field == field


def test_a_sampling_campaign_refuses_the_metamodel_table_and_lhs():
    data = pendulum_campaign()
    with pytest.raises(CampaignError) as error:
        parse_campaign({**data, "metamodel": {"batch": 4}})
    assert error.value.field == "metamodel"
    with pytest.raises(CampaignError) as error:
        parse_campaign({**data, "design": "lhs"})
    assert error.value.field == "design"


def test_the_shipped_metamodel_campaign_reuses_the_study_campaigns_samples():
    metamodel, study = load_campaign("c60-paper-metamodel"), load_campaign("c60-paper")
    assert "c60-paper-metamodel" in SHIPPED
    assert metamodel.method == "metamodel" and metamodel.samples == 256
    # the same law, design and seed: sample i is c60-paper's sample i, so its run key too
    assert np.array_equal(sample_inputs(metamodel, 0, 8), sample_inputs(study, 0, 8))


def test_lhs_batches_stratify_each_input_and_keep_earlier_batches():
    data = function_campaign([uniform("a", 0, 1), uniform("b", 0, 1)], samples=24,
                             design="lhs", batch=8)
    definition = parse_campaign(data)
    points = sample_inputs(definition)
    for block in range(3):
        rows = points[8 * block: 8 * block + 8]
        for column in rows.T:   # a Latin hypercube: one point in each eighth of [0, 1]
            assert sorted(np.floor(column * 8).astype(int)) == list(range(8))
    # point i depends on (seed, batch, i): a shorter or shifted request draws the same values
    assert np.array_equal(sample_inputs(definition, 5, 10), points[5:15])
    extended = parse_campaign({**data, "samples": 40})
    assert np.array_equal(sample_inputs(extended)[:24], points)


# ---------------------------------------------------------------------- validation
def test_q2_is_one_for_a_perfect_prediction_and_zero_for_the_mean():
    y = np.array([1.0, 2.0, 4.0, 8.0])
    assert q2_score(y, y) == 1.0
    assert q2_score(y, np.full(4, y.mean())) == pytest.approx(0.0, abs=1e-15)


def test_folds_partition_the_design():
    parts = folds_of(23, "k-fold", 5, seed=1)
    assert len(parts) == 5
    assert sorted(np.concatenate(parts).tolist()) == list(range(23))
    assert len(folds_of(6, "leave-one-out", 5, seed=1)) == 6


# ---------------------------------------------------------------------- known answers
def ishigami(x: np.ndarray) -> np.ndarray:
    return np.sin(x[:, 0]) + 7 * np.sin(x[:, 1]) ** 2 + 0.1 * x[:, 2] ** 4 * np.sin(x[:, 0])


#: Ishigami (a = 7, b = 0.1) on U(-pi, pi)^3: variance and partial variances in closed form.
ISHIGAMI_VARIANCE = 0.5 + 7**2 / 8 + 0.1 * math.pi**4 / 5 + 0.1**2 * math.pi**8 / 18
ISHIGAMI_V1 = 0.5 * (1 + 0.1 * math.pi**4 / 5) ** 2
ISHIGAMI_V2 = 7**2 / 8
ISHIGAMI_V13 = 0.1**2 * math.pi**8 * (1 / 18 - 1 / 50)
ISHIGAMI_S1 = np.array([ISHIGAMI_V1, ISHIGAMI_V2, 0.0]) / ISHIGAMI_VARIANCE
ISHIGAMI_ST = np.array([ISHIGAMI_V1 + ISHIGAMI_V13, ISHIGAMI_V2, ISHIGAMI_V13]) \
    / ISHIGAMI_VARIANCE


@pytest.mark.slow   # 27 chaos fits of degree 10 on 256 points: about 40 s on an idle core
def test_ishigami_indices_lie_within_their_bootstrap_intervals():
    inputs = [uniform(n, -math.pi, math.pi) for n in ("x1", "x2", "x3")]
    definition = parse_campaign(function_campaign(inputs, samples=256))
    x = sample_inputs(definition)
    y = ishigami(x)
    basis = ChaosBasis(input_distribution(definition))
    # degree 10: the sines need it (Q2 rises from 0.19 at degree 1 to 0.99999 at 10 on these
    # 256 points; the degree search is the slow test below)
    parts = folds_of(len(y), "k-fold", 5, seed=0)
    predictions = np.empty(len(y))
    for part in parts:
        keep = np.ones(len(y), bool)
        keep[part] = False
        predictions[part] = basis.fit(x[keep], y[keep], 10).predict(x[part])
    q2 = q2_score(y, predictions)
    assert q2 > 0.999   # a smooth function: the chaos carries all but 0.1 % of the variance
    rms = float(np.sqrt(np.mean((y - predictions) ** 2)))
    fitted = FittedModel("chaos", 10, q2, rms, predictions, basis.fit(x, y, 10))
    figures = bootstrap_estimates(fitted, basis, x, y, definition, None, None, replicates=20,
                                  seed=0)
    # the exact values inside the stated 95 % intervals, which are themselves narrow (the
    # intervals would also contain a wrong value if they were wide): half-width < 0.01
    for i in range(3):
        # widened by the unexplained share (< 1e-3 here), which the intervals do not carry
        slack = 2 * figures.unexplained
        assert figures.s1[i].low - slack <= ISHIGAMI_S1[i] <= figures.s1[i].high + slack
        assert figures.st[i].low - slack <= ISHIGAMI_ST[i] <= figures.st[i].high + slack
        assert figures.s1[i].high - figures.s1[i].low < 0.02
    assert figures.mean.low <= 3.5 <= figures.mean.high
    assert figures.sigma.low <= math.sqrt(ISHIGAMI_VARIANCE) * (1 + 1e-3)
    assert figures.sigma.high >= math.sqrt(ISHIGAMI_VARIANCE) * (1 - 1e-3)
    # interactions: only x1-x3, V13 / V = 0.2437 = 1 - S1_1 - S1_2
    assert figures.interaction.low - 1e-3 <= 1 - ISHIGAMI_S1.sum() \
        <= figures.interaction.high + 1e-3


def test_chaos_sigma_is_unbiased_on_a_rough_response():
    # sigma^2 = Var f + Var e over many designs of 256 runs, against the response's own sigma
    # (from 10^6 draws: its error, about 0.07 %, is far below the bound); PRESS / n in place
    # of the fit's residual gave +1.7 % (standard error 0.25 %) on this function
    # (python -m tools.sigma_estimator_bias)
    definition = parse_campaign(function_campaign(
        [standard_normal(f"x{i}") for i in range(7)], samples=256))
    basis = ChaosBasis(input_distribution(definition))
    rng = np.random.default_rng(5)
    exact = float(np.std(rough_response(rng.standard_normal((10**6, 7)))))
    ratios = []
    for _ in range(80):
        x = rng.standard_normal((256, 7))
        y = rough_response(x)
        predictor = basis.fit(x, y, 2)
        _, explained = predictor.moments()
        ratios.append(math.sqrt(explained + unexplained_variance("chaos", predictor, x, y,
                                                                 math.nan)) / exact)
    ratios = np.array(ratios)
    standard_error = ratios.std(ddof=1) / math.sqrt(len(ratios))
    # unbiased: the mean ratio within 3 standard errors of 1 (a 0.3 % chance to fail if it
    # is), and the standard error small enough (< 0.5 %) for the test to see a 2 % bias
    assert abs(ratios.mean() - 1.0) < 3 * standard_error
    assert standard_error < 0.005


def test_pick_freeze_indices_do_not_depend_on_the_outputs_offset():
    # y = offset + x1 + 0.5 x2 on U(0, 1)^3: S1 = ST = (0.8, 0.2, 0); an offset 1000 times the
    # spread (an FC at 10.7 mm with a sigma of 0.07 mm is 150 times) must change nothing
    rng = np.random.default_rng(0)
    a, b = rng.random((8192, 3)), rng.random((8192, 3))
    for offset in (0.0, 300.0):
        first, total = pick_freeze(lambda x, c=offset: c + x[:, 0] + 0.5 * x[:, 1], a, b)
        # 8192 pairs: the estimators' standard errors are about 0.01
        assert first == pytest.approx([0.8, 0.2, 0.0], abs=0.04)
        assert total == pytest.approx([0.8, 0.2, 0.0], abs=0.04)


@pytest.mark.slow
def test_the_degree_search_chooses_a_chaos_for_ishigami():
    inputs = [uniform(n, -math.pi, math.pi) for n in ("x1", "x2", "x3")]
    definition = parse_campaign(function_campaign(inputs, samples=256))
    x = sample_inputs(definition)
    basis = ChaosBasis(input_distribution(definition))
    fitted = choose_metamodel(x, ishigami(x), basis, max_degree=12)
    assert fitted.kind == "chaos" and fitted.q2 > 0.999
    assert fitted.candidates["kriging"] < fitted.q2


def linear_metamodel():
    """The chaos of y = 2 + a + 2 b (a, b standard normal: y ~ N(2, 5)) from 32 runs, and
    the inputs' law."""
    definition = parse_campaign(function_campaign([standard_normal("a"),
                                                   standard_normal("b")], samples=32))
    x = sample_inputs(definition)
    y = 2.0 + x[:, 0] + 2.0 * x[:, 1]
    distribution = input_distribution(definition)
    return choose_metamodel(x, y, ChaosBasis(distribution), candidates=("chaos",),
                            max_degree=1), distribution


def test_a_linear_models_failure_probability_matches_the_normal_tail():
    fitted, distribution = linear_metamodel()
    scale = math.sqrt(5.0)
    lower, upper = 2.0 - 4.0 * scale, 2.0 + 4.5 * scale    # beta 4 and 4.5
    exact = stats.norm.cdf(-4.0) + stats.norm.cdf(-4.5)     # 35.07 PPM
    result = failure_probability(fitted, distribution, lower, upper, seed=1)
    # FORM is exact for a limit state linear in the standard space: only the optimiser's
    # tolerance and the fit's round-off remain
    assert result["ppm_form"] == pytest.approx(1e6 * exact, rel=1e-4)
    assert [s.beta for s in result["sides"]] == pytest.approx([4.0, 4.5], rel=1e-5)
    low, high = result["ppm_importance_interval"]
    assert low <= 1e6 * exact <= high
    assert result["importance_cv"] <= 0.05 * 1.01    # the importance sampling's target CV
    # the design point of the lower side lies on the limit, along the gradient (1, 2)
    point = np.array(result["sides"][0].design_point)
    assert 2.0 + point[0] + 2.0 * point[1] == pytest.approx(lower, abs=1e-4 * scale)
    assert point[1] / point[0] == pytest.approx(2.0, rel=1e-3)


def test_a_side_the_median_inputs_already_fail_is_estimated_by_plain_monte_carlo():
    fitted, distribution = linear_metamodel()
    scale = math.sqrt(5.0)
    # the lower limit half a sigma above the median: P(y < LSL) = Phi(0.5) = 69 %, the
    # median design fails (post-analytical importance sampling centred on the design point
    # returned 3e-222 for such a side)
    lower, upper = 2.0 + 0.5 * scale, 2.0 + 6.0 * scale
    side = failure_probability(fitted, distribution, lower, upper, seed=1)["sides"][0]
    assert side.origin_fails and "plain Monte Carlo" in side.note
    # plain Monte Carlo to a CV of 5 %: the exact value inside 3 CVs (a 0.3 % chance of a
    # false failure for a normal estimator)
    exact = stats.norm.cdf(0.5)
    assert abs(side.importance - exact) <= 3 * side.importance_cv * exact


# ---------------------------------------------------------------------- on Dask
def pendulum_metamodel(samples: int = 12, **metamodel) -> dict:
    data = pendulum_campaign(samples=samples, name="pendulum-metamodel")
    data["outputs"] = [data["outputs"][1]]     # mean_x: smooth in the angle and the length
    data.update(method="metamodel", metamodel={
        "initial": 6, "batch": 3, "candidates": ["chaos"], "max_degree": 1,
        "bootstrap": 10, "confirmation_runs": 0, **metamodel})
    return data


def test_a_metamodel_campaign_stops_at_its_budget_or_its_targets(tmp_path):
    store = ResultsStore(tmp_path / "store")
    # Q2 >= 0.999999 is out of reach of 12 runs of a linear chaos: the budget ends it
    strict = parse_campaign(pendulum_metamodel(q2=0.999999))
    state = run_metamodel_campaign(strict, store, workers=2)
    assert state["stop"] == "run budget"
    assert [s["size"] for s in state["stages"]] == [6, 9, 12]
    assert state["stages"][-1]["short"] and state["runs"] == 12
    assert len(store.keys()) == 12
    # a loose target is met at the first stage (a linear chaos of the bob's mean x, smooth in
    # the angle and the length, validates on 9 runs well above Q2 0.5): no run beyond it
    # (the same samples, already in the store)
    loose = parse_campaign({**pendulum_metamodel(q2=0.5, initial=9), "name": "pendulum-loose"})
    state = run_metamodel_campaign(loose, store, workers=2)
    assert state["stop"] == "targets met" and [s["size"] for s in state["stages"]] == [9]
    assert len(store.keys()) == 12
    assert load_state(store, loose)["stop"] == "targets met"


def test_given_runs_must_have_the_designs_inputs(tmp_path):
    definition = parse_campaign(pendulum_metamodel())
    store = ResultsStore(tmp_path / "store")
    samples = plan_samples(definition, 0, 4)
    given = design_table(definition, store, 4)
    given["status"], given["mean_x"] = "ok", [0.1, 0.2, 0.3, 0.4]
    table = design_table(definition, store, 4, given)
    assert list(table["source"]) == ["given"] * 4 and list(table["mean_x"]) == [0.1, 0.2,
                                                                                0.3, 0.4]
    given.loc[2, "angle"] = samples[2].inputs[0] * 1.01
    with pytest.raises(CampaignError) as error:
        design_table(definition, store, 4, given)
    assert "sample 2" in error.value.field


def test_a_metamodel_campaign_killed_mid_batch_resumes_with_no_run_twice(tmp_path):
    # budget 15: 6 runs, then batches of 3, Q2 out of reach: every batch runs; killed after
    # 7 runs, i.e. inside the second batch
    campaign = tmp_path / "pendulum-metamodel.toml"
    campaign.write_text(tomli_w.dumps(pendulum_metamodel(samples=15, q2=0.999999)))
    store_dir = tmp_path / "store"
    log = store_dir / "campaigns" / "pendulum-metamodel.jsonl"
    command = campaign_command(campaign, store_dir)
    # (the first stage's fits come before the 7th run: a longer wait than a sampling campaign's)
    assert 7 <= kill_after(command, log, 7, within=900) < 15
    resumed = subprocess.run(command, cwd=ROOT, capture_output=True, text=True, timeout=600)
    assert resumed.returncode == 0, resumed.stderr
    assert "run budget" in resumed.stdout
    keys = recorded_keys(log)
    assert len(keys) == 15 and len(set(keys)) == 15        # every run once
    definition = load_campaign(campaign)
    assert set(keys) == {s.spec.key for s in plan_samples(definition)}
    # the report writes from the stored state, beside nothing (no --against)
    report = subprocess.run(
        [sys.executable, "-m", "clearbench.harness.cli.main", "campaign", "report",
         str(campaign), "--store", str(store_dir), "--out", str(tmp_path / "out")],
        cwd=ROOT, capture_output=True, text=True, timeout=600)
    assert report.returncode == 0, report.stderr
    markdown = (tmp_path / "out" / "pendulum-metamodel.md").read_text()
    assert "Stopped: **run budget** after 15 runs" in markdown
    assert (tmp_path / "out" / "figures" / "pendulum-metamodel_validation.png").exists()
