"""Cached reference-engine runs of the C-60 scenes, shared by the validation and the
identification study: a run's trajectory file is reused when its scene (which records the
model variant), the preset and the physics code are this run's."""

from __future__ import annotations

import functools
import logging
import time
from dataclasses import dataclass
from pathlib import Path

import clearbench
from clearbench.adapters.base import RunSettings
from clearbench.adapters.reference import create
from clearbench.adapters.trajectory import Trajectory
from clearbench.harness.measure import series as metrics
from clearbench.scenarios.library import get_scene
from clearbench.scenarios.scene import Scene

logger = logging.getLogger(__name__)


@dataclass(frozen=True)
class Run:
    """One cached run: the scene, its trajectory, and how long stepping took [s]."""

    key: str
    scene: Scene
    trajectory: Trajectory

    @property
    def unconverged(self) -> list:
        return list(self.trajectory.unconverged_steps)

    @functools.cached_property
    def penetration(self) -> float:
        """Largest contact penetration over the recorded states [mm] (computed once)."""
        depth = metrics.penetration(self.scene, self.trajectory)
        return float(depth.max()) if depth.size else 0.0


def run_scene(key: str, name: str, parameters: dict, cache: Path | None, preset: str = "default",
              record_every: int = 10, run_missing: bool = True) -> Run | None:
    """Run a registered scene with the reference engine, or read it back from ``cache``: a
    cached run is reused when its scene, preset and physics code (the sources of the scenes,
    the solver and the adapters, :data:`PHYSICS_CODE`) are this run's. With ``run_missing``
    False a run not in the cache is not made: None."""
    scene = get_scene(name, **parameters)
    code = clearbench.source_digest(PHYSICS_CODE)
    path = cache / f"{key}.npz" if cache is not None else None
    if path is not None and path.exists():
        trajectory = Trajectory.load(path)
        if (trajectory.scene_hash == scene.content_hash and trajectory.preset == preset
                and trajectory.metadata.get("physics_code") == code):
            logger.info("%s: read from %s", key, path)
            return Run(key, scene, trajectory)
    if not run_missing:
        return None
    logger.info("%s: running %s %s (%s steps)", key, name, parameters,
                round(scene.horizon / scene.time_step))
    tick = time.perf_counter()
    trajectory = create(preset).run(scene, RunSettings(record_every=record_every))
    logger.info("%s: %.0f s", key, time.perf_counter() - tick)
    trajectory.metadata["physics_code"] = code
    if path is not None:
        path.parent.mkdir(parents=True, exist_ok=True)
        trajectory.save(path)
    return Run(key, scene, trajectory)


#: The subpackages whose sources decide a cached run's trajectory.
PHYSICS_CODE = ("clearbench.kernels", "clearbench.scenarios", "clearbench.ref_solver",
                "clearbench.adapters")
