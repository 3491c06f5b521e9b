"""A tiny engine following the adapter contract, for the harness tests: a bare
:class:`~clearbench.adapters.base.Engine` on purpose, not the template of a new engine (that is
:class:`~clearbench.adapters.base.SteppingEngine`, followed by ``tests/toy_engine``): the
shared step loop's guards would catch its misbehaviour themselves, while the harness must catch
an engine that crashes, hangs or returns NaN with an ok status on its own.

It integrates free flight only (gravity, constant angular velocity; contacts and joints ignored)
with the symplectic Euler method, so its error against the exact ballistic motion is O(dt).
Presets misbehave on purpose:

- ``default``: free flight as above;
- ``segfault``: the process kills itself with SIGSEGV;
- ``hang``: never returns;
- ``nan``: positions become NaN halfway, status still OK (the harness must catch it);
- ``raise``: raises RuntimeError;
- ``energy``: velocities grow 1 % per step, status OK (energy growth must be caught).

Options: ``sleep`` (seconds to sleep before running), ``bias`` (every recorded z drifts up at
this rate [L/T], velocities untouched: a position error that grows with time). The
environment variable ``CLEARBENCH_FAKE_BIAS`` adds to ``bias`` (to inject a regression without
touching a suite definition), and ``CLEARBENCH_FAKE_NAN`` (non-empty) makes every preset behave
as ``nan``. Clearance joints are reported unsupported.
"""

from __future__ import annotations

import math
import os
import signal
import time

import numpy as np

from clearbench.adapters.base import Capability, Engine, RunSettings, Support
from clearbench.adapters.options import OptionTable, number
from clearbench.adapters.recording import record_schedule, step_count
from clearbench.adapters.trajectory import RunStatus, Trajectory, scene_fields
from clearbench.scenarios.bodies import Motion
from clearbench.scenarios.features import PLAIN_FEATURES

PRESETS = {"default": {}, "segfault": {}, "hang": {}, "nan": {}, "raise": {}, "energy": {}}
OPTIONS = OptionTable("fake", (number("sleep", at_least=0.0), number("bias")))


def availability() -> tuple[bool, str]:
    return True, "fake engine for tests 1.0"


def create(preset: str = "default") -> FakeEngine:
    return FakeEngine(preset)


def _quat_multiply(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    w1, v1 = p[0], p[1:]
    w2, v2 = q[0], q[1:]
    return np.concatenate(([w1 * w2 - v1 @ v2], w1 * v2 + w2 * v1 + np.cross(v1, v2)))


def _quat_exp(rotation: np.ndarray) -> np.ndarray:
    angle = float(np.linalg.norm(rotation))
    if angle == 0.0:
        return np.array([1.0, 0.0, 0.0, 0.0])
    return np.concatenate(([math.cos(angle / 2)], math.sin(angle / 2) * rotation / angle))


class FakeEngine(Engine):
    """Knows every feature of the vocabulary: clearance joints unsupported, contacts and
    ideal joints ignored, the rest 'native' (free flight does not look at them)."""

    name = "fake"
    PRESETS = PRESETS
    OPTIONS = OPTIONS

    def plain_capability(self, context, name: str) -> Capability | None:
        if name == "clearance_joints":
            return Capability(Support.UNSUPPORTED, "fake engine has no clearances")
        if name in ("contacts", "ideal_joints"):
            return Capability(Support.APPROXIMATED, "ignored (free flight only)")
        return Capability(Support.NATIVE, "") if name in PLAIN_FEATURES else None

    def shape_capability(self, context, kind: str) -> Capability | None:
        return Capability(Support.NATIVE, "")

    def joint_capability(self, context, kind: str) -> Capability | None:
        return Capability(Support.NATIVE, "")

    def pair_capability(self, context, kind_a: str, kind_b: str) -> Capability | None:
        return Capability(Support.NATIVE, "")

    def _run(self, scene, settings: RunSettings) -> Trajectory:
        options = settings.options
        time.sleep(float(options.get("sleep", 0.0)))
        if self.preset == "segfault":
            os.kill(os.getpid(), signal.SIGSEGV)
        if self.preset == "hang":
            while True:
                time.sleep(0.05)
        if self.preset == "raise":
            raise RuntimeError("fake engine failure")
        bias = float(options.get("bias", 0.0)) + float(os.environ.get("CLEARBENCH_FAKE_BIAS", 0))
        built = time.perf_counter()
        h = settings.time_step or scene.time_step
        horizon = settings.horizon or scene.horizon
        steps = step_count(horizon, h)
        record = record_schedule(steps, settings.record_every)
        nb = len(scene.bodies)
        free = np.array([b.motion is not Motion.FIXED for b in scene.bodies])
        x = np.array([b.position for b in scene.bodies], dtype=float)
        q = np.array([b.orientation for b in scene.bodies], dtype=float)
        v = np.array([b.velocity for b in scene.bodies], dtype=float) * free[:, None]
        w = np.array([b.angular_velocity for b in scene.bodies], dtype=float) * free[:, None]
        g = np.asarray(scene.gravity, dtype=float)
        count = len(record)
        nc = len(scene.all_contacts)
        out = {
            "positions": np.zeros((count, nb, 3)), "orientations": np.zeros((count, nb, 4)),
            "velocities": np.zeros((count, nb, 3)), "angular_velocities": np.zeros((count, nb, 3)),
        }
        start = time.perf_counter()
        slot = 0
        for k in range(steps + 1):
            if k > 0:
                v = v + h * g * free[:, None]
                if self.preset == "energy":
                    v = v * 1.01
                x = x + h * v
                for b in np.nonzero(free)[0]:
                    q[b] = _quat_multiply(q[b], _quat_exp(h * w[b]))
            if slot < count and k == record[slot]:
                out["positions"][slot] = x
                out["positions"][slot, :, 2] += bias * k * h
                out["orientations"][slot] = q
                out["velocities"][slot] = v
                out["angular_velocities"][slot] = w
                slot += 1
        stepping = time.perf_counter() - start
        if self.preset == "nan" or os.environ.get("CLEARBENCH_FAKE_NAN"):
            out["positions"][count // 2:] = np.nan
        return Trajectory(
            engine=self.name, preset=self.preset, **scene_fields(scene), time_step=h,
            times=np.array(record, dtype=float) * h,
            contact_normal_force=np.zeros((count, nc)), contact_force=np.zeros((count, nc, 3)),
            solver_iterations=np.zeros(count, dtype=np.int64), solver_residual=np.zeros(count),
            solver_converged=np.ones(count, dtype=bool),
            active_contacts=np.zeros(count, dtype=np.int64),
            build_seconds=start - built, stepping_seconds=stepping, steps=steps,
            status=RunStatus.OK, **out,
        )
