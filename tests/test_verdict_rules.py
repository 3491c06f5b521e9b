"""The verdict rules a scene writer cannot switch off by leaving something out: energy lost
where the scene's content says it is conserved (the implied ``energy_conservation`` check),
expectation parameters outside their meaning (refused before any engine runs, exit 2 naming
the field and value), and a run the engine called ok but the harness judges broken (the
verdict says both)."""

from __future__ import annotations

import dataclasses
import math

import pytest

from clearbench.adapters.base import RunSettings
from clearbench.harness.cli.main import main
from clearbench.harness.measure.figures import measure
from clearbench.harness.measure.kinds.invariants import ENERGY_GROWTH_ALLOWANCE
from clearbench.scenarios.contacts import ContactPair
from clearbench.scenarios.energy import dissipative_elements
from clearbench.scenarios.expectation_kinds import EXPECTATION_KINDS, Domain
from clearbench.scenarios.expectations import Expectation
from clearbench.scenarios.library import get_scene, scene_names
from clearbench.scenarios.loads import LinearSpringDamper
from clearbench.scenarios.serialization import scene_to_dict
from clearbench.scenarios.toml_format import dumps as toml_dumps
from clearbench.scenarios.validation import SceneError

from .fake_engine import create as fake_engine
from .verdict_scenes import elastic_row, elastic_row_in_space


# ---------------------------------------------------------------- energy conserved by content
def test_a_scene_conserves_energy_only_when_nothing_in_it_can_take_energy():
    assert dissipative_elements(elastic_row_in_space()) == ()
    assert dissipative_elements(get_scene("pendulum")) == ()  # an ideal joint takes nothing
    # The row on a floor with e = 0: the floor could take energy at any floor impact.
    assert dissipative_elements(elastic_row()) == tuple(
        f"contact floor_ball{i}: restitution 0" for i in range(3))
    row = elastic_row_in_space()
    rough = dataclasses.replace(row, contacts=(
        dataclasses.replace(row.contacts[0], friction=0.1), *row.contacts[1:]))
    assert dissipative_elements(rough) == ("contact ball0_ball1: friction 0.1",)
    damped = dataclasses.replace(row, loads=(LinearSpringDamper(
        "tie", body_a="ball0", body_b="ball2", stiffness=1.0, damping=0.5),))
    assert dissipative_elements(damped) == ("spring tie: damping 0.5",)
    clearance = get_scene("clearance-pendulum")  # mu 0.1, e = 0 on its generated contacts
    assert all(name.startswith("contact pivot.") for name in dissipative_elements(clearance))


def _free_flight(scene, factor_after: float | None = None):
    """The fake engine's free flight of ``scene`` (contacts ignored), the velocities scaled by
    ``factor_after`` from the middle sample on (energy taken from a scene that conserves it)."""
    trajectory = fake_engine()._run(scene, RunSettings())
    if factor_after is not None:
        half = len(trajectory.times) // 2
        trajectory.velocities[half:] *= factor_after
    return trajectory


def _result(measurement, name: str):
    return next((r for r in measurement.expectations if r["name"] == name), None)


def test_energy_lost_where_the_scene_conserves_it_fails_with_a_named_reason():
    scene = elastic_row_in_space()
    # The first ball, alone moving, keeps its speed: nothing lost, the check passes.
    kept = _result(measure(scene, _free_flight(scene)), "energy_conservation")
    assert kept["passed"] is True, kept
    # Its speed / 3 from the middle on: 8/9 of the kinetic energy (the scale) lost.
    lost = _result(measure(scene, _free_flight(scene, 1.0 / 3.0)), "energy_conservation")
    assert lost["passed"] is False
    assert lost["figures"]["energy_loss_relative"] == pytest.approx(8.0 / 9.0, rel=1e-9)
    assert lost["detail"].startswith("energy lost where the scene conserves it 88.9 % > 1 %")
    assert "every contact elastic and frictionless" in lost["criterion"]


def test_the_conservation_check_is_implied_only_where_nothing_takes_energy():
    # A scene whose floor contacts have e = 0 loses no check: its energy may fall.
    row = elastic_row()
    assert _result(measure(row, _free_flight(row, 0.5)), "energy_conservation") is None
    # A scene that states energy_conserved is judged by it (both ways), not twice.
    scene = dataclasses.replace(elastic_row_in_space(), expectations=(
        Expectation("energy", kind="energy_conserved"),))
    measured = measure(scene, _free_flight(scene, 0.5))
    assert _result(measured, "energy_conservation") is None
    assert _result(measured, "energy")["passed"] is False


def test_the_bound_separates_the_reference_from_a_plastic_row():
    # The reference's Moreau-Jean impacts with e = 1 lose nothing but round-off on the row
    # (measured: 2.4e-12 of the energy scale); the bound is ENERGY_GROWTH_ALLOWANCE, the
    # compliant engines' contact-energy error, far above it.
    from clearbench.adapters import reference
    scene = elastic_row_in_space()
    check = _result(measure(scene, reference.create().run(scene, RunSettings())),
                    "energy_conservation")
    assert check["passed"] is True
    # Round-off: 1e-9 is 400 times the measured loss and 1e7 times below the bound.
    assert check["figures"]["energy_loss_relative"] < 1e-9 < ENERGY_GROWTH_ALLOWANCE


# ---------------------------------------------------------------- parameters against meaning
def _library_parameters() -> dict[str, dict]:
    """One valid set of parameters of every kind that takes any, from the library."""
    found = {}
    for name in scene_names():
        if name.startswith("c60"):
            continue
        for expectation in get_scene(name).expectations:
            if expectation.parameters and expectation.kind not in found:
                found[expectation.kind] = (dict(expectation.parameters), expectation)
    return found


