"""Tolerance campaigns: the file's validation, the designs, the statistics on samples with known
answers, and runs on a Dask LocalCluster (resumed after a SIGKILL of the client and after the
loss of a worker, with no sample lost or recorded twice)."""

from __future__ import annotations

import json
import math
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import psutil
import pytest
from scipy import stats

from clearbench.harness.cli.main import main
from clearbench.harness.report.page import write_report
from clearbench.harness.run.store import ResultsStore
from clearbench.harness.studies.campaign import execution
from clearbench.harness.studies.campaign.definition import (
    SHIPPED,
    CampaignError,
    load_campaign,
    parse_campaign,
    with_overrides,
)
from clearbench.harness.studies.campaign.designs import sample_inputs, scene_parameters
from clearbench.harness.studies.campaign.execution import (
    execute_run,
    plan_samples,
    read_log,
    run_campaign,
)
from clearbench.harness.studies.campaign.report import (
    load_written_sections,
    write_campaign_report,
)
from clearbench.harness.studies.campaign.results import campaign_table, collect
from clearbench.harness.studies.campaign.statistics import (
    capability,
    cpk_standard_error,
    runs_needed,
    sensitivities,
)

ROOT = Path(__file__).resolve().parent.parent


def pendulum_campaign(samples: int = 4, design: str = "sobol", name: str = "pendulum-test",
                      engine: str = "mujoco") -> dict:
    """A campaign over the pendulum's initial angle and length: cheap runs (20 steps)."""
    return {
        "name": name, "scene": "pendulum", "engine": engine, "design": design,
        "samples": samples, "seed": 7, "horizon": 0.02, "timeout": 120,
        "inputs": [
            {"name": "angle", "parameter": "initial_angle", "unit": "rad", "law": "normal",
             "mean": 0.5, "sigma": 0.05, "lower": 0.3, "upper": 0.7},
            {"name": "length", "parameter": "length", "unit": "m", "law": "uniform",
             "lower": 0.5, "upper": 1.5},
        ],
        "outputs": [
            {"name": "final_angle", "output": "angle", "statistic": "final", "unit": "rad",
             "lower_limit": 0.0, "upper_limit": 1.0, "limits_source": "test"},
            {"name": "mean_x", "output": "bob_x", "statistic": "mean", "window": 0.01,
             "unit": "m"},
        ],
    }


def write_campaign(folder: Path, data: dict) -> Path:
    lines = []
    for key, value in data.items():
        if key not in ("inputs", "outputs"):
            lines.append(f"{key} = {json.dumps(value)}")
    for table in ("inputs", "outputs"):
        for entry in data[table]:
            lines.append(f"[[{table}]]")
            lines += [f"{k} = {json.dumps(v)}" for k, v in entry.items()]
    path = folder / f"{data['name']}.toml"
    path.write_text("\n".join(lines) + "\n")
    return path


# ---------------------------------------------------------------------- the campaign file
@pytest.mark.parametrize(("change", "field"), [
    ({"design": "latin"}, "design"),
    ({"samples": 0}, "samples"),
    ({"seed": -1}, "seed"),
    ({"samples": 2.5}, "samples"),
    ({"colour": "red"}, "colour"),
])
def test_bad_top_level_values_are_refused_naming_the_field(change, field):
    data = {**pendulum_campaign(), **change}
    with pytest.raises(CampaignError) as error:
        parse_campaign(data)
    assert error.value.field == field


@pytest.mark.parametrize(("index", "change", "field"), [
    (0, {"sigma": 0.0}, "inputs[0].sigma"),
    (0, {"law": "weibull"}, "inputs[0].law"),
    (0, {"upper": 0.2}, "inputs[0].upper"),
    (0, {"mean": 0.9}, "inputs[0].mean"),
    (1, {"name": "angle"}, "inputs[1].name"),
    (1, {"parameter": "initial_angle"}, "inputs[1].parameter"),
])
def test_bad_inputs_are_refused_naming_the_field(index, change, field):
    data = pendulum_campaign()
    data["inputs"][index] = {**data["inputs"][index], **change}
    with pytest.raises(CampaignError) as error:
        parse_campaign(data)
    assert error.value.field == field


