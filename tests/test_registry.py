"""Invariants over the whole scene registry (dm_control style): every scene builds, validates,
round-trips, rescales, and carries an expectation."""

from __future__ import annotations

import pytest

from clearbench.scenarios.library import get_entry, get_scene, scene_names
from clearbench.scenarios.serialization import is_close_scene, scene_from_dict, scene_to_dict
from clearbench.scenarios.units import MM_G_MS

NAMES = scene_names()

REQUIRED = {
    "bouncing-ball-e0", "bouncing-ball-e0.5", "bouncing-ball-e0.9", "incline-stick",
    "incline-slide", "sliding-box", "rolling-sphere", "pendulum", "torque-free-flip",
    "slider-crank", "clearance-pendulum", "flores-slider-crank", "rocking-block",
}


def test_every_required_scene_is_registered():
    assert REQUIRED <= set(NAMES)


@pytest.mark.parametrize("name", NAMES)
def test_scene_builds_round_trips_and_rescales(name):
    scene = get_scene(name)
    assert scene.name == name
    assert scene_from_dict(scene_to_dict(scene)) == scene
    # Rescaling multiplies and divides by powers of ten: 1e-12 relative is a few ulps.
    assert is_close_scene(scene.rescaled(MM_G_MS).rescaled(scene.units), scene, rtol=1e-12)
    assert scene.expectations, "every library scene states what physics expects of it"
    assert set(get_entry(name).tags) == set(scene.tags)


@pytest.mark.parametrize("name", NAMES)
def test_scene_is_deterministic(name):
    assert get_scene(name).content_hash == get_scene(name).content_hash


def test_tags_select_scenes():
    assert "bouncing-ball-e0.5" in scene_names("smoke")
    assert "pendulum" not in scene_names("clearance")
    assert set(scene_names("clearance")) >= {"clearance-pendulum", "flores-slider-crank"}


def test_features_are_derived_from_content():
    assert "restitution" not in get_scene("bouncing-ball-e0").features
    assert "restitution" in get_scene("bouncing-ball-e0.5").features
    assert {"clearance_joints", "rings", "arcs", "pair:circle-cylinder",
            "pair:arc-plane"} <= (
        get_scene("clearance-pendulum").features
    )
    assert "closed_loop" in get_scene("slider-crank").features
    assert "closed_loop" not in get_scene("flores-slider-crank").features
    assert "drivers" in get_scene("slider-crank").features


def test_factories_take_parameters():
    scene = get_scene("clearance-pendulum", radial_clearance=1e-6)
    assert scene.clearance_joints[0].radial_clearance == 1e-6


def test_a_factory_called_directly_takes_its_parameters_by_position_or_name():
    """The registry's wrapper keeps the factory's signature: ``incline_stick(10.0, 0.3)`` and
    ``incline_stick(angle_degrees=10.0, friction=0.3)`` build the same scene, named."""
    from clearbench.scenarios.library.basic import incline_stick

    by_position = incline_stick(12.0, 0.4)
    by_name = incline_stick(angle_degrees=12.0, friction=0.4)
    assert by_position == by_name
    assert by_position.name == "incline-stick"
    assert by_position.contacts[0].friction == 0.4


def test_unknown_scene_names_the_known_ones():
    with pytest.raises(KeyError, match="bouncing-ball-e0.5"):
        get_scene("no-such-scene")