def _outside(domain: Domain) -> list[float]:
    """Values just outside ``domain``'s bounds (and 0 when it is excluded)."""
    values = []
    if math.isfinite(domain.low):
        values.append(domain.low if domain.low_open else domain.low - 1.0 - abs(domain.low))
    if math.isfinite(domain.high):
        values.append(domain.high if domain.high_open else domain.high + 1.0 + abs(domain.high))
    if domain.nonzero:
        values.append(0.0)
    return values


LIBRARY_PARAMETERS = _library_parameters()


@pytest.mark.parametrize("kind", sorted(k for k, v in EXPECTATION_KINDS.items() if v.parameters))
def test_every_parameter_outside_its_domain_is_refused_naming_it(kind):
    assert kind in LIBRARY_PARAMETERS, f"no library scene uses {kind}"
    valid, expectation = LIBRARY_PARAMETERS[kind]
    refused = 0
    for key, parameter in EXPECTATION_KINDS[kind].parameters.items():
        for value in [*_outside(parameter.domain), math.nan]:
            with pytest.raises(SceneError) as error:
                dataclasses.replace(expectation, parameters={**valid, key: value})
            assert f"parameters.{key}" in str(error.value), (key, value, str(error.value))
            refused += 1
    assert refused >= len(EXPECTATION_KINDS[kind].parameters)


@pytest.mark.parametrize("kind, changes, field", [
    ("incline_stick", {"angle": 0.5, "friction": 0.3}, "angle"),      # tan 0.5 = 0.55 > 0.3
    ("incline_slide", {"angle": 0.1, "friction": 0.3}, "angle"),      # tan 0.1 = 0.10 < 0.3
    ("sticks", {"start_time": 2.0, "end_time": 1.0}, "end_time"),
    ("sticks", {"start_time": 1.0, "end_time": 1.0}, "end_time"),
    ("pendulum", {"pivot_inertia": 0.5}, "pivot_inertia"),            # < m d^2 = 1
    ("slider_crank", {"rod_length": 0.09}, "rod_length"),             # < crank 0.1 + 0
    ("rocking_ratio", {"half_width": 0.3, "half_height": 0.1}, "half_width"),
    ("output_value", {"absolute_tolerance": 0.0}, "absolute_tolerance"),
])
def test_parameters_that_contradict_each_other_are_refused(kind, changes, field):
    valid, expectation = LIBRARY_PARAMETERS[kind]
    with pytest.raises(SceneError, match=rf"parameters\.{field} = "):
        dataclasses.replace(expectation, parameters={**valid, **changes})


def test_parameters_that_contradict_the_scene_are_refused():
    scene = get_scene("sliding-box")
    stop = scene.expectations[0]
    with pytest.raises(SceneError, match=r"expectations\['stop'\]\.parameters\.gravity = 9\.8:"):
        dataclasses.replace(scene, expectations=(
            dataclasses.replace(stop, parameters={**stop.parameters, "gravity": 9.8}),))
    tunnel = get_scene("stiff-tunnelling")
    window = next(e for e in tunnel.expectations if e.kind == "sticks")
    with pytest.raises(SceneError, match=r"parameters\.start_time = 5\.0: must be before"):
        dataclasses.replace(tunnel, expectations=(dataclasses.replace(
            window, parameters={"start_time": 5.0, "end_time": 6.0}),))


@pytest.mark.parametrize("change, named", [
    ({"initial_speed": -2.0}, "parameters.initial_speed = -2.0: must be > 0"),
    ({"friction": 0.0}, "parameters.friction = 0.0: must be > 0"),
])
def test_a_scene_file_with_a_meaningless_parameter_exits_2_before_any_engine_runs(
        tmp_path, capsys, change, named):
    scene = get_scene("sliding-box")
    data = scene_to_dict(scene)
    data["expectations"][0]["parameters"].update(change)
    path = tmp_path / "scene.toml"
    path.write_text(toml_dumps(data))
    assert main(["validate", str(path)]) == 2
    assert named in capsys.readouterr().err
    # `run` refuses it the same way, before a worker or an engine starts.
    assert main(["run", str(path), "-e", "reference", "--store", str(tmp_path / "s")]) == 2
    assert named in capsys.readouterr().err


# ---------------------------------------------------------------- engine ok, harness broken
def test_an_engine_ok_on_a_run_the_harness_judges_broken_is_named_in_the_verdict():
    # The fake engine ignores the clearance joint: the pendulum's bore falls off the journal
    # while the engine reports ok.
    scene = get_scene("clearance-pendulum")
    trajectory = fake_engine()._run(scene, RunSettings(horizon=0.2))
    assert trajectory.status.value == "ok"
    measured = measure(scene, trajectory)
    assert measured.verdict.value == "diverged"
    reason = measured.verdict_reason
    assert reason.startswith("engine status ok, harness: diverged (")
    assert "journal of pivot left its bore" in reason and "at t = " in reason


def test_a_contact_pair_of_a_rough_scene_is_named_as_taking_energy():
    row = elastic_row_in_space()
    sticky = dataclasses.replace(row, contacts=(*row.contacts, ContactPair(
        "ball0_ball2", body_a="ball0", shape_a="sphere", body_b="ball2", shape_b="sphere",
        restitution=0.5)))
    assert dissipative_elements(sticky) == ("contact ball0_ball2: restitution 0.5",)