def test_bad_outputs_are_refused_naming_the_field():
    data = pendulum_campaign()
    data["outputs"][1] = {k: v for k, v in data["outputs"][1].items() if k != "window"}
    with pytest.raises(CampaignError, match=r"outputs\[1\]\.window"):
        parse_campaign(data)
    data = pendulum_campaign()
    del data["outputs"][0]["upper_limit"]
    with pytest.raises(CampaignError, match=r"outputs\[0\]\.upper_limit"):
        parse_campaign(data)


def test_outputs_and_parameters_are_checked_against_the_scene_before_any_run():
    data = pendulum_campaign()
    data["outputs"][0]["output"] = "no_such_output"
    with pytest.raises(CampaignError, match=r"outputs\[0\]\.output.*its outputs: angle"):
        plan_samples(parse_campaign(data))
    data = pendulum_campaign()
    data["inputs"][1]["parameter"] = "radius"
    with pytest.raises(CampaignError, match="sample 0.*radius"):
        plan_samples(parse_campaign(data))
    with pytest.raises(CampaignError, match="engine"):
        plan_samples(parse_campaign({**pendulum_campaign(), "engine": "nope"}))


def test_unreadable_campaign_files_are_refused(tmp_path):
    binary = tmp_path / "binary.toml"
    binary.write_bytes(b"\xff\xfe\x00garbage")
    with pytest.raises(CampaignError, match="not UTF-8"):
        load_campaign(binary)
    broken = tmp_path / "broken.toml"
    broken.write_text("name = \n")
    with pytest.raises(CampaignError, match="invalid TOML"):
        load_campaign(broken)
    with pytest.raises(CampaignError, match="no such campaign file"):
        load_campaign(tmp_path / "missing.toml")
    assert main(["campaign", "status", str(binary), "--store", str(tmp_path)]) == 2


def test_the_shipped_study_campaigns_load_and_plan():
    assert {"c60-paper", "c60-paper-mc"} <= set(SHIPPED)
    study = load_campaign("c60-paper")
    assert study.samples >= 1000 and study.design == "sobol"
    assert [o.name for o in study.outputs] == [f"FC-{i}" for i in range(1, 7)]
    fc1 = study.outputs[0]
    assert (fc1.lower_limit, fc1.upper_limit) == (9.0, 16.0)   # published (Section 4.2)
    assert not any(o.has_limits for o in study.outputs[1:])     # not published
    samples = plan_samples(with_overrides(study, samples=2))
    clearances = dict(samples[1].spec.source.parameters)["clearances"]
    assert sorted(clearances) == [f"J{i}" for i in range(1, 8)]


# ---------------------------------------------------------------------- designs
@pytest.mark.parametrize("design", ["monte-carlo", "sobol"])
def test_sample_i_depends_only_on_seed_design_and_i(design):
    small = parse_campaign(pendulum_campaign(samples=8, design=design))
    large = with_overrides(small, samples=32)
    assert np.array_equal(sample_inputs(small), sample_inputs(large)[:8])
    assert np.array_equal(sample_inputs(large, 5, 3), sample_inputs(large)[5:8])
    assert np.array_equal(sample_inputs(small), sample_inputs(small))
    other_seed = with_overrides(small, seed=8)
    assert not np.array_equal(sample_inputs(small), sample_inputs(other_seed))


def test_corners_are_every_combination_of_the_bounds():
    corners = parse_campaign(pendulum_campaign(samples=4, design="corners"))
    values = sample_inputs(corners)
    assert {tuple(v) for v in values} == {(0.3, 0.5), (0.7, 0.5), (0.3, 1.5), (0.7, 1.5)}
    with pytest.raises(CampaignError, match="2\\^2 = 4"):
        parse_campaign(pendulum_campaign(samples=5, design="corners"))


