"""What the engines declare to the harness (``HARNESS_DEFAULTS``,
:mod:`clearbench.adapters.harness_defaults`) and what the harness derives from it: the quick
suite of a new baseline is the committed one, run for run; the tolerance classes, the option
perturbations and the C-60 plans come from the declarations; bad declarations are refused
naming the engine and the field."""

from __future__ import annotations

import json
import subprocess
import sys
import types

import pytest

from clearbench.adapters import ENGINES, engine_availability
from clearbench.adapters.harness_defaults import HarnessDefaults, QuickRun
from clearbench.harness.run.engine_choice import RunInputError, engine_defaults, resolve_engine
from clearbench.harness.studies.c60_comparison import c60_plan, plan_engines
from clearbench.harness.studies.regress.baseline import DEFAULT_BASELINE, tolerance_model
from clearbench.harness.studies.regress.perturbations import default_perturbations
from clearbench.harness.studies.regress.suite import (
    EngineSelection,
    default_suite,
    suite_specs,
    with_declared_runs,
)

from .harness_helpers import ROOT


def _committed() -> dict:
    return json.loads((ROOT / DEFAULT_BASELINE).read_text())


def _committed_engines() -> list[str]:
    """The engines with runs in the committed baseline (an engine registered since gets its
    runs with ``clearbench regress --update -e NAME``)."""
    return list(dict.fromkeys(e["engine"].split("[")[0] for e in _committed()["suite"]))


def test_the_declared_quick_runs_are_the_committed_baselines_suite():
    """Same ids, and for the engines available here the same runs (one run key: scene
    content, engine, preset and settings), so the committed baseline stays the suite's."""
    committed = {"suite": _committed()["suite"]}
    derived = {"suite": default_suite(_committed_engines())}
    assert sorted(e["id"] for e in derived["suite"]) == sorted(e["id"] for e in
                                                                 committed["suite"])
    skipped: dict = {}
    ours, theirs = suite_specs(derived, skipped=skipped), suite_specs(committed, skipped={})
    assert set(ours) == set(theirs) and len(ours) + len(skipped) == len(committed["suite"])
    assert {ident: spec.key for ident, spec in ours.items()} == \
        {ident: spec.key for ident, spec in theirs.items()}


def test_the_committed_tolerance_model_and_perturbations_follow_the_declarations():
    committed = _committed()
    rigid = [name for name in tolerance_model()["rigid_engines"] if name in _committed_engines()]
    assert rigid == committed["tolerance_model"]["rigid_engines"]
    derived = {p["name"]: p for p in default_perturbations(_committed_engines())}
    for perturbation in committed["perturbations"]:
        assert derived[perturbation["name"]] == perturbation
    assert derived["exudyn-sparse"]["engines"] == ["exudyn"]


def test_every_declared_preset_is_one_of_the_engines_presets():
    for name in ENGINES:
        if not engine_availability(name).available:
            continue
        declared = engine_defaults(name)
        presets = {declared.regress_preset} | {run.preset for run in declared.regress_runs
                                               if run.preset}
        presets |= {preset for scenes in declared.c60_ladders.values()
                    for ladder in scenes.values() for preset in ladder}
        for preset in presets:
            resolve_engine(f"{name}[{preset}]")   # RunInputError for a preset it lacks


def test_reading_the_declarations_imports_no_engine():
    code = ("import sys\n"
            "from clearbench.harness.run.engine_choice import engine_defaults, engine_names\n"
            "[engine_defaults(name) for name in engine_names()]\n"
            "print([m for m in sys.modules if m.split('.')[0] in "
            "('mujoco', 'pybullet', 'exudyn', 'numba') or m.endswith('.engine')])\n")
    printed = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                             check=True).stdout
    assert printed.strip() == "[]"


def _plugged(monkeypatch, name: str, defaults: HarnessDefaults) -> dict:
    """An engine module holding only ``defaults``, importable as ``name``."""
    module = types.ModuleType(name)
    module.HARNESS_DEFAULTS = defaults
    monkeypatch.setitem(sys.modules, name, module)
    return {"plugged": name}


def test_a_plan_holds_what_a_plugged_engine_declares_and_refuses_an_unknown_scene(
        monkeypatch):
    modules = _plugged(monkeypatch, "plugged_engine",
                       HarnessDefaults(c60_ladders={"full": {"c60-trip": {"fast": (2e-3,)}}}))
    assert c60_plan("full", modules).ladders["c60-trip"]["plugged[fast]"] == (2e-3,)
    assert "plugged[fast]" not in c60_plan("full", modules).ladders["c60-on"]
    modules = _plugged(monkeypatch, "plugged_engine",
                       HarnessDefaults(c60_ladders={"demo": {"c60-of": {"default": (1e-3,)}}}))
    with pytest.raises(RunInputError, match="plugged HARNESS_DEFAULTS.c60_ladders"):
        c60_plan("demo", modules)


def test_a_label_without_a_ladder_in_the_plan_is_left_out_with_the_reason():
    chosen, left_out = plan_engines(c60_plan("demo"), ["reference", "reference[no-projection]"])
    assert [c.label for c in chosen] == ["reference[default]"]
    assert "no ladder in the demo plan" in left_out["reference[no-projection]"]


def test_bad_declarations_are_refused_naming_the_field():
    with pytest.raises(ValueError, match="colour = 'red'"):
        HarnessDefaults(colour="red")
    with pytest.raises(ValueError, match="c60_step_cost = 0"):
        HarnessDefaults(c60_step_cost=0)
    with pytest.raises(ValueError, match=r"c60_ladders\['demo'\]\['c60-on'\]\['default'\]"):
        HarnessDefaults(c60_ladders={"demo": {"c60-on": {"default": (0.0,)}}})
    with pytest.raises(ValueError, match="horizon = -1"):
        QuickRun("pendulum", horizon=-1.0)


def test_engine_selection_and_declared_runs_of_a_baseline():
    mujoco = EngineSelection.parse(["mujoco"])
    assert mujoco.takes({"engine": "mujoco[tuned]"}) and not mujoco.takes({"engine": "exudyn"})
    assert not EngineSelection.parse(["mujoco[default]"]).takes({"engine": "mujoco[tuned]"})
    assert EngineSelection.parse(["reference[default]"]).takes({"engine": "reference"})
    with pytest.raises(RunInputError, match="unknown engine"):
        EngineSelection.parse(["nosuch"])
    baseline = {"suite": [{"id": "p", "scene": "pendulum", "engine": "reference"}]}
    same, added = with_declared_runs(baseline, ["reference"])
    assert same is baseline and added == []
    grown, added = with_declared_runs(baseline, ["siconos"])
    assert added == ["siconos"]
    assert grown["suite"][1:] == engine_defaults("siconos").regress_entries("siconos")
