"""The regression tolerance model: classification of figures, checks, comparison lines, and
the round-off perturbation of a scene (no engine runs)."""

from __future__ import annotations

import math

import pytest

from clearbench.harness.run.runner import worker_environment
from clearbench.harness.run.spec import resolve_scene
from clearbench.harness.studies.regress import Check, classify, compare
from clearbench.harness.studies.regress.perturbations import (
    EPS,
    perturb_initial_state,
    variants_for,
)
from clearbench.harness.studies.regress.tolerance import (
    BOUND_HEADROOM,
    ENSEMBLE_WIDEN,
    EXACT_WIDEN,
    FLOOR_RELATIVE,
    figure_dimension,
)

#: The contacts of the engine a figure comes from: rigid (the reference, Siconos) or
#: compliant (MuJoCo, PyBullet, Exudyn), as each declares (HARNESS_DEFAULTS.rigid_contacts).
RIGID, COMPLIANT = True, False


def test_a_figure_moved_by_round_off_is_exact_within_its_widened_spread():
    check = classify("apex_heights.rest_time", RIGID, 1.0, [1.0 + 1e-15, 1.0 - 3e-15],
                     scale=1.0)
    assert check.kind == "exact" and check.spread == pytest.approx(3e-15)
    # tolerance = 10 x 3e-15 + 1e-8 x max(1, 1): the floor dominates.
    assert check.limit == pytest.approx(EXACT_WIDEN * 3e-15 + FLOOR_RELATIVE)
    assert check.allows(1.0 + 0.5e-8) and not check.allows(1.0 + 2e-8)


def test_a_spread_of_zero_does_not_make_the_check_bitwise():
    # A length of 0.68 m in a scene of size 1.1 m: floor 1e-8 x 1.1 m = 1.1e-8 m.
    check = classify("stop.stop_distance", RIGID, 0.68, [0.68, 0.68], scale=1.1)
    assert check.kind == "exact" and check.spread == 0.0
    assert check.allows(0.68 + 1e-8) and not check.allows(0.68 + 1.2e-8)
    # A 1 % friction change moves the stop distance by 1 %: six orders above the floor.
    assert not check.allows(0.68 * 0.99)


def test_energy_growth_is_checked_as_a_bound_not_as_equality():
    # The clearance pendulum's contact-free energy growth on two CPUs (issue's figures).
    check = classify("energy_growth_contact_free", RIGID, 9.6552e-07,
                     [9.61e-07, 9.70e-07], scale=1.0)
    assert check.kind == "bounded"
    assert check.limit == pytest.approx(BOUND_HEADROOM * 9.70e-07)
    assert check.allows(8.98594e-07)            # the other CPU's value
    assert check.allows(0.0)
    assert not check.allows(1e-5)               # ten times the largest measured: a change


def test_a_rigid_engines_penetration_is_bounded_a_compliant_engines_is_not():
    rigid = classify("penetration_max", RIGID, 6.9e-18, [0.0, 1.4e-17], scale=1.1)
    assert rigid.kind == "bounded"
    # Round-off values: the floor 1e-8 x the scene's size is the bound.
    assert rigid.limit == pytest.approx(FLOOR_RELATIVE * 1.1)
    soft = classify("penetration_max", COMPLIANT, 1.2e-4, [1.2e-4, 1.2e-4], scale=1.1)
    assert soft.kind == "exact"
    # 1 % more penetration (a softer contact) is 1.2e-6 m, above the floor of 1.1e-8 m.
    assert not soft.allows(1.2e-4 * 1.01)


def test_a_chaotic_figure_is_judged_against_its_ensembles_widened_range():
    ensemble = [8.9e-4, 1.0e-3, 9.5e-4, 9.9e-4, 9.1e-4, 9.7e-4, 1.01e-3, 9.3e-4]
    check = classify("fc1_force", COMPLIANT, 8.94e-4, ensemble, scale=50.0)
    assert check.kind == "statistical" and check.samples == 8
    assert check.low == 8.9e-4 and check.high == 1.01e-3
    # margin = 1 x the range (1.2e-4) + floor 1e-8 x 50 = 5e-7.
    assert check.limit == pytest.approx(ENSEMBLE_WIDEN * 1.2e-4 + FLOOR_RELATIVE * 50.0)
    assert check.allows(1.02552e-3)             # the other CPU's value: inside
    assert check.allows(8.9e-4 - 1.1e-4) and not check.allows(8.9e-4 - 1.3e-4)
    assert not check.allows(2e-3)