def test_the_bounded_normal_law_is_the_truncated_normal():
    # 4096 Sobol' points of the study's law N(0.07, 0.0175) on [0.01, 0.13]: within bounds,
    # and mean and sigma those of the truncated law to 1 % of sigma (Sobol' integration
    # error at n = 4096 is far below that for a smooth integrand).
    data = pendulum_campaign(samples=4096)
    data["inputs"][0] = {"name": "J1", "parameter": "initial_angle", "law": "normal",
                         "mean": 0.07, "sigma": 0.0175, "lower": 0.01, "upper": 0.13}
    values = sample_inputs(parse_campaign(data))[:, 0]
    assert values.min() >= 0.01 and values.max() <= 0.13
    law = stats.truncnorm((0.01 - 0.07) / 0.0175, (0.13 - 0.07) / 0.0175, 0.07, 0.0175)
    assert abs(values.mean() - law.mean()) < 0.01 * 0.0175
    assert abs(values.std() - law.std()) < 0.01 * 0.0175


def test_dotted_parameters_build_nested_factory_arguments():
    data = pendulum_campaign()
    data["inputs"][1]["parameter"] = "clearances.J2"
    definition = parse_campaign(data)
    assert scene_parameters(definition, np.array([0.4, 0.05])) == {
        "initial_angle": 0.4, "clearances": {"J2": 0.05}}


# ---------------------------------------------------------------------- statistics
def test_capability_of_a_normal_sample_matches_the_analytic_indices():
    # n = 20000 draws of N(13.66, 0.239) with the study's FC-1 limits [9, 16]: Cp, Cpk within
    # 4 of their standard errors of the analytic values, Cc exact to the sample mean's error.
    rng = np.random.default_rng(1)
    mean, sigma, lower, upper = 13.66, 0.239, 9.0, 16.0
    values = rng.normal(mean, sigma, 20000)
    cap = capability(values, lower, upper)
    cp = (upper - lower) / (6 * sigma)
    cpk = (upper - mean) / (3 * sigma)
    assert abs(cap.cp.value - cp) < 4 * cp / math.sqrt(2 * 20000)
    assert abs(cap.cpk.value - cpk) < 4 * cpk_standard_error(cpk, 20000)
    assert cap.cp.low < cp < cap.cp.high
    assert cap.cpk.low < cpk < cap.cpk.high
    assert cap.mean.low < mean < cap.mean.high
    assert cap.sigma.low < sigma < cap.sigma.high
    # the paper's Cc for FC-1 (Section 4.2: 0.3314) follows from its mean and limits
    assert abs(capability([13.66 - 1e-3, 13.66 + 1e-3], lower, upper).cc - 0.3314) < 1e-4
    # far inside the limits: nothing outside, and a normal-fit PPM far below 1
    assert cap.ppm_observed == 0 and cap.ppm_normal < 1e-3
    assert 0 < cap.ppm_observed_upper < 200     # 95 % bound of 0 in 20000: 3/n = 150 ppm


def test_ppm_counts_the_samples_outside_and_the_normal_tail():
    values = np.concatenate([np.zeros(990), np.full(10, 5.0)])
    cap = capability(values, -1.0, 1.0)
    assert cap.ppm_observed == pytest.approx(1e4)
    cap = capability(np.random.default_rng(2).normal(0, 1, 100000), -2.0, 2.0)
    assert cap.ppm_normal == pytest.approx(2e6 * stats.norm.sf(2.0), rel=0.05)
    assert cap.ppm_observed == pytest.approx(2e6 * stats.norm.sf(2.0), rel=0.05)


def test_every_sample_outside_the_limits():
    # the C-60's FC-1 below its LSL in every run: all outside, bounds finite, Cpk negative
    cap = capability([6.9, 7.0, 7.1], 9.0, 16.0)
    assert cap.ppm_observed == 1e6 and cap.ppm_observed_upper == 1e6
    assert cap.cpk.value < 0 and cap.cc < -1


