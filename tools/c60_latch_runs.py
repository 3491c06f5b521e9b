"""The reference's C-60 runs that judge the latch: one line of figures per run.

For each scene (``c60-on``, ``c60-trip``), variant (scenarios/c60/variants.py) and step given,
the reference engine runs in this process and one line is printed: status; FC-1 (C7's normal
force, mean over the run's last millisecond [N]); the hook's turn from its start at the end
[deg] (a latched hook stays within a few degrees); the trip's strike, release and opening
times [ms] (``harness.c60.analysis.trip_events``; NaN where they do not happen); the largest
penetration over the recorded states [mm] (the gap kernel's); the steps whose contact problem
did not converge and those whose projection did not (count, and the first few).

    .venv/bin/python -m tools.c60_latch_runs --scene c60-trip --variant source \
        --variant latch-face-normal --dt 1e-3 --dt 4e-3 [--clearance 0.07] [--horizon 4] \
        [--option proximal_rescue=0]

Only APIs that also exist in earlier revisions are used, so the same file run from another
checkout's environment measures that checkout (``python /path/to/c60_latch_runs.py ...``).
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

from clearbench.adapters.base import RunSettings
from clearbench.adapters.reference import create
from clearbench.harness.c60.analysis import settled_outputs, trip_events
from clearbench.harness.cli.common import add_engine_options_option, engine_options
from clearbench.harness.measure import series
from clearbench.scenarios.library import get_scene

#: The C-60's joints (their clearances set together by --clearance).
JOINTS = tuple(f"J{i}" for i in range(1, 8))


def run_line(scene_name: str, variant: str, time_step: float, clearance: float | None,
             horizon: float | None, record_every: int, options: dict | None = None) -> str:
    """Run one configuration (``options``: the reference engine's run options) and return its
    line of figures."""
    parameters = {"variant": variant}
    if clearance is not None:
        parameters["clearances"] = {joint: clearance for joint in JOINTS}
    scene = get_scene(scene_name, **parameters)
    started = time.perf_counter()
    trajectory = create("default").run(scene, RunSettings(
        time_step=time_step, horizon=horizon, record_every=record_every,
        options=options or {}))
    wall = time.perf_counter() - started
    hook = trajectory.orientations[:, trajectory.body_names.index("hook")]
    angle = 2.0 * np.degrees(np.arctan2(hook[:, 3], hook[:, 0]))
    fc1 = settled_outputs(scene, trajectory).get("FC1_contact_force", math.nan)
    events = trip_events(scene, trajectory)
    penetration = float(np.max(series.penetration(scene, trajectory)))
    metadata = trajectory.metadata
    unconverged = list(trajectory.unconverged_steps)
    count = int(getattr(trajectory, "unconverged_count", len(unconverged)))
    projections = list(metadata.get("unconverged_projections", []))
    shown = "".join(f" {key}={value}" for key, value in (options or {}).items())
    return (f"{scene_name} {variant} dt={time_step:g} clearance={clearance}{shown} "
            f"status={trajectory.status.value} FC1={fc1:.4f} N hook={angle[-1] - angle[0]:+.3f} "
            f"deg strike={events.strike:.3f} release={events.release:.3f} "
            f"opening={events.opening:.3f} ms penetration={penetration:.3e} mm "
            f"unconverged={count} {unconverged[:5]} projections={len(projections)} "
            f"{projections[:5]} iterations={np.mean(trajectory.solver_iterations):.1f} "
            f"steps={trajectory.steps} wall={wall:.0f} s")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", action="append", required=True)
    parser.add_argument("--variant", action="append", default=None)
    parser.add_argument("--dt", action="append", type=float, required=True, help="[ms]")
    parser.add_argument("--clearance", type=float, default=None,
                        help="every joint's radial clearance [mm] (default: the sheet's)")
    parser.add_argument("--horizon", type=float, default=None, help="[ms] (default: scene's)")
    parser.add_argument("--record-every-ms", type=float, default=0.01,
                        help="recording interval [ms]")
    add_engine_options_option(parser, "a run option of the reference engine (as `clearbench "
                              "run --option`), e.g. proximal_rescue=0 (the rescue off)")
    args = parser.parse_args()
    options = engine_options(args)
    for scene_name in args.scene:
        for variant in args.variant or ["source"]:
            for time_step in args.dt:
                every = max(1, round(args.record_every_ms / time_step))
                print(run_line(scene_name, variant, time_step, args.clearance, args.horizon,
                               every, options), flush=True)


if __name__ == "__main__":
    main()
