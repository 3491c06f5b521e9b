"""How far the reference's projection stage moves the bodies, against the violation it removes.

    .venv/bin/python -m tools.projection_moves c60-trip --dt 0.001 --steps 7400 \
        [--variant NAME] [--show 8]

Steps SCENE in the reference engine with the Python step (the default preset; the projection
itself is the compiled kernel the run uses) and, at every projection stage, reads the largest
violation at its start (``MoreauJeanStepper._violations``) and the largest displacement of a
body's points over the stage, |dx| + L |dtheta| with L the scene's length scale (the measure of
``projection_kernel.correction_size``). Prints the distribution of their ratio, displacement /
(violation + ``CORRECTION_FLOOR`` L), and the largest cases with their step: the figures of
docs/reference-solver.md ("The projection's bound") against ``PROJECTION_REACH``, the bound of a
projection's corrections.

``--dt`` is in the scene's time unit (C-60: ms).
"""

from __future__ import annotations

import argparse

import numpy as np

from clearbench.adapters.base import RunSettings
from clearbench.adapters.reference.build import build
from clearbench.adapters.reference.engine import create
from clearbench.kernels.quaternion import quat_angular_distance_batch
from clearbench.ref_solver.projection_kernel import CORRECTION_FLOOR, PROJECTION_REACH
from clearbench.scenarios.library import get_scene


def observe(scene_name: str, variant: str | None, time_step: float, steps: int) -> list:
    """(ratio, step, violation [L], displacement [L], body) of every projection stage."""
    scene = get_scene(scene_name, **({"variant": variant} if variant else {}))
    model = build(scene, create("default").run_settings(scene, RunSettings(
        time_step=time_step)))
    stepper, state = model.stepper, model.state
    length = stepper.settings.length_scale
    floor = CORRECTION_FLOOR * length
    names = [body.name for body in scene.expanded.bodies]
    seen, current = [], [0]
    original = stepper._projection_stage

    def observed(stage_state, active, impulses, closed):
        violation = stepper._violations(stage_state, active, closed)[4]
        x0, p0 = stage_state.x.copy(), stage_state.p.copy()
        result = original(stage_state, active, impulses, closed)
        moves = (np.linalg.norm(stage_state.x - x0, axis=1)
                 + length * quat_angular_distance_batch(p0, stage_state.p))
        body = int(np.argmax(moves))
        seen.append((moves[body] / (violation + floor), current[0], violation, moves[body],
                     names[body]))
        return result

    stepper._projection_stage = observed
    for step in range(1, steps + 1):
        current[0] = step
        state = stepper.step(state).state
    return seen


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene")
    parser.add_argument("--variant", default=None, help="a C-60 variant (scenarios/c60)")
    parser.add_argument("--dt", type=float, required=True, help="time step [scene's unit]")
    parser.add_argument("--steps", type=int, required=True)
    parser.add_argument("--show", type=int, default=8, help="largest cases printed")
    arguments = parser.parse_args(argv)
    seen = observe(arguments.scene, arguments.variant, arguments.dt, arguments.steps)
    ratios = np.array([entry[0] for entry in seen])
    percentiles = np.percentile(ratios, [50, 90, 99, 99.9, 100])
    print(f"{arguments.scene} {arguments.variant or ''} dt={arguments.dt:g}: {len(seen)} "
          f"projection stages in {arguments.steps} steps; displacement / (violation + floor) "
          f"median {percentiles[0]:.3g}, 90 % {percentiles[1]:.3g}, 99 % {percentiles[2]:.3g}, "
          f"99.9 % {percentiles[3]:.3g}, largest {percentiles[4]:.3g} "
          f"(the bound: {PROJECTION_REACH:g})")
    for ratio, step, violation, move, body in sorted(seen, key=lambda e: -e[0])[
            :arguments.show]:
        print(f"  {ratio:9.3g}  step {step}: violation {violation:.3e}, {body} moved "
              f"{move:.3e}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