def test_no_limits_no_indices():
    cap = capability([1.0, 2.0, 3.0])
    assert cap.cp is None and cap.cpk is None and cap.cc is None and cap.ppm_normal is None
    assert cap.mean.value == 2.0 and cap.sigma.value == 1.0


def test_runs_needed_grows_as_the_interval_narrows():
    assert runs_needed(1.6, 0.05) > runs_needed(1.6, 0.1) > runs_needed(1.6, 0.2)
    # the returned count gives at most the asked half-width
    n = runs_needed(1.6, 0.1)
    assert stats.norm.ppf(0.975) * cpk_standard_error(1.6, n) <= 0.1


def test_sensitivities_find_the_driving_input_of_a_linear_response():
    # y = 3 x1 + x2 + 0 x3 (+ small noise): SRC proportional to 3 : 1 : 0 (equal input
    # spreads), R^2 near 1, S1 largest for x1.
    rng = np.random.default_rng(3)
    x = rng.uniform(0, 1, (2000, 3))
    y = 3 * x[:, 0] + x[:, 1] + 0.01 * rng.normal(size=2000)
    sens = sensitivities(x, y, ["a", "b", "c"], seed=1)
    assert sens.r_squared > 0.999
    assert sens.src[0] / sens.src[1] == pytest.approx(3.0, rel=0.05)
    assert abs(sens.src[2]) < 0.02
    assert np.argmax(sens.s1) == 0


def test_first_order_indices_are_salibs_estimator_on_all_the_runs():
    # SALib's delta.analyze takes its S1 on one bootstrap resample of the runs; the report's
    # S1 is the same estimator on all of them, so it does not depend on the seed (which
    # draws only the half-width's resamples). It is the between-class variance over SALib's
    # equal-count classes of each input's rank (6 at 1,024 runs: ranks in (m_j, m_j+1],
    # m = 0, 1024/6, ..), recomputed here; rel 1e-12: the same sums in another order.
    rng = np.random.default_rng(5)
    x = rng.standard_normal((1024, 3))
    y = x @ np.array([1.0, 0.5, 0.0])
    first = sensitivities(x, y, ["a", "b", "c"], seed=1)
    second = sensitivities(x, y, ["a", "b", "c"], seed=2)
    assert np.array_equal(first.s1, second.s1)
    assert not np.array_equal(first.s1_confidence, second.s1_confidence)
    edges = np.linspace(0.0, 1024.0, 7)
    for i in range(3):
        rank = np.argsort(np.argsort(x[:, i], kind="stable"), kind="stable") + 1
        between = sum(np.count_nonzero(c) * (y[c].mean() - y.mean()) ** 2 for c in (
            (rank > edges[j]) & (rank <= edges[j + 1]) for j in range(6))) / len(y)
        assert first.s1[i] == pytest.approx(between / np.var(y), rel=1e-12)


def test_an_input_that_does_nothing_keeps_the_grouping_floor_only():
    # Under no effect the between-class share over 6 classes of 1,024 runs averages
    # (6 - 1) / 1024 = 0.0049; on one bootstrap resample of the runs (delta.analyze's point
    # estimate) the repeated rows double it (0.0100 measured over 200 such designs). Over 30
    # designs the mean's standard error is 0.0005 (the share's sd 0.003 / sqrt(30)), so
    # 0.0073 (0.0049 + 4 standard errors) separates the two.
    rng = np.random.default_rng(11)
    inactive = [sensitivities(x, x @ np.array([1.0, 0.7, 0.0]), ["a", "b", "c"], seed=k).s1[2]
                for k, x in enumerate(rng.standard_normal((30, 1024, 3)))]
    assert np.mean(inactive) < 0.0073


