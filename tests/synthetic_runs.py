"""Synthetic recordings for the report's tests: a trajectory from given poses and forces, and
c60-trip runs whose moving bodies turn about z at their own pace (the viewer's worst case)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from clearbench.adapters.trajectory import RunStatus, Trajectory
from clearbench.harness.report.viewer.frames import RecordedRun
from clearbench.kernels.quaternion import quat_from_axis_angle_batch, quat_multiply_batch
from clearbench.scenarios.bodies import Motion
from clearbench.scenarios.c60 import model
from clearbench.scenarios.scene import Scene

#: The synthetic trip's events [ms] (the forces of :func:`trip_forces` switch at them).
TRIP_EVENTS = {"strike": 3.1, "release": 6.8, "opening": 7.6}


def synthetic_trajectory(scene: Scene, times, positions, orientations, normal=None, force=None,
                         status=RunStatus.OK) -> Trajectory:
    """A trajectory of ``scene`` with the given samples (T,), poses (T, nb, 3) and (T, nb, 4)
    and contact normal forces (T, nc) and force vectors (T, nc, 3) (zero when None)."""
    empty = Trajectory.empty("test", "default", scene, status, "", time_step=float(
        times[1] - times[0]))
    count = len(times)
    nc = len(scene.all_contacts)
    return dataclasses.replace(
        empty, times=np.asarray(times, dtype=float), positions=positions,
        orientations=orientations, velocities=np.zeros_like(positions),
        angular_velocities=np.zeros_like(positions),
        contact_normal_force=np.zeros((count, nc)) if normal is None else normal,
        contact_force=np.zeros((count, nc, 3)) if force is None else force,
        solver_iterations=np.zeros(count, dtype=np.int64), solver_residual=np.zeros(count),
        solver_converged=np.ones(count, dtype=bool), active_contacts=np.zeros(count,
                                                                             dtype=np.int64))


def trip_forces(scene: Scene, times: np.ndarray) -> np.ndarray:
    """Normal forces (T, nc) [N] of a trip at :data:`TRIP_EVENTS`: the trip contacts loaded
    from the strike, the latch (C4, C5) until the release, C7 until the opening, every other
    pair at 1 N throughout."""
    normal = np.ones((len(times), len(scene.all_contacts)))
    for j, contact in enumerate(scene.all_contacts):
        if contact.name.startswith("TRIP_"):
            normal[:, j] = times >= TRIP_EVENTS["strike"]
        elif contact.name.startswith(("Hook_Tbar_C4", "Tbar_Hook_C5")):
            normal[:, j] = times < TRIP_EVENTS["release"]
        elif contact.name == model.C7:
            normal[:, j] = times < TRIP_EVENTS["opening"]
    return normal


def c60_runs(scene: Scene, count: int, samples: int = 851, trip: bool = False
             ) -> list[RecordedRun]:
    """``count`` synthetic c60-trip runs (``samples`` over 8.5 ms): every moving body turning
    about z by up to 20 degrees at its own pace; every contact pair carrying force in every
    sample (the worst case for the page's size), or with ``trip`` the forces of
    :func:`trip_forces`."""
    times = np.linspace(0.0, 8.5, samples)
    nb = len(scene.bodies)
    runs = []
    for k in range(count):
        positions = np.tile(np.array([b.position for b in scene.bodies]), (samples, 1, 1))
        start = np.array([b.orientation for b in scene.bodies])
        orientations = np.empty((samples, nb, 4))
        for i, body in enumerate(scene.bodies):
            angle = (0.0 if body.motion is Motion.FIXED else
                     math.radians(20) * np.sin(times * (1 + 0.3 * i + 0.1 * k)))
            turn = quat_from_axis_angle_batch(np.tile([0.0, 0.0, 1.0], (samples, 1)),
                                              angle * np.ones(samples))
            orientations[:, i] = quat_multiply_batch(turn, np.tile(start[i], (samples, 1)))
        normal = (trip_forces(scene, times) if trip else
                  1.0 + np.abs(np.sin(times[:, None] + np.arange(len(scene.all_contacts)))))
        runs.append(RecordedRun(f"engine{k}[default] dt 0.001 ms",
                                synthetic_trajectory(scene, times, positions, orientations,
                                                     normal),
                                events=dict(TRIP_EVENTS)))
    return runs