def test_nan_passes_only_where_it_was_measured():
    stopped_in_some = classify("stop.stop_time", RIGID, 0.7, [math.nan, 0.7], 1.0)
    assert stopped_in_some.allows(math.nan)
    never = classify("stop.stop_time", RIGID, math.nan, [math.nan], 1.0)
    assert never.kind == "exact" and never.allows(math.nan) and not never.allows(0.7)
    finite = classify("error", RIGID, 1e-3, [1e-3], 1.0)
    assert not finite.allows(math.nan) and not finite.allows(math.inf)


def test_iteration_counts_get_a_floor_of_whole_iterations():
    check = classify("solver_iterations_per_step", RIGID, 1.08, [1.08, 1.08], 1.0)
    # 5 % of 1.08 plus half an iteration.
    assert check.limit == pytest.approx(0.05 * 1.08 + 0.5)
    assert check.allows(1.5) and not check.allows(2.2)


def test_figure_dimensions():
    assert figure_dimension("penetration_max") == "length"
    assert figure_dimension("penetration_relative") == "relative"
    assert figure_dimension("energy.energy_growth_relative") == "relative"
    assert figure_dimension("apex_heights.rest_time") == "time"
    assert figure_dimension("stick.creep_rate") == "velocity"
    assert figure_dimension("energy_scale") == "energy"
    assert figure_dimension("joint_angle_max") == "angle"
    assert figure_dimension("solver_iterations_per_step") == "count"
    assert figure_dimension("something_new") == "relative"


def test_check_round_trips_through_json_safe_dicts():
    check = classify("stop.stop_time", RIGID, math.nan, [math.nan], 1.0)
    data = check.to_dict()
    assert data["base"] == "nan" and Check.from_dict(data).to_dict() == data
    assert math.isnan(Check.from_dict(data).base)
    assert figure_dimension("fc1_ratio") == "relative"


def _baseline(**checks) -> dict:
    return {"results": {"reference sliding-box": {
        "status": "ok", "expectations_passed": 1, "engine_version": "clearbench 0.1.0",
        "statuses_seen": ["ok"], "expectations_seen": [1],
        "metrics": {name: check.base for name, check in checks.items()},
        "checks": {name: check.to_dict() for name, check in checks.items()}}}}


def _result(status="ok", passed=1, **metrics) -> dict:
    return {"reference sliding-box": {"status": status, "expectations_passed": passed,
                                      "message": "", "engine": "reference[default]",
                                      "engine_version": "clearbench 0.1.0",
                                      "metrics": metrics}}


def test_compare_names_the_run_the_figure_the_values_and_the_criterion():
    baseline = _baseline(
        stop_distance=classify("stop_distance", RIGID, 0.68, [0.68], 1.1),
        energy_growth=classify("energy_growth", RIGID, 1e-15, [2e-15], 1.0))
    outcome = compare(baseline, _result(stop_distance=0.6732, energy_growth=3e-15))
    assert outcome.regressions == [
        "reference sliding-box: stop_distance 0.68 -> 0.6732 (exact: tolerance 1.1e-08, "
        "measured spread 0) [engine clearbench 0.1.0 unchanged]"]
    assert outcome.compared_figures == 2
    gone = compare(baseline, _result(stop_distance=0.68, extra=1.0))
    assert gone.regressions == ["reference sliding-box: energy_growth no longer computed "
                                "[engine clearbench 0.1.0 unchanged]"]
    assert any("new metrics not in the baseline: extra" in n for n in gone.notes)


def test_compare_accepts_a_status_seen_under_a_perturbation_only():
    baseline = _baseline(x=classify("x", COMPLIANT, 1.0, [1.0], 1.0))
    entry = baseline["results"]["reference sliding-box"]
    entry["statuses_seen"] = ["diverged", "ok"]
    entry["expectations_seen"] = [0, 1]
    assert compare(baseline, _result("diverged", 0, x=1.0)).regressions == []
    lines = compare(baseline, _result("crashed", None)).regressions
    assert lines[0].startswith("reference sliding-box: status ok -> crashed")
    assert lines[1].startswith("reference sliding-box: expectations passed 1 -> None")
    assert len(lines) == 2   # no figure lines: the status says it


