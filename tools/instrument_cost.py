"""What the run-wide geometry check adds to a run's measurement, measured side by side.

For every stored run of the scenes given (with a trajectory), the whole measurement
(:func:`clearbench.harness.measure.figures.measure`) is timed with the geometry check and
without it, in turn (with, without, with, without, ...), in one process: both see the same
drift of a shared machine's speed. Prints per run the states, the stride, the CPU seconds of
each (median of the repeats) and their ratio, then the totals over the runs. Measures, never
judges.

    .venv/bin/python -m tools.instrument_cost --store reports/store c60-on c60-trip
"""

from __future__ import annotations

import argparse
import statistics
import time

from clearbench.harness.measure import figures, geometry_check, series
from clearbench.harness.run.store import ResultsStore


def _timed(scene, trajectory, with_check: bool) -> float:
    """CPU seconds of one measurement (the kernel's gaps recomputed each time)."""
    series._LAST_GAPS[:] = [None, None, None]
    saved = figures._geometry
    if not with_check:
        figures._geometry = lambda *args: ""
    try:
        start = time.process_time()
        figures.measure(scene, trajectory)
        return time.process_time() - start
    finally:
        figures._geometry = saved


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("scenes", nargs="+", help="scene names whose stored runs to measure")
    parser.add_argument("--store", default="reports/store", help="results store directory")
    parser.add_argument("-n", "--repeats", type=int, default=2, help="pairs of timings per run")
    args = parser.parse_args(argv)
    store = ResultsStore(args.store)
    frame = store.dataframe(expand_metrics=False)
    rows = frame[frame["scene_name"].isin(args.scenes) & (frame["trajectory"] != "")]
    total_with = total_without = 0.0
    print(f"{'run':<44} {'states':>6} {'stride':>6} {'with [s]':>9} {'without [s]':>11} "
          f"{'ratio':>6}")
    for _, row in rows.sort_values(["scene_name", "label", "time_step"]).iterrows():
        scene = store.scene(row["scene_hash"])
        trajectory = store.load_trajectory(row["key"])
        if scene is None or trajectory is None or row["status"] not in ("ok", "diverged"):
            continue
        with_check, without = [], []
        for _ in range(args.repeats):
            with_check.append(_timed(scene, trajectory, True))
            without.append(_timed(scene, trajectory, False))
        a, b = statistics.median(with_check), statistics.median(without)
        total_with, total_without = total_with + a, total_without + b
        states = len(trajectory.times)
        label = f"{row['scene_name']} {row['label']} dt={row['time_step']:g}"
        print(f"{label:<44} {states:>6} {geometry_check.default_stride(states):>6} {a:>9.2f} "
              f"{b:>11.2f} {a / b:>6.2f}")
    if total_without > 0:
        print(f"{'total':<44} {'':>6} {'':>6} {total_with:>9.2f} {total_without:>11.2f} "
              f"{total_with / total_without:>6.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
