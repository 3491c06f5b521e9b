"""The C-60 across engines: per-joint excess, work-precision and the steps for 1 % on FC-1,
the report's C-60 section rendered from realistic figures, the demo plan, the engine styles."""

from __future__ import annotations

import html
import math

import numpy as np

from clearbench.harness.c60.cross_engine import C60RunFigures, joint_excess
from clearbench.harness.c60.work_precision import steps_for_target, work_precision
from clearbench.harness.report.c60_section import (
    C60Section,
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


def test_work_precision_errors_front_and_steps_for_one_percent():
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
    targets = {t.label: t for t in steps_for_target(fc1)}
    assert targets["mujoco[tuned]"].time_step == 4e-3         # both steps within 1 %: largest
    assert targets["siconos[default]"].time_step is None       # 1.49 %: not reached
    assert "1 % not reached" in targets["siconos[default]"].describe()
    opening = studies["opening time"]
    assert [p.label for p in opening.points] == ["mujoco[tuned]"]
    # 0.11 ms early on 7.59 ms: 1.45 % (exact arithmetic on the given figures).
    assert math.isclose(opening.points[0].error, 0.11 / 7.59, rel_tol=1e-9)


def test_c60_section_renders_every_engine_and_the_reasons():
    cannot = {"pybullet": "not available here: pybullet does not import",
              "siconos[projection]": "pair:arc-bore: it projects; pair:arc-disc: it projects"}
    studies = work_precision(RUNS)
    section = C60Section(RUNS, studies, {s.quantity: steps_for_target(s) for s in studies},
                         cannot)
    page = section_html(section)
    for label in ("reference[default]", "mujoco[tuned]", "mujoco[default]", "siconos[default]",
                  "exudyn[tuned]"):
        assert label in page
    assert "diverged at 0.111 ms" in page              # where the Exudyn run stopped
    assert "SLIPS, 1.64" in page and "holds" in page    # the latch verdicts
    assert "-0.79 %" in page                           # FC-1 of mujoco[tuned] vs the reference
    assert "7.480 (-1.45 %)" in page                    # opening time vs the reference's
    assert "<details><summary>J6 1.00e-06</summary>" in page   # worst joint, all folded
    assert "pybullet does not import" in page
    assert "pair:arc-bore, pair:arc-disc: it projects" in page  # one reason, said once
    markdown = "\n".join(section_markdown(section, "figures/c60-work-precision.png"))
    assert "| mujoco[tuned] | 0.004 | 4 | ok | 7.36 (+0.174 %)" in markdown
    assert "siconos[default], FC-1: 1 % not reached on the ladder: best 1.49 %" in markdown
    assert "![C-60 work-precision](figures/c60-work-precision.png)" in markdown


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
    section = C60Section([*RUNS, run], [], {}, {})
    markdown = "\n".join(section_markdown(section, "f.png"))
    assert "0.0685 UNSEEN 0.0685 more than the kernel's at 7.37 ms" in markdown
    assert html.escape(reason) in section_html(section)  # among the run messages
