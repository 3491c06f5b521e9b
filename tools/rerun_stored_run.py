"""Run stored reference runs again with this checkout's code and compare their positions.

    .venv/bin/python -m tools.rerun_stored_run KEY [KEY ...] [--store reports/store]

For each run KEY of the results store: rebuilds the stored scene (the store's scene JSON) and
run settings (step, horizon, recording interval, options), runs it in the reference engine, and
prints the largest difference of the recorded body positions against the stored trajectory
(in the scene's length unit) with the run's unconverged steps. 0 means the code reproduces the
stored run exactly: the check that a change meant to be neutral is.
"""

from __future__ import annotations

import argparse
import importlib
import json
from pathlib import Path

import numpy as np

from clearbench.adapters import ENGINES
from clearbench.adapters.base import RunSettings
from clearbench.harness.run.store import ResultsStore


def rerun(store: ResultsStore, key: str) -> str:
    """One line: the run's scene, its build and stepping times now [s], and the largest position
    difference."""
    row = store.get(key)
    if row is None:
        raise SystemExit(f"no run with key {key!r} in {store.directory}")
    if row["engine"] != "reference":
        raise SystemExit(f"run {key} is of engine {row['engine']!r}; only the reference is rerun")
    stored = store.load_trajectory(key).positions
    engine = importlib.import_module(ENGINES["reference"]).create(row["preset"])
    trajectory = engine.run(store.scene(row["scene_hash"]),
                            RunSettings(time_step=row["time_step"], horizon=row["horizon"],
                                        record_every=row["record_every"],
                                        options=json.loads(row["options"] or "{}")))
    n = min(len(stored), len(trajectory.positions))
    difference = float(np.max(np.abs(trajectory.positions[:n] - stored[:n])))
    return (f"{key} {row['scene_name']}: build {trajectory.build_seconds:.0f} s, stepping "
            f"{trajectory.stepping_seconds:.1f} s, samples {len(trajectory.positions)} "
            f"against {len(stored)}, largest position difference {difference:.3e}, unconverged "
            f"steps {list(trajectory.unconverged_steps)}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("keys", nargs="+", metavar="KEY")
    parser.add_argument("--store", type=Path, default=Path("reports/store"))
    args = parser.parse_args()
    store = ResultsStore(args.store)
    for key in args.keys:
        print(rerun(store, key), flush=True)


if __name__ == "__main__":
    main()
