"""The C-60 identification study's bookkeeping (no stepping): which section a variant's figures
match, the table, the stored-only mode, the command's input checks, and the rigid-body bound
on FC-2..FC-5."""

from __future__ import annotations

import math

import numpy as np
import pytest

from clearbench.harness.c60 import analysis, identification
from clearbench.harness.c60.identification import Candidate, Identification, VariantFigures
from clearbench.harness.c60.runs import StudyRuns
from clearbench.harness.cli.main import main
from clearbench.harness.run.store import ResultsStore
from clearbench.scenarios.c60 import model, variants

PAPER = model.load_model()["paper"]


def figures_at_the_paper(variant: str = "source") -> VariantFigures:
    """A variant whose every figure is the paper's simulated one (its Monte Carlo means)."""
    fcs = PAPER["functional_conditions"]
    experiments = PAPER["experiments"]
    return VariantFigures(
        Candidate(variant, "test"), variants.model_parameters(variant).label(),
        fc_mean={fc: fcs[fc.replace("-", "")]["mean"] for fc in identification.FCS},
        fc1_prototype=experiments["contact_force_at_equilibrium_N"]["simulated"],
        trip_peak=experiments["trip_test_peak_force_N"]["simulated"],
        trip_peak_at=experiments["trip_test_peak_at_mm"],
        trip_distance=experiments["trip_test_total_distance_mm"]["simulated"])


def test_the_study_names_only_known_variants_and_runs_the_source():
    names = [c.variant for c in identification.CANDIDATES]
    assert set(names) <= set(variants.VARIANTS) and len(set(names)) == len(names)
    assert names[0] == "source"
    assert {"latch-0.1", "paper-table-4"} <= {c.variant for c in identification.CANDIDATES
                                              if c.trip_test}


def test_the_papers_own_figures_match_every_section():
    assert identification.section_matches(figures_at_the_paper()) == {
        "4.2": "yes", "5.2": "yes", "5.3": "yes"}


def test_misses_say_which_figure_and_by_how_much():
    figures = figures_at_the_paper()
    sigma = PAPER["functional_conditions"]["FC3"]["sigma"]
    figures.fc_mean["FC-3"] -= 2.5 * sigma          # beyond the 2 sigma of a match
    figures.fc1_prototype *= 0.5                      # -50 %, beyond 6 %
    figures.trip_distance += 0.05                     # beyond 0.03 mm
    matches = identification.section_matches(figures)
    assert matches["4.2"] == "no: FC-3 -2.5 sigma"
    assert matches["5.2"] == "no: FC-1 -50 %"
    assert matches["5.3"] == "no: trip distance +0.050 mm"
    empty = VariantFigures(Candidate("source", "test"), "the source's model")
    assert identification.section_matches(empty) == {"4.2": "-", "5.2": "-", "5.3": "-"}


def test_the_table_has_the_paper_row_then_one_row_per_variant():
    study = Identification(figures=[figures_at_the_paper("source"),
                                    figures_at_the_paper("latch-0.1")])
    lines = identification.table_lines(study)
    columns = lines[0].count("|")
    assert all(line.count("|") == columns for line in lines)
    assert lines[2].startswith("| **paper**")
    assert "`latch-0.1` (friction C4 0.1)" in lines[4] and "yes / yes / yes" in lines[4]


def test_stored_only_runs_nothing_and_lists_what_is_missing(tmp_path):
    runs = StudyRuns(ResultsStore(tmp_path / "store"), run_missing=False)
    study = identification.identify(runs, candidates=identification.candidates("latch-0.1"))
    assert study.runs == {} and runs.made == [] and len(runs.store) == 0
    assert study.missing == ["identify_on_mean_latch-0.1", "identify_on_prototype_latch-0.1",
                             "identify_trip_test_latch-0.1"]
    assert math.isnan(study.figures[0].fc1_prototype)
    identification.write_markdown(study, tmp_path / "t.md", "default", 4.0)
    assert "Runs not made" in (tmp_path / "t.md").read_text()


def test_an_unknown_variant_is_refused_before_any_run(tmp_path, capsys):
    assert main(["c60", "identify", "--variants", "source,paper", "--store",
                 str(tmp_path)]) == 2
    assert "paper" in capsys.readouterr().err
    assert not (tmp_path / "runs.sqlite").exists()