def test_compare_notes_skipped_runs_and_scene_changes():
    baseline = _baseline(x=classify("x", RIGID, 1.0, [1.0], 1.0))
    baseline["results"]["reference sliding-box"]["scene_hash"] = "a" * 64
    results = _result(x=1.0)
    results["reference sliding-box"]["scene_hash"] = "b" * 64
    outcome = compare(baseline, results, {"mujoco[tuned] pendulum": "mujoco not available"})
    assert outcome.regressions == []
    assert "mujoco[tuned] pendulum: not run (mujoco not available)" in outcome.notes
    assert any("scene definition changed" in note for note in outcome.notes)


def test_roundoff_perturbation_moves_every_moving_body_by_a_few_roundings_only():
    scene, _ = resolve_scene("c60-on", {"horizon": 0.2})
    perturbed = perturb_initial_state(scene, seed=3, ulps=4)
    assert perturb_initial_state(scene, seed=0) is scene   # off: the very same scene
    assert perturbed.content_hash != scene.content_hash
    assert perturb_initial_state(scene, seed=3).content_hash == perturbed.content_hash
    moved = 0
    for before, after in zip(scene.bodies, perturbed.bodies, strict=True):
        for field in ("position", "orientation", "velocity", "angular_velocity"):
            for a, b in zip(getattr(before, field), getattr(after, field), strict=True):
                # (1 + k eps) with |k| <= 4, and one rounding of the product.
                assert abs(b - a) <= 5 * EPS * abs(a)
                moved += a != b
    assert moved > 10


def test_variants_of_an_entry():
    perturbations = [
        {"name": "roundoff", "kind": "roundoff", "ulps": 4, "seeds": 2},
        {"name": "numba-generic", "kind": "environment",
         "environment": {"NUMBA_CPU_NAME": "generic"}},
        {"name": "exudyn-sparse", "kind": "options", "engines": ["exudyn"],
         "options": {"linear_solver": "EigenSparse"}}]
    names = [v.name for v in variants_for({"ensemble": 8}, "exudyn", perturbations)]
    assert names == [f"roundoff-{k}" for k in range(1, 9)] + ["numba-generic",
                                                               "exudyn-sparse"]
    assert [v.name for v in variants_for({}, "mujoco", perturbations)] == [
        "roundoff-1", "roundoff-2", "numba-generic"]


def test_a_numba_code_generation_variable_gets_its_own_cache_directory(monkeypatch):
    import clearbench

    monkeypatch.setattr(clearbench, "USER_NUMBA_CACHE_DIR", None)
    plain = clearbench.numba_cache_dir({})
    generic = worker_environment({"NUMBA_CPU_NAME": "generic"})
    optimised_off = worker_environment({"NUMBA_OPT": "0"})
    assert generic["NUMBA_CPU_NAME"] == "generic"
    caches = {str(plain), generic["NUMBA_CACHE_DIR"], optimised_off["NUMBA_CACHE_DIR"]}
    assert len(caches) == 3 and all(c.startswith(str(plain)) for c in caches)
    assert "NUMBA_CACHE_DIR" not in worker_environment({"OPENBLAS_CORETYPE": "Prescott"})
    assert worker_environment(None) == {}


def test_the_warm_up_runs_each_reference_scene_for_two_steps_with_a_long_limit():
    from clearbench.harness.studies.regress.suite import (
        WARM_UP_TIMEOUT,
        default_suite,
        warm_up_specs,
    )

    entries = {e["id"]: e for e in default_suite()}
    specs = warm_up_specs(entries)
    assert sorted(s.scene.name for s in specs) == sorted(
        ["bouncing-ball-e0.5", "incline-stick", "sliding-box", "pendulum",
         "clearance-pendulum", "c60-on"])
    assert all(s.engine.name == "reference" for s in specs)
    for spec in specs:
        # Two steps compile every kernel a step uses; the limit covers a compilation from an
        # empty cache on a loaded machine.
        assert spec.horizon == pytest.approx(2 * spec.time_step)
        assert spec.timeout == WARM_UP_TIMEOUT
