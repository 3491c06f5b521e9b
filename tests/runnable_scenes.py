"""Hypothesis strategies of small runnable scene files (plain dicts, written as JSON): a fixed
floor, one to three free spheres and boxes above it, contact pairs with the floor and between
spheres, an optional ideal joint, spring and point force, and expectations; and one-field
mutations that make such a scene invalid, each with the field the error must name
(tests/scene_strategies.py generates scenes of every element for the format's round trip;
these are the runnable subset).

Sizes [m], masses [kg] and speeds [m/s] stay in ranges where the scene is physical (bodies
start apart and above the floor: no initial penetration), so a valid scene is one every
engine should be able to run, and a failure to is an engine or harness outcome, not bad input.
"""

from __future__ import annotations

import math

from hypothesis import strategies as st

#: Simulated: a few steps, enough to build every engine's model and step it.
TIME_STEP = 1e-3
HORIZON = 5e-3


def _box_inertia(mass: float, half: list) -> list:
    a, b, c = (2.0 * h for h in half)
    return [[mass * (b * b + c * c) / 12.0, 0.0, 0.0], [0.0, mass * (a * a + c * c) / 12.0, 0.0],
            [0.0, 0.0, mass * (a * a + b * b) / 12.0]]


def _sphere_inertia(mass: float, radius: float) -> list:
    moment = 0.4 * mass * radius * radius
    return [[moment, 0.0, 0.0], [0.0, moment, 0.0], [0.0, 0.0, moment]]


@st.composite
def free_body(draw, index: int) -> dict:
    """A free sphere or box at x = 0.5 index m (bodies 0.5 m apart, sizes <= 0.2 m), resting
    its lowest point 1 mm to 0.1 m above the floor."""
    mass = draw(st.floats(0.05, 20.0))
    speed = st.floats(-1.0, 1.0)
    if draw(st.booleans()):
        radius = draw(st.floats(0.01, 0.2))
        shape = {"kind": "sphere", "name": "shape", "radius": radius}
        inertia, low = _sphere_inertia(mass, radius), radius
    else:
        half = [draw(st.floats(0.01, 0.2)) for _ in range(3)]
        shape = {"kind": "box", "name": "shape", "half_extents": half}
        inertia, low = _box_inertia(mass, half), half[2]
    lift = draw(st.floats(1e-3, 0.1))
    return {"name": f"body{index}", "mass": mass, "inertia": inertia,
            "position": [0.5 * index, 0.0, low + lift],
            "velocity": [draw(speed), draw(speed), draw(speed)],
            "angular_velocity": [draw(speed), draw(speed), draw(speed)],
            "shapes": [shape]}


def _pair(name: str, body_a: str, body_b: str, friction: float, restitution: float) -> dict:
    return {"name": name, "body_a": body_a, "shape_a": "shape" if body_a != "floor" else "top",
            "body_b": body_b, "shape_b": "shape", "friction": friction,
            "restitution": restitution}


@st.composite
def valid_scene(draw) -> dict:
    """A small valid scene (see the module docstring), as the dict of a JSON scene file."""
    count = draw(st.integers(1, 3))
    bodies = [draw(free_body(i)) for i in range(count)]
    friction, restitution = st.floats(0.0, 1.0), st.floats(0.0, 1.0)
    contacts = [_pair(f"floor_{b['name']}", "floor", b["name"], draw(friction),
                      draw(restitution)) for b in bodies]
    spheres = [b["name"] for b in bodies if b["shapes"][0]["kind"] == "sphere"]
    if len(spheres) >= 2 and draw(st.booleans()):
        contacts.append(_pair("spheres", spheres[0], spheres[1], draw(friction),
                              draw(restitution)))
    scene = {
        "name": "generated", "description": "hypothesis-generated scene",
        "gravity": [0.0, 0.0, -9.81], "horizon": HORIZON, "time_step": TIME_STEP,
        "bodies": [{"name": "floor", "motion": "fixed",
                    "shapes": [{"kind": "plane", "name": "top"}]}, *bodies],
        "contacts": contacts,
    }
    loads, working = [], False
    if count >= 2 and draw(st.booleans()):
        a, b = bodies[0], bodies[1]
        scene["joints"] = [{"kind": draw(st.sampled_from(("spherical", "revolute"))),
                            "name": "hinge", "body_a": a["name"], "body_b": b["name"],
                            "anchor": [0.25, 0.0, 0.5 * (a["position"][2] + b["position"][2])],
                            "axis": [0.0, 1.0, 0.0]}]
        if scene["joints"][0]["kind"] == "spherical":
            del scene["joints"][0]["axis"]
    if count >= 2 and draw(st.booleans()):
        loads.append({"kind": "linear_spring", "body_a": bodies[0]["name"],
                      "body_b": bodies[-1]["name"], "stiffness": draw(st.floats(1.0, 1e3)),
                      "damping": draw(st.floats(0.0, 10.0)), "rest_length": 0.5 * (count - 1),
                      "name": "spring"})
    if draw(st.booleans()):
        working = True
        loads.append({"kind": "point_force", "name": "push", "body": bodies[0]["name"],
                      "force": [draw(st.floats(-10.0, 10.0)), 0.0, 0.0]})
    if loads:
        scene["loads"] = loads
    expectations = [{"name": "no_penetration", "kind": "no_penetration"}]
    if not working and draw(st.booleans()):
        expectations.append({"name": "energy", "kind": "energy_non_increasing"})
    scene["expectations"] = expectations
    return scene


def _set(path: list, value):
    """A mutation setting the field at ``path`` to ``value``."""
    def mutate(scene: dict) -> None:
        target = scene
        for key in path[:-1]:
            target = target[key]
        target[path[-1]] = value
    return mutate


#: One-field mutations: (what it does, field the error must name, mutate(scene)).
MUTATIONS = [
    ("negative mass", "mass", _set(["bodies", 1, "mass"], -1.0)),
    ("zero mass", "mass", _set(["bodies", 1, "mass"], 0.0)),
    ("NaN mass", "mass", _set(["bodies", 1, "mass"], math.nan)),
    ("inertia not positive definite", "inertia",
     _set(["bodies", 1, "inertia"], [[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0]])),
    ("zero quaternion", "orientation", _set(["bodies", 1, "orientation"], [0.0, 0.0, 0.0, 0.0])),
    ("infinite position", "position", _set(["bodies", 1, "position"], [0.0, math.inf, 0.0])),
    ("position beyond 1e30", "position", _set(["bodies", 1, "position"], [0.0, 0.0, 1e31])),
    ("negative friction", "friction", _set(["contacts", 0, "friction"], -0.5)),
    ("restitution above 1", "restitution", _set(["contacts", 0, "restitution"], 1.5)),
    ("unknown body", "body_b", _set(["contacts", 0, "body_b"], "nobody")),
    ("unknown shape", "shape_a", _set(["contacts", 0, "shape_a"], "nothing")),
    ("zero time step", "time_step", _set(["time_step"], 0.0)),
    ("negative horizon", "horizon", _set(["horizon"], -1.0)),
    ("NaN gravity", "gravity", _set(["gravity"], [0.0, 0.0, math.nan])),
    ("unknown key", "colour", _set(["bodies", 1, "colour"], "red")),
    ("unknown unit", "units", _set(["units"], {"length": "furlong"})),
    ("unknown motion", "motion", _set(["bodies", 1, "motion"], "floating")),
    ("unknown shape kind", "kind", _set(["bodies", 1, "shapes", 0, "kind"], "torus")),
]
