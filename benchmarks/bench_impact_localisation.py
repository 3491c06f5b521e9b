"""Bouncing-ball apex errors with impact localisation off (classic Moreau–Jean) and on.

Run: ``.venv/bin/python benchmarks/bench_impact_localisation.py [SCENE ...]``

For each bouncing-ball scene and step h (1e-3 s, 1e-4 s): the relative error of apexes 1–4
from the shared expectation evaluator, the height after t_inf, the penetration and the number
of localised (split) steps. These are the README's "Measured against physics" figures. Prints
numbers, asserts nothing.
"""

from __future__ import annotations

import sys

from clearbench.adapters.base import RunSettings
from clearbench.adapters.reference.engine import create
from clearbench.harness.measure.expectation_figures import evaluate
from clearbench.scenarios.library import get_scene


def main(names: list[str]) -> None:
    engine = create()
    for name in names or ["bouncing-ball-e0.5", "bouncing-ball-e0.9"]:
        scene = get_scene(name)
        for h in (1e-3, 1e-4):
            for localise in (False, True):
                trajectory = engine.run(scene, RunSettings(
                    time_step=h, options={"localise_impacts": localise}))
                figures = {r.name: r.figures for r in evaluate(scene, trajectory)}
                apexes = figures["apex_heights"]
                errors = " ".join(f"{apexes.get(f'apex_{k}_relative_error', float('nan')):+.2e}"
                                  for k in range(1, 5))
                print(f"{name:20s} h={h:g} s {'localised' if localise else 'classic  '} "
                      f"apex 1-4: {errors}  after t_inf {apexes['height_after_rest']:.1e} m  "
                      f"penetration {figures['no_penetration']['penetration_max']:.1e} m  "
                      f"split steps {trajectory.metadata['split_steps']}", flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
