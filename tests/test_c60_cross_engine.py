"""The C-60 across engines: per-joint excess, work-precision and the steps for 1 % on FC-1,
the report's C-60 section rendered from realistic figures, the demo plan, the engine styles."""

from __future__ import annotations

import html
import math

import numpy as np

from clearbench.harness.c60.cross_engine import C60RunFigures, joint_excess
from clearbench.harness.c60.work_precision import error_budget, work_precision
from clearbench.harness.report.c60_section import (
    EVENT_BOUND,
    C60Section,
    compare_events,
    condense,
    section_html,
    section_markdown,
)
from clearbench.harness.report.engine_style import engine_style
from clearbench.harness.run.engine_choice import EngineChoice
from clearbench.harness.studies.c60_comparison import (
    c60_plan,
    expected_cost,
    plan_engines,
    plan_runs,
)
from clearbench.scenarios.library import get_scene

FC_REST = {"FC-2": 10.62, "FC-3": 2.83, "FC-4": 10.73, "FC-5": 2.29, "FC-6": 0.51}


def _on(label, dt, fc1, wall, status="ok", **extra) -> C60RunFigures:
    """A c60-on run with the figures measured on this machine (4 ms horizon)."""
    values = dict(key=f"{label}-{dt}", scene_name="c60-on", label=label, engine_version="x",
                  time_step=dt, horizon=4.0, status=status, message="",
                  functional_conditions={"FC-1": fc1, **FC_REST}, latch_creep=1e-12,
                  latched=True, penetration_max=1e-6, penetration_pair="Rod_hook_J6_bot",
                  clearance_excess={"J1": 1e-7, "J6": 1e-6}, stepping_seconds=wall,
                  stepping_seconds_per_step=wall * dt / 4.0, simulated_until=4.0)
    values.update(extra)
    return C60RunFigures(**values)


def _trip(label, dt, opening, wall) -> C60RunFigures:
    return C60RunFigures(key=f"trip-{label}-{dt}", scene_name="c60-trip", label=label,
                         engine_version="x", time_step=dt, horizon=8.5, status="ok",
                         message="", strike=3.10, release=6.83, opening=opening,
                         stepping_seconds=wall, stepping_seconds_per_step=wall * dt / 8.5,
                         simulated_until=8.5)


RUNS = [
    _on("reference[default]", 1e-3, 7.3457, 25.4),
    _on("reference[default]", 4e-3, 7.3244, 17.6),
    _on("mujoco[tuned]", 1e-3, 7.2877, 1.33),
    _on("mujoco[tuned]", 4e-3, 7.3585, 1.04),
    _on("siconos[default]", 1e-2, 7.2361, 82.5),
    _on("mujoco[default]", 1e-3, 0.0, 9.5, status="diverged", latch_creep=1.64, latched=False,
        message="penetration 0.495 exceeds its smallest feature 0.1 (tunnelled)"),
    _on("exudyn[tuned]", 1e-3, math.nan, 39.9, status="diverged", simulated_until=0.111,
        functional_conditions={}, latch_creep=math.nan, latched=None,
        message="Exudyn solver failed at t = 0.110561"),
    _trip("reference[default]", 1e-3, 7.59, 195.0),
    _trip("mujoco[tuned]", 4e-3, 7.48, 7.1),
]


