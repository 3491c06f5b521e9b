"""Stored runs for the viewer: a run chosen by its key, or per engine label the stored run of a
scene (at a given step, else the finest with a recording), with the C-60 trip's events."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from clearbench.harness.c60.analysis import trip_events
from clearbench.harness.report.viewer.frames import RecordedRun
from clearbench.harness.report.viewer.payload import Event
from clearbench.harness.run.store import ResultsStore
from clearbench.scenarios.scene import Scene

#: Statuses whose recording is worth playing (a diverged run up to where it stopped).
PLAYABLE = ("ok", "diverged")


class ViewInputError(ValueError):
    """What the user asked for is not in the store: ``field`` and ``value`` name it."""

    def __init__(self, field: str, value, reason: str):
        super().__init__(f"{field} {value!r}: {reason}")
        self.field, self.value, self.reason = field, value, reason


def _events(scene: Scene, trajectory) -> dict[str, float]:
    """The C-60 trip's events of a c60-trip run (strike, release, opening [ms]); none for
    another scene."""
    if scene.name != "c60-trip":
        return {}
    try:
        events = trip_events(scene, trajectory)
    except (ValueError, IndexError):
        return {}
    return {"strike": events.strike, "release": events.release, "opening": events.opening}


def _recorded(store: ResultsStore, row: dict, scene: Scene) -> RecordedRun:
    trajectory = store.load_trajectory(row["key"])
    if trajectory is None or len(trajectory.times) < 2:
        raise ViewInputError("run", row["key"], f"{row['label']} ({row['status']}) has no "
                             "recording in the store")
    return RecordedRun(f"{row['label']} dt {row['time_step']:g} {scene.units.time}",
                       trajectory, row["status"], row.get("message") or "",
                       _events(scene, trajectory))


def stored_runs(store: ResultsStore, run_or_scene: str, labels: Sequence[str] = (),
                time_step: float | None = None) -> tuple[Scene, list[RecordedRun]]:
    """The scene and the runs to play for ``run_or_scene``: a run key (or a prefix of at least
    6 characters that only one key has), else a scene name: per engine label of ``labels``
    (``mujoco`` takes every preset, ``mujoco[tuned]`` that one; all labels when empty) its run
    at the step nearest ``time_step``, else its finest step, among the runs with a recording
    (ok or diverged) of the scene's latest variant in the store.

    Raises
    ------
    ViewInputError
        Nothing in the store matches, or a label has no playable run of the scene.
    """
    frame = store.dataframe(expand_metrics=False)
    if not len(frame):
        raise ViewInputError("store", str(store.directory), "holds no run")
    keys = [k for k in frame["key"] if len(run_or_scene) >= 6 and k.startswith(run_or_scene)]
    if len(keys) == 1:
        row = frame[frame["key"] == keys[0]].iloc[0].to_dict()
        scene = store.scene(row["scene_hash"])
        return scene, [_recorded(store, row, scene)]
    if len(keys) > 1:
        raise ViewInputError("run", run_or_scene, f"{len(keys)} run keys start with it")
    rows = frame[frame["scene_name"] == run_or_scene]
    if not len(rows):
        names = ", ".join(sorted(frame["scene_name"].unique()))
        raise ViewInputError("run or scene", run_or_scene,
                             f"no run key or scene of that name in the store (scenes: {names})")
    latest = rows.iloc[-1]["scene_hash"]
    rows = rows[(rows["scene_hash"] == latest) & rows["status"].isin(PLAYABLE)
                & (rows["trajectory"].fillna("") != "")]
    scene = store.scene(latest)
    wanted = list(labels) or sorted(rows["label"].unique(),
                                    key=lambda label: (not label.startswith("reference["),
                                                       label))
    chosen = []
    for wanted_label in wanted:
        mine = rows[(rows["label"] == wanted_label) | (rows["engine"] == wanted_label)]
        if not len(mine):
            raise ViewInputError("--engines", wanted_label,
                                 f"no run of {run_or_scene} with a recording in the store")
        for _, group in mine.groupby("label", sort=True):
            steps = group["time_step"].astype(float)
            if time_step is None:
                index = steps.idxmin()
            else:
                index = np.abs(np.log(steps / time_step)).idxmin()
            chosen.append(group.loc[index].to_dict())
    return scene, [_recorded(store, row, scene) for row in chosen]


def first_events(runs: Sequence[RecordedRun]) -> list[Event]:
    """The first run's events that happened (the snapshots' instants)."""
    if not runs:
        return []
    return [Event(name, time, runs[0].label.split(" dt ")[0])
            for name, time in runs[0].events.items() if math.isfinite(time)]
