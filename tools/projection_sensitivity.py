"""How far a reference run's trajectory moves when only the round-off of its projection changes.

The reference stepper has two implementations of the projection's active-set solves: the
compiled kernel (``projection_kernel.project``, numba's least squares) that every run uses, and
the numpy one (``MoreauJeanStepper._project_python``, numpy's least squares) that the tests hold
it to. They solve the same problems and differ by round-off. This steps one scene with each
(the Python step, the default preset) and prints, at a few steps, the largest difference of
the bodies' positions [scene length unit] and each side's (solver iterations, projection
iterations, activation rounds) of that step, then the totals:

    .venv/bin/python -m tools.projection_sensitivity c60-on 500

On the C-60 the difference grows from round-off to a visible one within a few hundred steps
(the clearance joints' contacts chatter), so the run's cost and convergence, not only its
positions, follow the trajectory: a change of round-off in any kernel changes both.
"""

from __future__ import annotations

import argparse

import numpy as np

from clearbench.adapters.base import RunSettings
from clearbench.adapters.reference.build import build
from clearbench.adapters.reference.engine import create
from clearbench.scenarios.library import get_scene

#: Steps (0-based) at which the difference is printed, besides the last one.
REPORTED_STEPS = (0, 10, 50, 100, 200, 400)


def stepped(name: str, steps: int, numpy_projection: bool) -> list[tuple]:
    """(positions (nb, 3), solver iterations, projection iterations, activation rounds) after
    each of ``steps`` Python steps of library scene ``name``."""
    scene = get_scene(name)
    model = build(scene, create("default").run_settings(scene, RunSettings()))
    stepper, state = model.stepper, model.state
    if numpy_projection:
        stepper._project = stepper._project_python
    out = []
    for _ in range(steps):
        result = stepper.step(state)
        state = result.state
        stats = result.statistics
        out.append((state.x.copy(), stats.solver_iterations, stats.projection_iterations,
                    stats.activation_rounds))
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene")
    parser.add_argument("steps", type=int)
    args = parser.parse_args()
    compiled = stepped(args.scene, args.steps, numpy_projection=False)
    numpy = stepped(args.scene, args.steps, numpy_projection=True)
    print("step  largest position difference  (solver, projection, rounds) compiled / numpy")
    for k in sorted({k for k in REPORTED_STEPS if k < args.steps} | {args.steps - 1}):
        difference = float(np.abs(compiled[k][0] - numpy[k][0]).max())
        print(f"{k:>4}  {difference:>27.3g}  {compiled[k][1:]} / {numpy[k][1:]}")
    for index, label in ((1, "solver"), (2, "projection")):
        print(f"{label} iterations in all: {sum(r[index] for r in compiled)} compiled, "
              f"{sum(r[index] for r in numpy)} numpy")


if __name__ == "__main__":
    main()