def test_work_precision_errors_front_and_error_budget():
    studies = {s.quantity: s for s in work_precision(RUNS)}
    fc1 = studies["FC-1"]
    assert fc1.reference_value == 7.3457 and fc1.reference_step == 1e-3
    # The fine reference is what the others are measured against, not a point; the diverged
    # runs are not points either.
    assert {(p.label, p.time_step) for p in fc1.points} == {
        ("reference[default]", 4e-3), ("mujoco[tuned]", 1e-3), ("mujoco[tuned]", 4e-3),
        ("siconos[default]", 1e-2)}
    errors = {(p.label, p.time_step): p.error for p in fc1.points}
    # |7.2877 - 7.3457| / 7.3457 = 0.79 %, to the digits given (the figures are exact inputs).
    assert math.isclose(errors[("mujoco[tuned]", 1e-3)], 0.0580 / 7.3457, rel_tol=1e-9)
    front = {(p.label, p.time_step) for p in fc1.points if p.on_front}
    assert front == {("mujoco[tuned]", 4e-3)}   # fastest and most accurate of the four
    budget = {t.label: t for t in error_budget(RUNS, fc1, 0.01)}
    # both steps within 1 % (0.79 % and 0.17 %): the cheaper, 4 us at 1.04 s
    assert budget["mujoco[tuned]"].time_step == 4e-3
    assert budget["mujoco[tuned]"].wall_seconds == 1.04
    assert budget["siconos[default]"].time_step is None       # 1.49 %: not met
    assert "1 % not met: 1.49 % at its finest step" in budget["siconos[default]"].describe()
    # The finest reference run is the yardstick (error 0); its 4 us run (0.29 %) is cheaper.
    assert budget["reference[default]"].time_step == 4e-3
    assert budget["reference[default]"].errors[0] == (1e-3, 0.0)
    # mujoco[default] diverged at its only step: the budget is not met, and it says why.
    assert budget["mujoco[default]"].time_step is None
    assert "diverged" in budget["mujoco[default]"].reason
    opening = studies["opening time"]
    assert [p.label for p in opening.points] == ["mujoco[tuned]"]
    # 0.11 ms early on 7.59 ms: 1.45 % (exact arithmetic on the given figures).
    assert math.isclose(opening.points[0].error, 0.11 / 7.59, rel_tol=1e-9)


def test_c60_section_renders_every_engine_and_the_reasons():
    cannot = {"pybullet": "not available here: pybullet does not import",
              "siconos[projection]": "pair:arc-bore: it projects; pair:arc-disc: it projects"}
    studies = work_precision(RUNS)
    budgets = [b for s in studies for target in (0.01, 0.05) for b in error_budget(RUNS, s, target)]
    section = C60Section(RUNS, studies, budgets, cannot)
    page = section_html(section)
    for label in ("reference[default]", "mujoco[tuned]", "mujoco[default]", "siconos[default]",
                  "exudyn[tuned]"):
        assert label in page
    assert "diverged at 0.111 ms" in page              # where the Exudyn run stopped
    assert "SLIPS, creep 1.64 mm" in page and "holds" in page    # the latch verdicts
    assert "-0.79 %" in page                           # FC-1 of mujoco[tuned] vs the reference
    assert "7.480 (-1.45 %)" in page                    # opening time vs the reference's
    # worst joint, all folded; 1e-6 mm written in um
    assert "<details><summary>J6 0.001 µm</summary>" in page
    assert "pybullet does not import" in page
    assert "pair:arc-bore, pair:arc-disc: it projects" in page  # one reason, said once
    markdown = "\n".join(section_markdown(section, "figures/c60-work-precision.png"))
    assert "| mujoco[tuned] | 0.004 | 4 | ok | 7.36 (+0.174 %)" in markdown
    assert "not met: 1.49 % at its finest step, dt = 0.01 ms" in markdown
    assert "![C-60 work-precision](figures/c60-work-precision.png)" in markdown


def _ladder(label, steps, values, walls, statuses=None) -> list[C60RunFigures]:
    statuses = statuses or ["ok"] * len(steps)
    return [_on(label, dt, v, w, status=st) for dt, v, w, st
            in zip(steps, values, walls, statuses, strict=True)]


def test_error_budget_takes_the_cheapest_step_whose_finer_steps_stay_within():
    # The reference's 1 us run (the yardstick) costs 9.7 s, its 4 us run 15.3 s (its contact
    # solver iterates more): the budget picks the cheaper 1 us run, not the larger step.
    runs = _ladder("reference[default]", [1e-3, 4e-3], [7.3457, 7.3440], [9.7, 15.3])
    # pybullet[tuned]: 1 us within 0.5 %, 2 us +1.7 %, 4 us within 1 % again: at 1 % only
    # 1 us qualifies (4 us is within 1 %, but a finer step is not).
    runs += _ladder("pybullet[tuned]", [1e-3, 2e-3, 4e-3],
                    [7.3457 * 1.005, 7.3457 * 1.017, 7.3457 * 0.995], [40.0, 20.0, 10.0])
    # drake[tuned]: its finest step diverged, so no coarser step is trusted.
    runs += _ladder("drake[tuned]", [1e-3, 2e-3], [math.nan, 7.3457], [50.0, 25.0],
                    ["diverged", "ok"])
    study = next(s for s in work_precision(runs) if s.quantity == "FC-1")
    one = {b.label: b for b in error_budget(runs, study, 0.01)}
    five = {b.label: b for b in error_budget(runs, study, 0.05)}
    assert (one["reference[default]"].time_step, one["reference[default]"].wall_seconds) == \
        (1e-3, 9.7)
    assert one["pybullet[tuned]"].time_step == 1e-3
    assert five["pybullet[tuned]"].time_step == 4e-3            # all three within 5 %
    assert math.isclose(five["pybullet[tuned]"].error, 0.005, rel_tol=1e-9)
    assert one["drake[tuned]"].time_step is None and five["drake[tuned]"].time_step is None
    assert "dt = 0.001 ms, diverged" in one["drake[tuned]"].reason


