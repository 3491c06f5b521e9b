"""Lossless round trips of scenes through dict, JSON and TOML, and unit rescaling."""

from __future__ import annotations

import tomllib

from hypothesis import HealthCheck, given, settings

from clearbench.scenarios.serialization import (
    is_close_scene,
    scene_from_dict,
    scene_from_json,
    scene_from_toml,
    scene_to_dict,
    scene_to_json,
    scene_to_toml,
)
from clearbench.scenarios.units import MM_G_MS, SI, UnitSystem

from .scene_strategies import scenes

PROPERTY = settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])


@PROPERTY
@given(scenes())
def test_dict_round_trip_is_exact(scene):
    assert scene_from_dict(scene_to_dict(scene)) == scene


@PROPERTY
@given(scenes())
def test_json_round_trip_is_exact(scene):
    assert scene_from_json(scene_to_json(scene)) == scene


@PROPERTY
@given(scenes())
def test_toml_round_trip_is_exact_and_the_text_is_valid_toml(scene):
    text = scene_to_toml(scene)
    tomllib.loads(text)  # raises on invalid TOML
    assert scene_from_toml(text) == scene


@PROPERTY
@given(scenes())
def test_rescaling_there_and_back_restores_every_value(scene):
    # Each value is multiplied then divided by powers of 10: a few ulps of error at most, so a
    # relative tolerance of 1e-12 is ample and still catches any wrong exponent (>= 1e-3).
    other = UnitSystem("um", "mg", "us")
    assert is_close_scene(scene.rescaled(other).rescaled(scene.units), scene, rtol=1e-12)


@PROPERTY
@given(scenes())
def test_content_hash_depends_only_on_content(scene):
    again = scene_from_dict(scene_to_dict(scene))
    assert again.content_hash == scene.content_hash


def test_mm_g_ms_force_unit_is_the_newton():
    assert MM_G_MS.force_unit() == "N"
    assert SI.force_unit() == "N"
    # 1 kg m^2 = 1e9 g mm^2, as the C-60 data sheet states.
    assert SI.factor_to(MM_G_MS, (2, 1, 0)) == 1e9
