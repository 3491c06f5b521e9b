"""Engine options are checked against their declarations (adapters/options.py) when the run spec
is made: a value of the wrong type, out of range or not among the choices exits with status 2
naming the engine, the option, the value and what is allowed, before any engine runs and
before anything is stored; a crashed run is run again rather than served from the store."""

from __future__ import annotations

import importlib
import math

import pytest

from clearbench.adapters import ENGINES, engine_availability
from clearbench.adapters.options import OptionError, OptionSpec
from clearbench.harness.cli.main import main
from clearbench.harness.run.engine_choice import RunInputError
from clearbench.harness.run.runner import Runner
from clearbench.harness.run.spec import make_run_spec, parse_assignment
from clearbench.harness.run.store import ResultsStore

from .harness_helpers import FAKE


def _engine(name: str, preset: str = "default"):
    return importlib.import_module(ENGINES[name]).create(preset)


def _invalid_values(spec: OptionSpec) -> list:
    """Values the declaration must refuse: each bound crossed (an open bound is itself out),
    a wrong type, a value outside the choices, a sequence of the wrong length."""
    if spec.kind == "boolean":
        return ["maybe", 1]
    if spec.kind == "choice":
        return ["no-such-choice", 99]
    if spec.kind == "numbers":
        return [(1.0,) * (spec.length + 1), (math.nan,) * spec.length, "1 2"]
    out = ["text", math.nan, math.inf, True]
    if spec.kind == "integer":
        out.append(2.5)
    if spec.above is not None:
        out.append(spec.above)
    if spec.at_least is not None:
        out.append(spec.at_least - 1)
    if spec.below is not None:
        out.append(spec.below)
    if spec.at_most is not None:
        out.append(spec.at_most + 1)
    return out


DECLARED = [(engine, spec) for engine in ENGINES
            for spec in _engine(engine).OPTIONS.specs.values()]


@pytest.mark.parametrize("engine, spec", DECLARED,
                         ids=[f"{engine}-{spec.name}" for engine, spec in DECLARED])
def test_every_declared_option_refuses_what_it_does_not_allow(engine, spec):
    checked = _engine(engine)
    for value in _invalid_values(spec):
        with pytest.raises(OptionError) as caught:
            checked.check_options({spec.name: value})
        assert (caught.value.engine, caught.value.name) == (engine, spec.name)
        assert spec.allowed() in str(caught.value)
    if engine_availability(engine).available:  # the same refusal as an input error of a run
        with pytest.raises(RunInputError) as caught:
            make_run_spec("pendulum", engine, options={spec.name: _invalid_values(spec)[0]})
        assert caught.value.field == f"{engine} option {spec.name}"


@pytest.mark.parametrize("engine", list(ENGINES))
def test_every_preset_satisfies_the_declarations(engine):
    module = importlib.import_module(ENGINES[engine])
    for preset in _engine(engine).PRESETS:
        checked = module.create(preset)
        values = {k: v for k, v in checked.PRESETS[preset].items() if k in checked.OPTIONS.names}
        checked.check_options(values)  # raises on a preset value its declaration refuses
    assert set(checked.OPTIONS.names) >= set().union(
        *(set(values) for values in checked.PRESETS.values()))


def test_settings_dataclasses_declare_every_field():
    """The engines whose settings are a dataclass declare each field, and nothing else."""
    import dataclasses

    from clearbench.adapters.drake.settings import OPTIONS as DRAKE
    from clearbench.adapters.drake.settings import DrakeSettings
    from clearbench.adapters.exudyn.settings import OPTIONS as EXUDYN
    from clearbench.adapters.exudyn.settings import ExudynSettings
    from clearbench.adapters.mujoco.settings import OPTIONS as MUJOCO
    from clearbench.adapters.mujoco.settings import MujocoSettings
    from clearbench.adapters.pybullet.settings import OPTIONS as PYBULLET
    from clearbench.adapters.pybullet.settings import PybulletSettings

    # Fields inherited from a shared settings class (PieceSettings) come first in the
    # dataclass and where they belong in the table: the same names, each once. Drake's
    # internal_units is a constant of its model (SI), a field but not an option.
    for table, settings in ((MUJOCO, MujocoSettings), (EXUDYN, ExudynSettings),
                            (PYBULLET, PybulletSettings), (DRAKE, DrakeSettings)):
        fields = [f.name for f in dataclasses.fields(settings)
                  if f.name != "internal_units" or "internal_units" in table.names]
        assert len(set(table.names)) == len(table.names)
        assert set(table.names) == set(fields)


# The examples: each became a "crashed" run, exit 1, cached in the store.
EXAMPLES = [
    ("mujoco", "iterations=-5", "mujoco option iterations=-5: must be an integer >= 1"),
    ("mujoco", "cone=round", "mujoco option cone='round': must be one of 'pyramidal', "
                             "'elliptic'"),
    ("exudyn", "contact_period_steps=-1",
     "exudyn option contact_period_steps=-1: must be a finite number > 0"),
    ("pybullet", "num_solver_iterations=-1",
     "pybullet option num_solver_iterations=-1: must be an integer >= 1"),
    ("reference", "tolerance=-1", "reference option tolerance=-1: must be a finite number > 0"),
    ("siconos[default]", "tolerance=-1",
     "siconos option tolerance=-1: must be a finite number > 0"),
]


@pytest.mark.parametrize("engine, option, message", EXAMPLES)
def test_bad_option_values_exit_2_before_any_run_and_store_nothing(engine, option, message,
                                                                   tmp_path, capsys):
    name = engine.split("[")[0]
    with pytest.raises(OptionError) as caught:
        _engine(name).check_options(dict([parse_assignment(option, "--option")]))
    assert str(caught.value) == message
    if not engine_availability(name).available:
        pytest.skip(f"{name} not available here: the CLI refuses it as unavailable")
    store = tmp_path / "store"
    status = main(["run", "pendulum", "-e", engine, "--option", option, "--store", str(store)])
    assert status == 2
    named, allowed = message.split(": ", 1)
    assert f"{named.replace('=', ' = ', 1)}: {allowed}" in capsys.readouterr().err
    assert not store.exists()  # nothing from an invalid request is stored


def test_options_that_do_not_go_together_are_refused_before_any_run():
    with pytest.raises(OptionError, match="localise_impacts.*needs projection"):
        _engine("reference").check_options({"projection": False, "localise_impacts": True})
    _engine("reference").check_options({"projection": False})  # the preset's own is switched off


def test_a_valid_option_still_runs(tmp_path, capsys):
    status = main(["run", "pendulum", "-e", "mujoco", "--option", "iterations=50",
                   "--option", "cone=elliptic", "--horizon", "0.02",
                   "--store", str(tmp_path / "store")])
    out = capsys.readouterr().out
    assert status == 0, out
    assert "pass" in out or "no check" in out


def test_a_crashed_run_is_run_again_and_a_finished_one_is_served(tmp_path):
    store = ResultsStore(tmp_path / "store")
    crashing = make_run_spec("torque-free-flip", "fake[raise]", horizon=0.1,
                             extra_engine_modules=FAKE)
    finishing = make_run_spec("torque-free-flip", "fake", horizon=0.1,
                              extra_engine_modules=FAKE)
    Runner(store, jobs=1).run_all([crashing, finishing])
    assert store.get(crashing.key)["status"] == "crashed"
    again = Runner(store, jobs=1).run_all([crashing, finishing])
    assert again.ran == [crashing.key] and again.skipped == [finishing.key]
    assert len(store) == 2  # the crash's record replaced, not duplicated
