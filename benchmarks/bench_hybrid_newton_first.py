"""The hybrid one-step solver with and without "Newton first after a step that needed it".

Run: ``.venv/bin/python benchmarks/bench_hybrid_newton_first.py [HORIZON_MS]``

Runs the first HORIZON_MS (default 1.5) of c60-on twice with the reference engine: as shipped,
and with the stepper's memory of the last solve disabled (every step starts with NSGS, as
before). Prints stepping and solver wall time and iterations per step. Prints numbers, asserts
nothing; the times depend on the machine's load.
"""

from __future__ import annotations

import sys

import numpy as np

from clearbench.adapters.base import RunSettings
from clearbench.adapters.reference.engine import create
from clearbench.ref_solver import stepper
from clearbench.scenarios.library import get_scene


def _run(horizon: float, newton_first: bool) -> None:
    original = stepper.MoreauJeanStepper._solve

    def nsgs_first(self, problem, r0):
        self._newton_first = False  # forget that the last step needed Newton
        return original(self, problem, r0)

    if not newton_first:
        stepper.MoreauJeanStepper._solve = nsgs_first
    try:
        engine = create()
        scene = get_scene("c60-on")
        engine.run(scene, RunSettings(horizon=0.01))  # compile
        trajectory = engine.run(scene, RunSettings(horizon=horizon))
    finally:
        stepper.MoreauJeanStepper._solve = original
    iterations = trajectory.solver_iterations[1:]
    print(f"newton first {'on ' if newton_first else 'off'}: stepping "
          f"{trajectory.stepping_seconds:.1f} s, solver {trajectory.metadata['solver_seconds']:.1f}"
          f" s, iterations per step mean {iterations.mean():.1f}, p90 "
          f"{np.percentile(iterations, 90):.0f}, unconverged "
          f"{len(trajectory.metadata['unconverged_steps'])}", flush=True)


if __name__ == "__main__":
    horizon = float(sys.argv[1]) if len(sys.argv) > 1 else 1.5
    for newton_first in (False, True):
        _run(horizon, newton_first)
