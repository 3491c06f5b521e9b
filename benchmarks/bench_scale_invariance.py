"""Clearance pendulum in SI against mm–g–ms, and against SI with the bob moved by 1e-15 m.

Run: ``.venv/bin/python benchmarks/bench_scale_invariance.py``

Prints the largest body-position difference [m] at a few times. Both differences grow at the
same rate (the rattling in the clearance is chaotic): the README's scale-invariance figures.
Prints numbers, asserts nothing (tests/test_reference_engine.py asserts the behaviour).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from clearbench.adapters.base import RunSettings
from clearbench.adapters.reference.engine import create
from clearbench.scenarios.library import get_scene
from clearbench.scenarios.units import MM_G_MS

HORIZON = 0.5  # [s]
TIMES = (0.05, 0.1, 0.15, 0.2, 0.3, 0.4, 0.5)  # [s]


def main() -> None:
    engine = create()
    scene = get_scene("clearance-pendulum")
    bob = scene.body_index("bob")
    body = scene.bodies[bob]
    bodies = list(scene.bodies)
    bodies[bob] = dataclasses.replace(
        body, position=(body.position[0] + 1e-15,) + tuple(body.position[1:]))
    si = engine.run(scene, RunSettings(horizon=HORIZON))
    mm = engine.run(scene.rescaled(MM_G_MS), RunSettings(horizon=1e3 * HORIZON))
    moved = engine.run(dataclasses.replace(scene, bodies=tuple(bodies)),
                       RunSettings(horizon=HORIZON))
    print("t [s]   SI vs mm-g-ms [m]   SI vs SI with the bob 1e-15 m away [m]")
    for t in TIMES:
        k = int(np.searchsorted(si.times, t))
        units = np.abs(1e-3 * mm.positions[k] - si.positions[k]).max()
        perturbed = np.abs(moved.positions[k] - si.positions[k]).max()
        print(f"{t:5.2f}   {units:17.2e}   {perturbed:17.2e}")


if __name__ == "__main__":
    main()
