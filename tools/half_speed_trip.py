"""The half-speed trip test in the reference, as `clearbench c60 validate`'s speed check runs
it, to a horizon: its projection failures and deepest pairs, and where it parts from another
checkout's run of the same.

    .venv/bin/python -m tools.half_speed_trip 67.7 --save this.npz [--against other.npz]

Run it in two checkouts (each with its own environment), the second with ``--against`` the
first's file: it prints the first recorded time at which the bodies' positions differ by more
than each of several thresholds. Lengths in mm, times in ms; recorded every 40 steps (40 us).
"""

from __future__ import annotations

import argparse

import numpy as np

from clearbench.adapters.base import RunSettings
from clearbench.adapters.reference import create
from clearbench.harness.c60.validation import half_speed_scene
from clearbench.harness.measure.series import penetration

#: Position differences [mm] whose first recorded time is printed with --against.
THRESHOLDS = (0.0, 1e-12, 1e-9, 1e-6, 1e-4, 1e-3, 1e-2, 0.1)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("horizon", type=float, help="run's end [ms]")
    parser.add_argument("--save", help="write times and positions to this .npz")
    parser.add_argument("--against", help="another run's .npz (--save) to compare with")
    args = parser.parse_args(argv)
    scene = half_speed_scene("c60-trip-force-test")
    trajectory = create().run(scene, RunSettings(horizon=args.horizon, record_every=40))
    failures = trajectory.metadata.get("unconverged_projections", [])
    print(f"status {trajectory.status.value}, {trajectory.steps} steps; unconverged steps "
          f"{list(trajectory.unconverged_steps)[:10]}; {len(failures)} projection failures "
          f"(first {list(failures)[:5]})")
    depth = penetration(scene, trajectory)
    names = [contact.name for contact in scene.expanded.contacts]
    for k in np.argsort(depth.max(axis=0))[::-1][:5]:
        print(f"  {names[k]}: largest penetration {depth[:, k].max():.3g} mm at "
              f"{trajectory.times[depth[:, k].argmax()]:.4f} ms, at the end {depth[-1, k]:.3g}")
    if args.save:
        np.savez(args.save, times=trajectory.times, positions=trajectory.positions)
    if args.against:
        other = np.load(args.against)
        count = min(len(other["times"]), len(trajectory.times))
        apart = np.abs(other["positions"][:count] - trajectory.positions[:count]).max(axis=(1, 2))
        for threshold in THRESHOLDS:
            beyond = np.nonzero(apart > threshold)[0]
            when = f"{trajectory.times[beyond[0]]:.4f} ms" if len(beyond) else "never"
            print(f"  positions apart by more than {threshold:g} mm from {when}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
