"""Every kind of bad input is refused with a message naming the field and the value."""

from __future__ import annotations

import copy
import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from clearbench.scenarios.library import get_scene
from clearbench.scenarios.serialization import scene_from_dict, scene_to_dict
from clearbench.scenarios.validation import SceneError


def _ball_dict():
    return scene_to_dict(get_scene("bouncing-ball-e0.5"))


def _pendulum_dict():
    return scene_to_dict(get_scene("clearance-pendulum"))


def _mutate(data, path, value):
    node = data
    for key in path[:-1]:
        node = node[key]
    node[path[-1]] = value
    return data


BAD_INPUTS = [
    # (scene factory, path in the dict, bad value, text expected in the field path)
    (_ball_dict, ("bodies", 1, "mass"), -1.0, "mass"),
    (_ball_dict, ("bodies", 1, "mass"), 0.0, "mass"),
    (_ball_dict, ("bodies", 1, "inertia"), [[1, 0, 0], [0, 1, 0], [0, 0, -1]], "inertia"),
    (_ball_dict, ("bodies", 1, "inertia"), [[1, 0.5, 0], [0, 1, 0], [0, 0, 1]], "inertia"),
    (_ball_dict, ("bodies", 1, "inertia"), [[1, 0, 0], [0, 1, 0], [0, 0, 2.5]], "inertia"),
    (_ball_dict, ("bodies", 1, "orientation"), [0, 0, 0, 0], "orientation"),
    (_ball_dict, ("bodies", 1, "orientation"), [1, 0, 0, math.nan], "orientation"),
    (_ball_dict, ("bodies", 1, "orientation"), [2, 0, 0, 0], "orientation"),
    (_pendulum_dict, ("clearance_joints", 0, "radial_clearance"), 0.0, "radial_clearance"),
    (_pendulum_dict, ("clearance_joints", 0, "radial_clearance"), -1e-4, "radial_clearance"),
    (_pendulum_dict, ("clearance_joints", 0, "axial_clearance"), 0.0, "axial_clearance"),
    (_ball_dict, ("contacts", 0, "friction"), -0.1, "friction"),
    (_ball_dict, ("contacts", 0, "restitution"), 1.5, "restitution"),
    (_ball_dict, ("contacts", 0, "restitution"), -0.5, "restitution"),
    (_ball_dict, ("contacts", 0, "body_b"), "bal", "body_b"),
    (_ball_dict, ("contacts", 0, "shape_b"), "cube", "shape_b"),
    (_pendulum_dict, ("clearance_joints", 0, "bearing_body"), "bobb", "bearing_body"),
    (_ball_dict, ("time_step",), 0.0, "time_step"),
    (_ball_dict, ("time_step",), -1e-3, "time_step"),
    (_ball_dict, ("horizon",), math.inf, "horizon"),
    (_ball_dict, ("gravity",), [0.0, 0.0, math.nan], "gravity"),
    (_ball_dict, ("bodies", 1, "position"), [0.0, math.inf, 0.0], "position"),
    (_ball_dict, ("bodies", 1, "shapes", 0, "radius"), -0.1, "radius"),
    (_ball_dict, ("bodies", 1, "shapes", 0, "kind"), "torus", "kind"),
    (_ball_dict, ("bodies", 1, "motion"), "flying", "motion"),
    (_ball_dict, ("bodies", 1, "massa"), 1.0, "massa"),
    (_ball_dict, ("units", "length"), "furlong", "units.length"),
]


@pytest.mark.parametrize(("factory", "path", "value", "field"), BAD_INPUTS)
def test_bad_input_is_refused_naming_field_and_value(factory, path, value, field):
    data = _mutate(factory(), path, value)
    with pytest.raises(SceneError) as caught:
        scene_from_dict(data)
    message = str(caught.value)
    assert field in caught.value.field, message
    # The whole value, or for vectors the offending component, appears in the message.
    shown = [repr(value), str(value)]
    if isinstance(value, list):
        shown += [repr(v) for v in value if not isinstance(v, list)]
    assert any(text in message for text in shown), message


def _numeric_paths(node, prefix=()):
    """Every path to a float leaf of a scene dict."""
    if isinstance(node, dict):
        for key, value in node.items():
            yield from _numeric_paths(value, prefix + (key,))
    elif isinstance(node, list):
        for index, value in enumerate(node):
            yield from _numeric_paths(value, prefix + (index,))
    elif isinstance(node, float):
        yield prefix


CLEARANCE_PATHS = list(_numeric_paths(_pendulum_dict()))


@settings(max_examples=80, deadline=None)
@given(st.sampled_from(CLEARANCE_PATHS), st.sampled_from([math.nan, math.inf, -math.inf]))
def test_nan_or_inf_anywhere_is_refused_with_its_path(path, bad):
    data = _mutate(copy.deepcopy(_pendulum_dict()), path, bad)
    with pytest.raises(SceneError) as caught:
        scene_from_dict(data)
    # The last key of the path (field name, or index of a vector component) is named.
    last_name = next(str(p) for p in reversed(path) if isinstance(p, str))
    assert last_name in caught.value.field, (path, str(caught.value))


def test_driven_body_needs_a_driver_and_driver_needs_driven_body():
    data = scene_to_dict(get_scene("slider-crank"))
    data["drivers"] = []
    with pytest.raises(SceneError, match="no driver"):
        scene_from_dict(data)
    data = scene_to_dict(get_scene("slider-crank"))
    data["bodies"][1]["motion"] = "free"
    with pytest.raises(SceneError, match="must be 'driven'"):
        scene_from_dict(data)


def test_duplicate_names_are_refused():
    data = _ball_dict()
    data["bodies"][1]["name"] = "ground"
    with pytest.raises(SceneError, match="duplicate"):
        scene_from_dict(data)


def test_values_are_stored_as_given():
    # A quaternion within 1e-6 of unit norm is accepted and kept exactly as written.
    data = _ball_dict()
    data["bodies"][1]["orientation"] = [0.7071068, 0.0, 0.0, 0.7071068]
    scene = scene_from_dict(data)
    assert scene.bodies[1].orientation == (0.7071068, 0.0, 0.0, 0.7071068)
