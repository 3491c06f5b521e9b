"""The engine contract, over every engine of the registry (dm_control style invariants).

For each engine of :data:`clearbench.adapters.ENGINES` that is available here and each library
scene, a run of a few steps either answers UNSUPPORTED with its reasons or returns a trajectory
of the contract (:mod:`clearbench.adapters.trajectory`): the scene's bodies and pairs, the
sampling of ``record_every``, float64 / int64 / bool arrays, times in the scene's unit, unit
quaternions and finite values for an ok run. Every engine, available or not, answers a feature
it does not know UNSUPPORTED with the same reason, and refuses an unknown preset or option
before anything runs. Every engine and preset gives the same run twice bit for bit.

Cost: about 20 s on two shared cores with numba's cache warm (a cold cache adds the reference
solver's compilation, paid once per process by whichever test steps it first), most of it the
Siconos worker processes, one per scene; the horizon is three steps (enough for a subsampled
sample and the last one).
"""

from __future__ import annotations

import importlib

import numpy as np
import pytest

from clearbench.adapters import ENGINES, engine_availability
from clearbench.adapters.base import Engine, RunSettings, Support, unknown_feature
from clearbench.adapters.recording import record_schedule
from clearbench.adapters.trajectory import RunStatus, Trajectory
from clearbench.harness.run.engine_choice import RunInputError, resolve_engine
from clearbench.scenarios.library import get_scene, scene_names
from clearbench.scenarios.scene import Scene

STEPS = 3
RECORD_EVERY = 2
FLOAT_ARRAYS = ("times", "positions", "orientations", "velocities", "angular_velocities",
                "contact_normal_force", "contact_force", "solver_residual")
INT_ARRAYS = ("solver_iterations", "active_contacts")
#: Features no engine knows: a plain one, each qualified kind, and a malformed pair.
UNKNOWN_FEATURES = ("warp_drive", "shape:torus", "joint:screw", "pair:plane-torus",
                    "pair:sphere")


def _module(name: str):
    return importlib.import_module(ENGINES[name])


def _available_module(name: str):
    availability = engine_availability(name)
    if not availability.available:
        pytest.skip(f"{name} is not available here: {availability.detail}")
    return _module(name)


@pytest.fixture(scope="module")
def scenes() -> dict[str, Scene]:
    return {name: get_scene(name) for name in scene_names()}


def test_every_registered_engine_has_the_entry_points():
    for name, subpackage in ENGINES.items():
        module = _module(name)
        assert module.__name__ == subpackage
        available, detail = module.availability()
        assert isinstance(available, bool) and isinstance(detail, str) and detail
        engine = module.create()
        assert isinstance(engine, Engine)
        assert engine.name == name and engine.preset == "default"
        assert "default" in engine.PRESETS
        for preset in engine.PRESETS:
            assert module.create(preset).label == f"{name}[{preset}]"


def _check_arrays(trajectory: Trajectory, samples: int, bodies: int, pairs: int) -> None:
    shapes = {
        "times": (samples,), "positions": (samples, bodies, 3),
        "orientations": (samples, bodies, 4), "velocities": (samples, bodies, 3),
        "angular_velocities": (samples, bodies, 3), "contact_normal_force": (samples, pairs),
        "contact_force": (samples, pairs, 3), "solver_iterations": (samples,),
        "solver_residual": (samples,), "solver_converged": (samples,),
        "active_contacts": (samples,),
    }
    for name, shape in shapes.items():
        array = getattr(trajectory, name)
        assert isinstance(array, np.ndarray) and array.shape == shape, name
    for name in FLOAT_ARRAYS:
        assert getattr(trajectory, name).dtype == np.float64, name
    for name in INT_ARRAYS:
        assert getattr(trajectory, name).dtype == np.int64, name
    assert trajectory.solver_converged.dtype == np.bool_