def test_a_report_takes_the_runs_its_store_lacks_from_campaign_csvs(tmp_path):
    # A campaign reported from its CSV (written by another revision, or on another machine)
    # and an empty store: the same statistics as from the runs, each CSV used by the campaign
    # whose design it matches (here the study and a plain Monte Carlo companion).
    import pandas as pd

    definition = parse_campaign(pendulum_campaign(samples=8))
    companion = parse_campaign(pendulum_campaign(samples=4, design="monte-carlo",
                                                 name="pendulum-mc"))

    def csv_rows(campaign):
        return pd.DataFrame([{
            "sample": s.index, "key": f"{campaign.name}-{s.index}", "angle": s.inputs[0],
            "length": s.inputs[1], "status": "ok", "message": "", "worker_seconds": 2.0,
            "stepping_seconds": 1.0, "final_angle": 0.1 * s.index, "mean_x": 0.01 * s.index}
            for s in plan_samples(campaign)])

    ours, theirs = csv_rows(definition), csv_rows(companion)
    store = ResultsStore(tmp_path / "store")
    out = tmp_path / "out"
    summary = write_campaign_report(definition, store, out, (companion,),
                                    {"ours.csv": ours, "theirs.csv": theirs})
    assert summary["sources"] == {"given": 8}
    assert summary["outputs"][0]["capability"]["count"] == 8
    assert summary["outputs"][0]["capability"]["mean"]["value"] == pytest.approx(0.35)
    ours.to_csv(tmp_path / "ours.csv", index=False)
    # the same file, keys included (those of the runs that computed the rows)
    assert (out / "pendulum-test.csv").read_text() == (tmp_path / "ours.csv").read_text()
    assert "Runs by source: 8 given" in (out / "pendulum-test.md").read_text()
    # a CSV of neither campaign is refused by name; one with a sample's inputs changed, by
    # that sample
    other = ours.assign(angle=ours["angle"] + 0.01)
    with pytest.raises(CampaignError) as error:
        write_campaign_report(definition, store, out, given={"other.csv": other})
    assert error.value.field == "given other.csv"
    changed = ours.copy()
    changed.loc[2, "angle"] *= 1.01
    with pytest.raises(CampaignError) as error:
        write_campaign_report(definition, store, out, given={"changed.csv": changed})
    assert "sample 2" in error.value.field
    # the command names the CSV
    campaign = write_campaign(tmp_path, pendulum_campaign(samples=8))
    other.to_csv(tmp_path / "other.csv", index=False)
    assert main(["campaign", "report", str(campaign), "--store", str(tmp_path / "store"),
                 "--out", str(out), "--given", str(tmp_path / "other.csv")]) == 2


def test_collect_takes_the_statistic_over_the_last_window():
    data = pendulum_campaign()
    data["outputs"][1]["window"] = 0.05
    definition = parse_campaign(data)
    times = np.linspace(0.0, 1.0, 101)
    values = times * 10
    assert collect(definition.outputs[0], times, values) == 10.0          # final
    # the samples at t = 0.95 .. 1.00 (6 of them): mean 9.75
    assert collect(definition.outputs[1], times, values) == pytest.approx(9.75)


# ---------------------------------------------------------------------- running on Dask
def test_a_run_keyed_by_other_sources_stops_the_campaign_by_name(tmp_path):
    # A worker that runs other sources (edited while the campaign ran, or another checkout
    # behind a remote scheduler) keys its run otherwise: the client stores it under that key
    # and stops with the sample named, rather than wait for a key that never comes.
    from dataclasses import asdict

    from clearbench.harness.run.messages import MeasuredMessage, RanMessage
    from clearbench.harness.run.store import RunRecord, machine_info, revision_info

    sample = plan_samples(parse_campaign(pendulum_campaign()))[0]
    row = asdict(RunRecord.from_messages(sample.spec, RanMessage(status="ok"),
                                         MeasuredMessage(), revision_info(), machine_info()))
    store = ResultsStore(tmp_path / "store")
    assert execution._record(store, sample, {"row": row, "trajectory": None}).key == \
        sample.spec.key
    other = dict(row, key="0" * 24)
    with pytest.raises(CampaignError) as error:
        execution._record(store, sample, {"row": other, "trajectory": None})
    assert error.value.field == "sample 0" and "other sources" in error.value.reason
    assert store.keys() == {sample.spec.key, "0" * 24}