def test_each_trip_event_is_compared_and_flagged_beyond_the_bound():
    reference = _trip("reference[default]", 1e-3, 7.59, 195.0)
    # mujoco[tuned] lets the latch go at 3.22 ms against 6.83 ms: -52.9 %, flagged; its
    # strike 1 % late and its opening 1.45 % early stay within the 5 % bound.
    early = C60RunFigures(key="k", scene_name="c60-trip", label="mujoco[tuned]",
                          engine_version="x", time_step=4e-3, horizon=8.5, status="ok",
                          message="", strike=3.10 * 1.01, release=3.22, opening=7.48)
    compared = {c.event: c for c in compare_events(early, reference)}
    assert set(compared) == {"strike", "release", "opening"}
    assert math.isclose(compared["release"].change, (3.22 - 6.83) / 6.83)
    assert compared["release"].flagged and "-52.9 %" in compared["release"].text()
    assert not compared["strike"].flagged and not compared["opening"].flagged
    assert EVENT_BOUND == 0.05
    # An event the reference has and the run not (no opening) is flagged too.
    stuck = C60RunFigures(**{**early.__dict__, "opening": math.nan})
    assert {c.event: c.flagged for c in compare_events(stuck, reference)}["opening"]
    # The section's trip table shows every event with its difference.
    page = section_html(C60Section([reference, early], work_precision([reference, early])))
    assert "3.220 (-52.9 %) \u2691" in page and "3.131 (+1 %)" in page


def test_condense_says_each_reason_once():
    assert condense("a: x; b: x; c: y") == "a, b: x; c: y"
    assert condense("plain reason") == "plain reason"


def test_joint_excess_groups_the_ring_pairs_by_joint():
    scene = get_scene("c60-on", horizon=0.01)
    names = [c.name for c in scene.expanded.contacts]
    depth = np.zeros((3, len(names)))
    depth[1, names.index("Rod_hook_J6_bot")] = 2e-3
    depth[2, names.index("Rod_hook_J6_top")] = 3e-3
    depth[0, names.index("Mcontact_Fcontact_bot_1_C7")] = 9.0   # not a joint's ring
    excess = joint_excess(scene, depth)
    assert set(excess) == {"J1", "J2", "J3", "J4", "J5", "J6", "J7", "S3"}
    assert excess["J6"] == 3e-3 and excess["J1"] == 0.0


def test_demo_plan_runs_longest_first_with_shortened_horizons():
    engines = [EngineChoice("mujoco", "tuned", "clearbench.adapters.mujoco", ""),
               EngineChoice("reference", "default", "clearbench.adapters.reference", ""),
               EngineChoice("exudyn", "mechanism", "clearbench.adapters.exudyn", "")]
    demo = c60_plan("demo")
    specs = plan_runs(demo, engines)
    # Exudyn's 4,000 C-60 steps at 98 reference steps each come first, then the reference's
    # 8,500-step c60-trip; MuJoCo's 8 us c60-on (500 steps at 0.32) is last.
    assert [s.engine.label for s in specs[:2]] == ["exudyn[mechanism]", "reference[default]"]
    assert specs[1].scene.name == "c60-trip"
    assert (specs[-1].engine.label, specs[-1].time_step) == ("mujoco[tuned]", 8e-3)
    costs = [expected_cost(s) for s in specs]
    assert costs == sorted(costs, reverse=True)
    assert {s.engine.label for s in specs} == {"reference[default]", "mujoco[tuned]",
                                              "exudyn[mechanism]"}
    for spec in specs:
        assert spec.horizon == demo.horizons[spec.scene.name]
        # about one sample per 0.01 ms, whatever the step
        assert math.isclose(spec.record_every * spec.time_step, 0.01, rel_tol=0.5)
    _, left_out = plan_engines(demo, ["nosuch[default]"])
    assert "nosuch[default]" in left_out and "unknown engine" in left_out["nosuch[default]"]


