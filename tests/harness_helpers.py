"""Shared pieces of the harness tests: the fake engine's module name, a free-flight scene file,
and the marker for tests that need the shared metrics (they need the geometry module)."""

from __future__ import annotations

import os
from pathlib import Path

from clearbench.scenarios.bodies import Body
from clearbench.scenarios.inertia import solid_sphere
from clearbench.scenarios.outputs import PointPosition
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.serialization import scene_to_toml

ROOT = Path(__file__).resolve().parent.parent
FAKE = {"fake": "tests.fake_engine"}
FAKE_OPTION = ["--engine-module", "fake=tests.fake_engine"]



def probe_scene(horizon: float = 1.0, time_step: float = 1e-2) -> Scene:
    """One free ball thrown upward in gravity (no contact): the fake engine's error against
    the exact parabola is O(dt); its named output is the height [m]."""
    return Scene(
        name="probe", description="A ball thrown upward, free flight.", horizon=horizon,
        time_step=time_step,
        bodies=(Body("ball", mass=1.0, inertia=solid_sphere(1.0, 0.1), position=(0, 0, 1.0),
                     velocity=(1.0, 0.0, 5.0)),),
        outputs=(PointPosition("height", body="ball", component="z"),),
    )


def write_probe(directory: Path, **kwargs) -> Path:
    path = directory / "probe.toml"
    path.write_text(scene_to_toml(probe_scene(**kwargs)))
    return path


def subprocess_env() -> dict:
    """Environment for a `clearbench` subprocess that can import the fake engine."""
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(ROOT), env.get("PYTHONPATH")]))
    return env