def test_a_dask_worker_keeps_its_run_process_warm_between_samples():
    # execute_run is what a Dask task calls: with runs_per_worker = 2 the first two samples
    # run in one process, which is then replaced; each sample's row is that of a fresh process
    samples = plan_samples(parse_campaign(pendulum_campaign(samples=3)))
    fresh = [execute_run(s.spec, runs_per_worker=1) for s in samples]
    warm, processes = [], []
    try:
        for sample in samples:
            warm.append(execute_run(sample.spec, runs_per_worker=2))
            runner = execution._WARM_RUNNERS[(threading.get_ident(), 2)]
            processes.append([slot.process.pid for slot in runner._slots])
    finally:
        for key in [(threading.get_ident(), 1), (threading.get_ident(), 2)]:
            execution._WARM_RUNNERS.pop(key).close()
    # kept after the first sample, retired after the second, a new one for the third
    assert len(processes[0]) == 1 and processes[1] == [] and len(processes[2]) == 1
    assert processes[0] != processes[2]
    for one, other in zip(fresh, warm, strict=True):
        assert one["row"]["status"] == other["row"]["status"] == "ok"
        assert one["row"]["metrics"] == other["row"]["metrics"]
        assert one["trajectory"] is not None and other["trajectory"] is not None


def test_a_campaign_runs_on_a_local_cluster_resumes_and_reports(tmp_path):
    definition = parse_campaign(pendulum_campaign(samples=4))
    store = ResultsStore(tmp_path / "store")
    first = run_campaign(definition, store, workers=2)
    assert (first.planned, first.already, first.recorded) == (4, 0, 4)
    assert first.statuses == {"ok": 4}
    # A kill -9 after the store's transaction and before the log's line (or in its middle):
    # the last sample's line is cut. The next call runs nothing and logs that sample again,
    # as recovered; the cut line is left out, and a new line never joins it.
    log = store.directory / "campaigns" / "pendulum-test.jsonl"
    lines = log.read_text().splitlines(keepends=True)
    last = next(i for i in reversed(range(len(lines))) if '"event": "sample"' in lines[i])
    lost = json.loads(lines[last])["key"]
    log.write_text("".join(lines[:last]) + lines[last][:25])
    again = run_campaign(definition, store, workers=2)
    assert (again.already, again.recorded) == (4, 0)
    entries = [e for e in read_log(log) if e.get("event") == "sample"]
    assert sorted(e["key"] for e in entries) == sorted(store.keys())
    assert [e["key"] for e in entries if e.get("recovered")] == [lost]
    more = run_campaign(with_overrides(definition, samples=6), store, workers=2)
    assert (more.already, more.recorded) == (4, 2)
    table = campaign_table(with_overrides(definition, samples=6), store)
    assert list(table["status"]) == ["ok"] * 6
    assert np.isfinite(table["final_angle"]).all() and np.isfinite(table["mean_x"]).all()
    summary = write_campaign_report(with_overrides(definition, samples=6), store,
                                    tmp_path / "out")
    assert summary["outputs"][0]["capability"]["count"] == 6
    assert summary["outputs"][1]["capability"]["cpk"] is None   # no limits given
    for suffix in (".md", ".html", ".json", ".csv"):
        assert (tmp_path / "out" / f"pendulum-test{suffix}").exists()
    assert summary["throughput"]["samples"] == 6 and summary["throughput"]["recovered"] == 1
    # the comparison report carries the campaign's section, figures included
    paths = write_report(store, tmp_path / "report", c60_validation=None,
                         campaigns=tmp_path / "out")
    page = paths["html"].read_text()
    assert "Tolerance campaign pendulum-test</h" in page  # a heading of the campaign's section
    assert "data:image/png;base64" in page
    markdown = paths["markdown"].read_text()
    assert "## Tolerance campaign `pendulum-test`" in markdown
    assert (tmp_path / "report" / "figures" / "pendulum-test_final_angle_histogram.png").exists()