def test_each_engine_keeps_one_style():
    names = ["reference", "mujoco", "pybullet", "exudyn", "siconos"]
    assert len({engine_style(n).colour for n in names}) == len(names)
    assert engine_style("mujoco[tuned]").colour == engine_style("mujoco[default]").colour
    assert engine_style("mujoco[tuned]").marker != engine_style("mujoco[default]").marker
    assert engine_style("mujoco[tuned] dt=0.001") == engine_style("mujoco[tuned]")
    assert engine_style("mine[odd]") == engine_style("mine[odd]")   # stable for any label


def test_conclusions_give_one_line_per_engine_and_the_model_against_the_paper():
    import json

    from clearbench.harness.report.conclusions import conclusions, standing
    from clearbench.harness.report.page import C60_VALIDATION

    studies = work_precision(RUNS)
    budgets = [b for s in studies for b in error_budget(RUNS, s, 0.01)]
    section = C60Section(RUNS, studies, budgets)
    labels = sorted({r.label for r in RUNS})
    lines = {c.label: c for c in conclusions(labels, [], section)}
    assert list(lines)[0] == "reference[default]"
    assert lines["mujoco[tuned]"].on.startswith("FC-1 7.29 N (-0.79 %), latch holds")
    assert lines["mujoco[tuned]"].trip.startswith("strike 3.100 (+0 %), release 6.830 (+0 %)")
    assert lines["mujoco[tuned]"].budget == "dt 0.004 ms (1.04 s per run)"
    assert lines["exudyn[tuned]"].on.startswith("diverged at 0.111 ms")
    assert lines["siconos[default]"].budget.startswith("not met: 1.49 %")
    assert lines["siconos[default]"].library == "not run"
    # The model's standing, from the committed validation: its FC-1 row, not a variant's
    # (the figures are the JSON's, whatever the model's physics gives).
    validation = json.loads(C60_VALIDATION.read_text())
    sentence = standing(validation)
    row = next(r for r in validation["rows"] if r["quantity"].startswith("FC-1")
               and "variant" not in (r["note"] or ""))
    assert sentence.startswith("The C-60 model as its source gives it (the reference engine) "
                               f"has FC-1 {row['ours']:.3g} N against the paper's "
                               f"{row['paper_simulated']:g} N simulated and "
                               f"{row['paper_measured']:g} N measured "
                               f"({100 * row['difference']:+.0f} %)")


def test_the_instrument_figure_stands_beside_the_kernels():
    """A run's stored instrument figures reach the C-60 table: the largest penetration read
    by the independent instrument, and UNSEEN with the verdict's words where it saw more."""
    from clearbench.harness.c60.cross_engine import run_figures

    reason = ("unseen penetration: Hook_Tbar_C4_4 at t = 7.37 ms: the instrument witnesses "
              "0.0685 mm, the kernel's figure is 0 mm")
    row = {"key": "k", "scene_name": "c60-trip", "engine": "reference", "preset": "default",
           "time_step": 1e-3, "horizon": 8.5, "status": "ok", "verdict_reason": reason,
           "metrics": '{"instrument_penetration_max": 0.0685, "unseen_penetration": 0.0685, '
                      '"unseen_penetration_time": 7.37}'}
    run = run_figures(row, None, None)
    assert (run.instrument_penetration, run.unseen_time) == (0.0685, 7.37)
    section = C60Section([*RUNS, run], [])
    markdown = "\n".join(section_markdown(section, "f.png"))
    # 0.0685 mm written in µm (html_parts.length_text: µm below 0.1 mm)
    assert "68.5 µm UNSEEN 68.5 µm more than the kernel's at 7.37 ms" in markdown
    assert html.escape(reason) in section_html(section)  # among the run messages