@pytest.mark.parametrize("scene_name", scene_names())
@pytest.mark.parametrize("engine_name", list(ENGINES))
def test_a_short_run_keeps_the_trajectory_contract(engine_name, scene_name, scenes):
    module = _available_module(engine_name)
    scene = scenes[scene_name]
    engine = module.create()
    capabilities = engine.capabilities(scene)
    assert set(capabilities) == set(scene.features)
    unsupported = [f for f, c in capabilities.items() if c.support is Support.UNSUPPORTED]
    assert all(capabilities[f].detail for f in unsupported), "an unsupported feature says why"
    h = scene.time_step
    trajectory = engine.run(scene, RunSettings(horizon=STEPS * h, record_every=RECORD_EVERY))

    assert (trajectory.engine, trajectory.preset) == (engine_name, "default")
    assert (trajectory.scene_name, trajectory.scene_hash) == (scene.name, scene.content_hash)
    assert trajectory.units == {"length": scene.units.length, "mass": scene.units.mass,
                                "time": scene.units.time}
    assert trajectory.body_names == tuple(b.name for b in scene.bodies)
    assert trajectory.contact_names == tuple(c.name for c in scene.all_contacts)
    bodies, pairs = len(scene.bodies), len(scene.all_contacts)
    if unsupported:
        assert trajectory.status is RunStatus.UNSUPPORTED
        for feature in unsupported:
            assert feature in trajectory.message
        _check_arrays(trajectory, 0, bodies, pairs)
        return
    assert trajectory.status in (RunStatus.OK, RunStatus.DIVERGED), trajectory.message
    schedule = record_schedule(STEPS, RECORD_EVERY)
    samples = len(trajectory.times)
    assert 1 <= samples <= len(schedule)
    _check_arrays(trajectory, samples, bodies, pairs)
    # Times in the scene's unit, from 0, increasing, within the horizon (a diverged run keeps
    # the offending step as its last sample).
    assert trajectory.time_step == pytest.approx(h, rel=1e-12)
    times = trajectory.times
    assert times[0] == 0.0 and (np.diff(times) > 0).all()
    assert times[-1] <= STEPS * h * (1 + 1e-9)
    if trajectory.status is RunStatus.OK:
        assert samples == len(schedule) and trajectory.steps == STEPS
        assert np.allclose(times, np.array(schedule) * h, rtol=1e-9, atol=1e-12 * h)
        for name in FLOAT_ARRAYS[:-1]:
            assert np.isfinite(getattr(trajectory, name)).all(), name
        assert not np.isinf(trajectory.solver_residual).any()
        norms = np.linalg.norm(trajectory.orientations, axis=-1)
        assert np.max(np.abs(norms - 1.0)) < 1e-12
        assert (trajectory.solver_iterations >= 0).all()
        assert (trajectory.active_contacts >= 0).all()


def _preset_labels() -> list[tuple[str, str]]:
    return [(name, preset) for name in ENGINES for preset in _module(name).create().PRESETS]


@pytest.mark.parametrize("engine_name, preset", _preset_labels())
def test_a_run_is_deterministic_bit_for_bit(engine_name, preset):
    """Every engine and preset, the same run twice: every array of the trajectory equal bit
    for bit (NaN where the engine reports no residual). The clearance pendulum (a ring in a
    bore, friction, a fixed body) for 30 steps of its 1 ms, a sample kept every 2."""
    module = _available_module(engine_name)
    scene = get_scene("clearance-pendulum")
    settings = RunSettings(horizon=30 * scene.time_step, record_every=2)
    first = module.create(preset).run(scene, settings)
    second = module.create(preset).run(scene, settings)
    assert first.status is second.status and first.message == second.message
    assert first.steps == second.steps
    for name in Trajectory.ARRAYS:
        a, b = getattr(first, name), getattr(second, name)
        assert np.array_equal(a, b, equal_nan=a.dtype.kind == "f"), name


@pytest.mark.parametrize("engine_name", list(ENGINES))
def test_an_unknown_feature_is_unsupported_with_one_reason_everywhere(engine_name,
                                                                      monkeypatch):
    scene = get_scene("pendulum")
    features = scene.features | set(UNKNOWN_FEATURES)
    monkeypatch.setattr(Scene, "features", property(lambda self: features))
    engine = _module(engine_name).create()
    capabilities = engine.capabilities(scene)
    for feature in UNKNOWN_FEATURES:
        assert capabilities[feature] == unknown_feature(engine_name, feature)
    # The run is answered without starting anything (no worker, no model).
    monkeypatch.setattr(type(engine), "_run", _must_not_run)
    trajectory = engine.run(scene, RunSettings(horizon=scene.time_step))
    assert trajectory.status is RunStatus.UNSUPPORTED
    assert all(feature in trajectory.message for feature in UNKNOWN_FEATURES)


def _must_not_run(self, scene, settings):
    raise AssertionError("the engine ran")


@pytest.mark.parametrize("engine_name", list(ENGINES))
def test_unknown_presets_and_options_are_refused_before_any_run(engine_name, monkeypatch):
    module = _module(engine_name)
    with pytest.raises(ValueError, match=f"unknown {engine_name} preset 'no-such-preset'"):
        module.create("no-such-preset")
    engine = module.create()
    monkeypatch.setattr(type(engine), "_run", _must_not_run)
    scene = get_scene("pendulum")
    bad = RunSettings(horizon=scene.time_step, options={"no_such_option": 1})
    with pytest.raises(ValueError, match=f"no_such_option.*unknown {engine_name} option"):
        engine.run(scene, bad)
    with pytest.raises(ValueError, match="no_such_option"):
        engine.capabilities(scene, bad.options)


@pytest.mark.parametrize("engine_name", list(ENGINES))
def test_the_harness_refuses_them_through_the_engine(engine_name):
    _available_module(engine_name)
    with pytest.raises(RunInputError) as caught:
        resolve_engine(f"{engine_name}[no-such-preset]")
    assert caught.value.field == "engine preset" and "no-such-preset" in str(caught.value)
    with pytest.raises(RunInputError) as caught:
        resolve_engine(engine_name, options={"no_such_option": 1})
    # The field names the engine and the option (adapters/options.py's OptionError).
    assert caught.value.field == f"{engine_name} option no_such_option"
