"""The Siconos engine: the study's own software (Debian python3-siconos 4.4) as a second
nonsmooth engine.

Siconos imports only under /usr/bin/python3 with Debian's numpy and a clean environment, so
every run goes through a worker process (:mod:`.worker.engine`, started by
:func:`~.run.run_worker`): this side sends the scene (JSON, clearance joints
expanded) and the settings, the worker builds the model with the kernel API and returns the
common trajectory as .npz. A crash or a hang of the worker is a recorded outcome (CRASHED /
TIMED_OUT), never an exception.

Presets (each a separate engine variant ``siconos[preset]`` in results):

- ``default``: ``MoreauJeanOSI`` with theta = 1/2, no projection; ``FrictionContact`` solved by
  NSGS, or ``GenericMechanical`` (NSGS, local contact solver NSN_GP_HYBRID) when the scene
  has ideal joints; tolerance 1e-10 on Siconos's
  normalised residual; contacts activate when y + h/2 y' <= 1e-10 x the smallest feature.
- ``projection``: the same with the combined projection scheme
  (``MoreauJeanCombinedProjectionOSI`` + ``TimeSteppingCombinedProjection``; enumerative MLCP
  projection on the active set, tolerance 1e-8 x the scene's smallest feature length). It
  refuses pairs that drop candidates (bores): see
  :data:`.capabilities.PROJECTION_DROPPED_SLOTS`.
- ``nsn-ac``: as ``default`` with the semismooth Newton (Alart-Curnier) fc3d solver; scenes
  with ideal joints use ``GenericMechanical``, whose only solver is NSGS over its blocks, with
  the Alart-Curnier Newton (``ONECONTACT_NSN``) as the local solver of each contact block.

Options (``RunSettings.options``) override: ``theta``, ``projection``, ``solver`` ("nsgs" /
``"nsn-ac"``), ``tolerance``, ``max_iterations``, ``newton_iterations``, ``newton_tolerance``,
``activation_threshold`` [L], ``constraint_tolerance`` [L], ``projection_max_iterations``,
``projection_solver`` ("enum" or "pgs"), ``gmp_reduction`` ("auto": "gs" for closed loops,
else "assemble"; or "gs", "substitute", "assemble", "mlcp": GenericMechanical's handling of
equality rows), ``contact_frame`` ("shared", or
"siconos-builtin": Siconos 4.4's own contact Jacobian, whose first tangent is not orthogonal to
the normal when n_z dominates and n_x != n_y; kept to document that bug), ``timeout`` [s] of
the worker process and ``fault`` (fault injection for tests: "segfault", "hang", "exception").

Presets and options: :mod:`.settings`. Approximations, stated per feature by
:mod:`.capabilities`: springs and law
loads are explicit forces (no stiffness Jacobian); rotation drivers prescribe the body-axis
angular velocity aligned with the driven world axis at t = 0; position drivers are imposed
through their rate.
Unsupported: box-box and capsule-capsule pairs (their candidate count changes with the
configuration; see :mod:`.worker.geometry`), and any feature the adapter does not know.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from clearbench.adapters.base import ModuleEngine, RunSettings
from clearbench.adapters.siconos import HARNESS_DEFAULTS, capabilities
from clearbench.adapters.siconos.run import (
    WorkerStatus,
    run_worker,
)
from clearbench.adapters.siconos.settings import (
    OPTIONS,
    PRESETS,
    resolve_options,
    resolve_settings,
)
from clearbench.adapters.trajectory import RunStatus, Trajectory, scene_fields
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.serialization import scene_to_json

WORKER_SCRIPT = Path(__file__).parent / "worker" / "engine.py"

def create(preset: str = "default") -> SiconosEngine:
    return SiconosEngine(preset)


class SiconosEngine(ModuleEngine):
    """Siconos 4.4 kernel (Moreau-Jean, fc3d / GenericMechanical) in a worker process."""

    name = "siconos"
    RIGID_CONTACTS = HARNESS_DEFAULTS.rigid_contacts
    PRESETS = PRESETS
    OPTIONS = OPTIONS
    CAPABILITIES = capabilities
    RESOLVE_SETTINGS = staticmethod(resolve_settings)

    def resolve_run_settings(self, scene: Scene, settings: RunSettings) -> dict:
        """The settings of a run of ``scene``: :func:`~.settings.resolve_options`."""
        return resolve_options(self.preset, scene, settings.options)

    # ------------------------------------------------------------------ run
    def _run(self, scene: Scene, settings: RunSettings) -> Trajectory:
        options = self.resolve_run_settings(scene, settings)
        h = settings.time_step or scene.time_step
        horizon = settings.horizon or scene.horizon
        worker_settings = {key: options[key] for key in options if key != "timeout"}
        worker_settings.update(time_step=h, horizon=horizon, record_every=settings.record_every)
        inputs = {"scene_json": np.array(scene_to_json(scene.expanded, indent=None)),
                  "settings_json": np.array(json.dumps(worker_settings))}
        outcome = run_worker(WORKER_SCRIPT, inputs, timeout=float(options["timeout"]))
        metadata = {"worker_process_seconds": outcome.process_time, **{
            k: options[k] for k in ("theta", "projection", "solver", "tolerance")}}
        if outcome.status is WorkerStatus.UNAVAILABLE:
            return Trajectory.empty(self.name, self.preset, scene, RunStatus.UNSUPPORTED,
                                    outcome.message, h, metadata)
        if outcome.status is WorkerStatus.TIMED_OUT:
            return Trajectory.empty(self.name, self.preset, scene, RunStatus.TIMED_OUT,
                                    f"Siconos worker timed out: {outcome.message}", h, metadata)
        if outcome.status is WorkerStatus.CRASHED:
            return Trajectory.empty(self.name, self.preset, scene, RunStatus.CRASHED,
                                    f"Siconos worker died: {outcome.message}", h, metadata)
        if outcome.status is WorkerStatus.FAILED:
            last = (outcome.message.strip().splitlines() or ["no message"])[-1]
            return Trajectory.empty(self.name, self.preset, scene, RunStatus.CRASHED,
                                    f"Siconos worker raised: {last}", h,
                                    {**metadata, "traceback": outcome.message})
        return self._trajectory(scene, h, outcome, metadata)

    def _trajectory(self, scene: Scene, h: float, outcome, metadata: dict) -> Trajectory:
        data = outcome.outputs
        status = {"ok": RunStatus.OK, "diverged": RunStatus.DIVERGED,
                  "failed": RunStatus.CRASHED}[str(data["status"])]
        metadata.update(json.loads(str(data["metadata_json"])))
        arrays = {name: np.asarray(data[name]) for name in Trajectory.ARRAYS}
        arrays["solver_iterations"] = arrays["solver_iterations"].astype(np.int64)
        arrays["active_contacts"] = arrays["active_contacts"].astype(np.int64)
        arrays["solver_converged"] = arrays["solver_converged"].astype(bool)
        for name in ("times", "positions", "orientations", "velocities", "angular_velocities",
                     "contact_normal_force", "contact_force", "solver_residual"):
            arrays[name] = arrays[name].astype(np.float64)
        return Trajectory(
            engine=self.name, preset=self.preset, **scene_fields(scene), time_step=h, **arrays,
            build_seconds=float(data["build_seconds"]),
            stepping_seconds=float(data["stepping_seconds"]), steps=int(data["steps"]),
            status=status, message=str(data["message"]),
            unconverged_steps=tuple(metadata.pop("unconverged_steps", ())),
            unconverged_count=int(metadata.pop("unconverged_count", 0)),
            internal_units=scene.units.describe(), metadata=metadata,
        )