def test_pin_and_lamage_are_closer_on_the_bar_than_the_papers_means_allow():
    ours, height, paper = analysis.pin_lamage_distance()
    # CAD: 0.570 mm in xy and 5.75 mm along z between the middles of the two axes of the
    # rigid tripping bar; the paper's means (FC-2, FC-3) and (FC-4, FC-5): 1.627 mm apart.
    # All three to 1e-3 mm (the CAD's extraction residual is 1.2e-4 mm).
    assert ours == pytest.approx(0.570, abs=1e-3)
    assert height == pytest.approx(5.75, abs=1e-3)
    assert paper == pytest.approx(1.627, abs=1e-3)
    # 1.627 mm would need the bar tilted asin(1.057 / 5.75) = 10.6 deg out of its plane.
    assert "10.6 deg" in analysis.pin_lamage_cause()


def test_tilt_is_the_angle_of_the_body_z_axis_from_world_z():
    half = math.radians(3.0) / 2
    about_x = [math.cos(half), math.sin(half), 0.0, 0.0]
    about_z = [math.cos(half), 0.0, 0.0, math.sin(half)]
    # Exact up to the round-off of cos/arccos near 3 degrees (1e-12 rad).
    assert analysis.tilt(np.array(about_x)) == pytest.approx(math.radians(3.0), abs=1e-12)
    assert analysis.tilt(np.array(about_z)) == pytest.approx(0.0, abs=1e-7)


def test_a_variant_whose_mechanism_opened_matches_no_section_and_is_listed():
    figures = figures_at_the_paper("latch-0.1")
    figures.fc_mean["FC-1"] = 0.0      # C7 unloaded over the last millisecond
    figures.opened = True
    matches = identification.section_matches(figures)
    assert matches["4.2"] == f"no: {identification.OPENED}"
    assert matches["5.2"] == "yes"     # the prototype's run stayed ON
    lines = identification.opened_lines(Identification(figures=[figures]))
    assert len(lines) == 1 and "`latch-0.1`" in lines[0]
    assert "with the prototype's clearances it stayed ON" in lines[0]


def test_fc6_is_the_bar_to_plunger_gap_of_table_1():
    geometry = analysis.magnetic_gap_geometry()
    # The plunger's face and the case plane are both at x = -5 mm in the CAD's ON pose (the
    # CAD's coordinates are exact to 1e-6 mm), so the source's pair measures the paper's
    # "distance between tripping bar and plunger in X"; its value in that pose is 0.389 mm
    # (to the 1e-3 mm of a length read from the B-spline CAD, residual 1.2e-4 mm).
    assert geometry.plunger_in_case_plane
    assert geometry.case_plane_x == pytest.approx(-5.0, abs=1e-6)
    assert geometry.cad_value == pytest.approx(0.389, abs=1e-3)


def test_the_fc6_paragraph_names_the_closest_variant_and_says_when_none_matches():
    source, latch = figures_at_the_paper("source"), figures_at_the_paper("latch-0.1")
    sigma = PAPER["functional_conditions"]["FC6"]["sigma"]
    source.fc_mean["FC-6"] += 7.0 * sigma
    latch.fc_mean["FC-6"] += 5.0 * sigma
    text = identification.magnetic_gap_cause(Identification(figures=[source, latch]))
    assert "closest variant is latch-0.1" in text and "+5.0 sigma" in text
    assert "no variant of the study puts FC-6 within 2 sigma" in text
    latch.fc_mean["FC-6"] -= 4.0 * sigma
    text = identification.magnetic_gap_cause(Identification(figures=[source, latch]))
    assert "latch-0.1 puts FC-6 within 2 sigma" in text


def test_the_running_median_drops_a_one_sample_spike_at_either_end():
    # The probe's first touch is an impact: one recorded sample of several newtons before the
    # quasi-static load (the preload-0.9599 trip test: 5.2 N, then 0.36 N). A width-5 median
    # must give the neighbours' values there, exactly (a median picks a sample).
    values = np.array([5.2, 0.0, 0.0, 0.36, 0.37, 0.38, 0.0, 9.0])
    smooth = analysis.running_median(values, 5)
    assert smooth[0] == 0.0 and smooth[-1] == 0.38
    assert smooth.max() == 0.38
    assert analysis.running_median(np.array([1.0]), 5).tolist() == [1.0]
