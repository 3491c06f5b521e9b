"""One-step jumps of a reference run: steps where a body moves farther than its velocity says.

Runs a library scene in the reference engine, recorded at every step, and for each step from
``--from`` on prints the body whose displacement over the step differs most from h times its
velocity at the step's end, where that difference exceeds ``--factor`` times the run's median
of the same figure over the window (the steady part is the frame origin's offset from the
centre of mass turning with the body, and the change of velocity within the step: both smooth
from step to step). A projection that pulls a contact onto a face by a gap it never closed
shows as one step standing far above its neighbours.

    .venv/bin/python -m tools.step_jumps c60-trip --horizon 7.02 --from 6.7 [--dt 1e-3] \
        [--option proximal_rescue=0]

Lengths and times in the scene's units (the C-60: mm, ms). Only APIs that also exist in earlier
revisions are used, so the file run from another checkout's environment measures that
checkout.
"""

from __future__ import annotations

import argparse

import numpy as np

from clearbench.adapters.base import RunSettings
from clearbench.adapters.reference import create
from clearbench.harness.run.spec import parse_assignment
from clearbench.scenarios.library import get_scene


def displacement_excess(times, positions, velocities) -> np.ndarray:
    """|x_{k+1} - x_k - (t_{k+1} - t_k) v_{k+1}| per step and body, (T - 1, B) [L], from the
    recorded (T,), (T, B, 3) positions and (T, B, 3) velocities."""
    h = np.diff(times)[:, None, None]
    return np.linalg.norm(np.diff(positions, axis=0) - h * velocities[1:], axis=2)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene")
    parser.add_argument("--horizon", type=float, required=True, help="run's end [T]")
    parser.add_argument("--from", dest="start", type=float, default=0.0,
                        help="first step's end time examined [T]")
    parser.add_argument("--dt", type=float, default=None, help="time step [T] (scene's)")
    parser.add_argument("--factor", type=float, default=10.0,
                        help="a step is a jump above this multiple of the window's median")
    parser.add_argument("--option", action="append", default=[], metavar="NAME=VALUE",
                        help="reference engine option, read as `clearbench run --option` reads it")
    args = parser.parse_args(argv)
    try:
        options = dict(parse_assignment(item, "--option") for item in args.option)
    except ValueError as error:
        parser.error(str(error))
    scene = get_scene(args.scene)
    trajectory = create().run(scene, RunSettings(time_step=args.dt, horizon=args.horizon,
                                                 record_every=1, options=options))
    excess = displacement_excess(trajectory.times, trajectory.positions,
                                 trajectory.velocities)
    window = trajectory.times[1:] >= args.start
    median = float(np.median(excess[window].max(axis=1)))
    print(f"{args.scene}: {int(window.sum())} steps from {args.start:g}; median largest "
          f"displacement beyond h v {median:.3g}; status {trajectory.status.value}")
    for k in np.nonzero(window)[0]:
        body = int(excess[k].argmax())
        if excess[k, body] > args.factor * median:
            print(f"  step ending at {trajectory.times[k + 1]:.6g}: {trajectory.body_names[body]} "
                  f"{excess[k, body]:.3g} ({excess[k, body] / median:.0f} x median)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
