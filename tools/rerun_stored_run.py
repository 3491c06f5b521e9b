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
import sqlite3
import time
from pathlib import Path

import numpy as np

from clearbench.adapters import ENGINES
from clearbench.adapters.base import RunSettings
from clearbench.scenarios.serialization import scene_from_json


def rerun(store: Path, key: str) -> str:
    """One line: the run's scene, its stepping time now, and the largest position difference."""
    with sqlite3.connect(store / "runs.sqlite") as db:
        row = db.execute("select scene_name, scene_hash, engine, preset, time_step, horizon, "
                         "record_every, options, trajectory from runs where key = ?",
                         (key,)).fetchone()
        if row is None:
            raise SystemExit(f"no run with key {key!r} in {store}")
        name, scene_hash, engine_name, preset, step, horizon, every, options, path = row
        scene_json = db.execute("select scene_json from scenes where scene_hash = ?",
                                (scene_hash,)).fetchone()[0]
    if engine_name != "reference":
        raise SystemExit(f"run {key} is of engine {engine_name!r}; only the reference is rerun")
    stored = np.load(store / path, allow_pickle=False)["positions"]
    engine = importlib.import_module(ENGINES["reference"]).create(preset)
    tick = time.perf_counter()
    trajectory = engine.run(scene_from_json(scene_json),
                            RunSettings(time_step=step, horizon=horizon, record_every=every,
                                        options=json.loads(options)))
    seconds = time.perf_counter() - tick
    n = min(len(stored), len(trajectory.positions))
    difference = float(np.max(np.abs(trajectory.positions[:n] - stored[:n])))
    return (f"{key} {name}: {seconds:.0f} s, samples {len(trajectory.positions)} against "
            f"{len(stored)}, largest position difference {difference:.3e}, unconverged steps "
            f"{list(trajectory.unconverged_steps)}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("keys", nargs="+", metavar="KEY")
    parser.add_argument("--store", type=Path, default=Path("reports/store"))
    args = parser.parse_args()
    for key in args.keys:
        print(rerun(args.store, key), flush=True)


if __name__ == "__main__":
    main()
