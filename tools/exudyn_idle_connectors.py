"""Exudyn with its idle contact connectors switched off against Exudyn evaluating them all.

Runs each scene in one Exudyn preset with ``cull_idle_connectors`` 'on' and 'off', alternately in
this one process after a short warm-up run (numba's law-load kernels and Exudyn's first build),
and prints per scene: the stepping time per nominal step of each side [ms] and their ratio
(medians over ``--repeat`` pairs), the mean fraction of connectors left on, the margin's
median [scene length unit], the margin breaches, and whether the two trajectories (every
recorded array, every step recorded) are equal bit for bit:

    .venv/bin/python -m tools.exudyn_idle_connectors c60-on --horizon 0.06 --preset mechanism
    .venv/bin/python -m tools.exudyn_idle_connectors clearance-pendulum box-grid \\
        stiff-many-contacts --horizon 0.3

The ratio is a side-by-side figure of one invocation; the times themselves depend on the
machine's load.
"""

from __future__ import annotations

import argparse
import statistics

import numpy as np

from clearbench.adapters.base import RunSettings
from clearbench.adapters.exudyn import create
from clearbench.scenarios.library import get_scene

#: Arrays of a trajectory compared bit for bit.
COMPARED = ("times", "positions", "orientations", "velocities", "angular_velocities",
            "contact_normal_force", "contact_force", "solver_iterations", "active_contacts")


def run(preset: str, scene_name: str, horizon: float | None, cull: bool):
    """One Exudyn run of ``scene_name`` to ``horizon`` [scene time unit], every step
    recorded."""
    return create(preset).run(get_scene(scene_name), RunSettings(
        horizon=horizon, options={"cull_idle_connectors": "on" if cull else "off"}))


def identical(a, b) -> bool:
    """Every compared array of trajectories ``a`` and ``b`` equal bit for bit (NaN = NaN)."""
    return all(np.array_equal(getattr(a, name), getattr(b, name), equal_nan=True)
               for name in COMPARED)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("scenes", nargs="+")
    parser.add_argument("--preset", default="tuned")
    parser.add_argument("--horizon", type=float, default=None,
                        help="simulated time [scene time unit] (default: the scene's)")
    parser.add_argument("--repeat", type=int, default=2, help="pairs of runs per scene")
    args = parser.parse_args(argv)
    print(f"exudyn[{args.preset}], horizon {args.horizon or 'of the scene'}, "
          f"{args.repeat} pairs of runs, alternating")
    print(f"{'scene':24s} {'connectors':>10s} {'on [ms/step]':>12s} {'all [ms/step]':>13s} "
          f"{'ratio':>6s} {'active':>7s} {'margin':>9s} {'breaches':>8s}  identical")
    for name in args.scenes:
        scene = get_scene(name)
        run(args.preset, name, 3 * scene.time_step, True)  # warm-up
        culled, full, same = [], [], True
        for _ in range(args.repeat):
            a = run(args.preset, name, args.horizon, True)
            b = run(args.preset, name, args.horizon, False)
            steps = max(1, a.steps)
            culled.append(a.stepping_seconds / steps * 1e3)
            full.append(b.stepping_seconds / steps * 1e3)
            same = same and identical(a, b) and a.status == b.status
        idle = a.metadata["solver_statistics"]["idle_connectors"] or {}
        on, every = statistics.median(culled), statistics.median(full)
        margin = idle.get("margin_median")
        print(f"{name:24s} {idle.get('connectors', 0):10d} {on:12.3f} {every:13.3f} "
              f"{on / every:6.2f} {idle.get('mean_active_fraction', 1.0):7.3f} "
              f"{margin if margin is not None else float('nan'):9.2g} "
              f"{idle.get('margin_breaches', 0):8d}  {'yes' if same else 'NO'}", flush=True)


if __name__ == "__main__":
    main()
