"""Invariants over the whole registry of expectation kinds: every kind a scene may write is
measured and judged, every kind is complete (parameters with dimension and domain, figures
with units, a criterion in words), every kind is exercised by a library scene, and the docs'
copies of the kinds' tables are the registry's."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import pytest

from clearbench.adapters.base import RunSettings
from clearbench.harness.measure.figures import measure
from clearbench.harness.measure.kinds import KINDS, unmeasured_declarations
from clearbench.harness.measure.units import figure_unit
from clearbench.harness.measure.verdicts import analytic_error, criteria_table
from clearbench.scenarios.expectation_kinds import (
    EXPECTATION_KINDS,
    OUTPUT_DIMENSION,
    Domain,
    energy_may_not_grow,
    parameters_table,
)
from clearbench.scenarios.library import get_entry, get_scene, scene_names
from clearbench.scenarios.tags import C60

from .fake_engine import create as fake_engine

DOCS = Path(__file__).resolve().parent.parent / "docs"
#: Library scenes measured here (the C-60's kinds, sticks and no_penetration, are used by
#: other scenes too; building and stepping it costs seconds).
SCENES = [name for name in scene_names() if C60 not in get_entry(name).tags]
WITHOUT_ENERGY = "bouncing-ball-e0.5 without its energy expectation"
SCENES.append(WITHOUT_ENERGY)


def test_every_kind_a_scene_may_write_is_measured_and_judged():
    assert unmeasured_declarations() == []
    for name, kind in KINDS.items():
        if kind.implied:
            assert name not in EXPECTATION_KINDS, f"implied {name} is not for scenes to write"
        else:
            assert EXPECTATION_KINDS[name] is kind.declaration


@pytest.mark.parametrize("name", list(EXPECTATION_KINDS))
def test_every_parameter_has_a_dimension_and_a_domain(name):
    kind = EXPECTATION_KINDS[name]
    assert kind.statement
    for key, parameter in kind.parameters.items():
        assert parameter.dimension == OUTPUT_DIMENSION or (
            len(parameter.dimension) == 3 and all(isinstance(p, int)
                                                  for p in parameter.dimension)), key
        assert isinstance(parameter.domain, Domain), key


def _library_scene(name: str):
    if name == WITHOUT_ENERGY:  # a scene that lists no energy expectation: the implied check
        scene = get_scene("bouncing-ball-e0.5")
        return dataclasses.replace(scene, expectations=tuple(
            e for e in scene.expectations if not energy_may_not_grow(e.kind)))
    return get_scene(name)


@pytest.fixture(scope="module")
def library_measurements():
    """Every non-C-60 library scene in free flight (the fake engine, contacts and joints
    ignored, clearance joints too: its ``_run``): each kind's handler and criterion on real
    scenes, whatever its figures say about the engine; 0.5 s at most of each, a few seconds
    in all."""
    measured = {}
    for name in SCENES:
        scene = _library_scene(name)
        settings = RunSettings(horizon=min(scene.horizon, 0.5))
        measured[name] = (scene, measure(scene, fake_engine()._run(scene, settings)))
    return measured


def test_every_kind_is_exercised_by_a_library_scene(library_measurements):
    used = {result["kind"] for _, m in library_measurements.values() for result in
            m.expectations}
    assert set(KINDS) <= used


@pytest.mark.parametrize("name", SCENES)
def test_every_figure_has_a_unit_and_every_result_a_criterion(name, library_measurements):
    scene, measurement = library_measurements[name]
    assert not measurement.metrics_error, measurement.metrics_error
    for result in measurement.expectations:
        kind = KINDS[result["kind"]]
        assert result["criterion"] and result["detail"], result
        assert result["passed"] in (True, False, None)
        assert result["headline"] in result["figures"] or not result["figures"] or \
            kind.unit_of(result["headline"]) is not None
        for figure in result["figures"]:
            assert figure_unit(f"{result['name']}.{figure}", scene) is not None, \
                (result["kind"], figure)
        if kind.analytic_error:
            named = {f for f, _ in kind.analytic_error}
            if named & set(result["figures"]):
                assert math.isfinite(analytic_error(kind.name, result["figures"]))


def test_the_docs_show_the_criteria_as_the_registry_has_them():
    # docs/harness.md carries the criteria as criteria_table() writes them from the kinds: a
    # criterion changed in the code without its words in the docs fails here.
    assert criteria_table() in (DOCS / "harness.md").read_text()
    assert {"bounce_apex", "no_penetration", "output_value", "energy_balance"} <= set(KINDS)


def test_the_docs_show_the_parameters_as_the_registry_has_them():
    assert parameters_table() in (DOCS / "scene-format.md").read_text()