def test_the_report_lists_a_study_before_the_companions_named_after_it(tmp_path):
    # sorted by file name, "c60-paper-mc.json" came before "c60-paper.json" ('-' < '.'), and
    # the comparison report opened with a companion instead of the study
    for name in ("c60-paper-mc-identified", "c60-paper", "c60-paper-mc"):
        summary = {"definition": {"name": name}, "outputs": []}
        (tmp_path / f"{name}.json").write_text(json.dumps(summary), encoding="utf-8")
    (tmp_path / "not-a-campaign.json").write_text("{}", encoding="utf-8")
    names = [summary["definition"]["name"] for summary, _ in load_written_sections(tmp_path)]
    assert names == ["c60-paper", "c60-paper-mc", "c60-paper-mc-identified"]


def recorded_keys(log: Path) -> list[str]:
    """Run keys of the samples a campaign's log records, in order."""
    return [entry["key"] for entry in read_log(log) if entry.get("event") == "sample"]


def campaign_command(campaign: Path, store_dir: Path) -> list[str]:
    return [sys.executable, "-m", "clearbench.harness.cli.main", "campaign", "run",
            str(campaign), "--store", str(store_dir), "--workers", "2", "--no-progress"]


def kill_after(command: list[str], log: Path, count: int, within: float = 300) -> int:
    """Start the campaign ``command``, SIGKILL it once its ``log`` records ``count`` samples
    (failing after ``within`` seconds), check that its cluster died with it; returns the
    samples recorded."""
    process = subprocess.Popen(command, cwd=ROOT, stdout=subprocess.DEVNULL,
                               stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + within
    while time.monotonic() < deadline:
        if log.exists() and len(recorded_keys(log)) >= count:
            break
        time.sleep(0.1)
    else:
        process.kill()
        pytest.fail(f"the campaign recorded {count} samples not within {within:g} s")
    children = psutil.Process(process.pid).children(recursive=True)
    process.send_signal(signal.SIGKILL)
    process.wait()
    psutil.wait_procs(children, timeout=30)   # the cluster dies with its client
    assert not [c for c in children if c.is_running() and c.status() != "zombie"]
    return len(recorded_keys(log))


def test_a_campaign_killed_with_sigkill_resumes_with_no_sample_lost_or_twice(tmp_path):
    campaign = write_campaign(tmp_path, pendulum_campaign(samples=8))
    store_dir = tmp_path / "store"
    log = store_dir / "campaigns" / "pendulum-test.jsonl"
    command = campaign_command(campaign, store_dir)
    assert kill_after(command, log, 2) >= 2
    resumed = subprocess.run(command, cwd=ROOT, capture_output=True, text=True, timeout=600)
    assert resumed.returncode == 0, resumed.stderr
    keys = recorded_keys(log)
    assert len(keys) == 8 and len(set(keys)) == 8        # every sample once
    definition = load_campaign(campaign)
    expected = {sample.spec.key for sample in plan_samples(definition)}
    assert set(keys) == expected
    assert set(ResultsStore(store_dir).keys()) == expected


def test_a_lost_worker_loses_no_sample(tmp_path):
    definition = parse_campaign(pendulum_campaign(samples=6))
    store = ResultsStore(tmp_path / "store")
    killed = []

    def kill_a_worker(index, record):
        if killed:
            return
        # a LocalCluster's nannies live in this process: its Dask worker processes are this
        # process's children (and each run's process their child). Kill one Dask worker while
        # samples are still running: Dask reruns its task elsewhere.
        workers = [c for c in psutil.Process(os.getpid()).children()
                   if "spawn_main" in " ".join(c.cmdline())]
        assert workers, "no Dask worker process found"
        workers[0].send_signal(signal.SIGKILL)
        killed.append(workers[0].pid)

    outcome = run_campaign(definition, store, workers=2, on_recorded=kill_a_worker)
    assert killed
    assert outcome.recorded == 6 and outcome.statuses == {"ok": 6}
    assert len(store.keys()) == 6
