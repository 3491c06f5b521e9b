"""The Siconos engine: the study's own software (Debian python3-siconos 4.4) as a second
nonsmooth engine.

Siconos imports only under /usr/bin/python3 with Debian's numpy and a clean environment, so
every run goes through a worker process (:mod:`.worker.engine`, started by
:func:`~.process.run_worker`): this side sends the scene (JSON, clearance joints
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
  refuses pairs that drop candidates (bounded faces, bores): see PROJECTION_DROPPED_SLOTS.
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

Approximations, stated per feature by :meth:`SiconosEngine.capabilities`: springs and law
loads are explicit forces (no stiffness Jacobian); rotation drivers prescribe the body-axis
angular velocity aligned with the driven world axis at t = 0; position drivers are imposed
through their rate.
Unsupported: box-box and capsule-capsule pairs (their candidate count changes with the
configuration; see :mod:`.worker.geometry`), and any feature the adapter does not know.
"""

from __future__ import annotations

import functools
import json
import subprocess
from pathlib import Path

import numpy as np

from clearbench.adapters.base import Capability, Engine, RunSettings, Support
from clearbench.adapters.options import OptionTable, boolean, choice, integer, number
from clearbench.adapters.siconos.process import (
    SICONOS_PYTHON,
    WorkerStatus,
    interpreter_imports,
    run_worker,
)
from clearbench.adapters.siconos.worker import geometry as worker_geometry
from clearbench.adapters.trajectory import RunStatus, Trajectory, scene_fields
from clearbench.kernels.quaternion import quat_normalize, quat_to_matrix
from clearbench.scenarios.scales import feature_lengths
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.serialization import scene_to_json

WORKER_SCRIPT = Path(__file__).parent / "worker" / "engine.py"

PRESETS: dict[str, dict] = {
    "default": {"theta": 0.5, "projection": False, "solver": "nsgs"},
    "projection": {"theta": 0.5, "projection": True, "solver": "nsgs"},
    "nsn-ac": {"theta": 0.5, "projection": False, "solver": "nsn-ac"},
}
#: Defaults of the options every preset shares.
DEFAULTS: dict = {
    "tolerance": 1e-10,
    "max_iterations": 10_000,
    "newton_iterations": 50,     # Siconos's default
    "newton_tolerance": 1e-6,    # Siconos's default
    "projection_max_iterations": 50,
    "projection_solver": "enum",
    "contact_frame": "shared",
    # GenericMechanical's handling of equality rows (iparam ISREDUCED), see resolved_options.
    "gmp_reduction": "auto",
    "timeout": 3600.0,
    "fault": "",
}
SOLVERS = ("nsgs", "nsn-ac")
CONTACT_FRAMES = ("shared", "siconos-builtin")
PROJECTION_SOLVERS = ("enum", "pgs")
FAULTS = ("", "segfault", "hang", "exception")
GMP_REDUCTIONS = ("auto", "gs", "substitute", "assemble", "mlcp")
#: Type, range and allowed values of every option (lengths [L] in the scene's unit; theta: the
#: theta-method in (0, 1]; tolerance: Siconos's normalised residual; timeout [s]).
OPTIONS = OptionTable("siconos", (
    number("theta", above=0.0, at_most=1.0),
    boolean("projection"),
    choice("solver", SOLVERS),
    number("tolerance", above=0.0),
    integer("max_iterations", at_least=1),
    integer("newton_iterations", at_least=1),
    number("newton_tolerance", above=0.0),
    integer("projection_max_iterations", at_least=1),
    choice("projection_solver", PROJECTION_SOLVERS),
    choice("contact_frame", CONTACT_FRAMES),
    choice("gmp_reduction", GMP_REDUCTIONS),
    number("timeout", above=0.0),
    choice("fault", FAULTS),
    number("constraint_tolerance", above=0.0),
    number("activation_threshold", at_least=0.0),
))
OPTION_NAMES = OPTIONS.names

_JOINT_CLASSES = {"revolute": "PivotJointR", "spherical": "KneeJointR",
                  "prismatic": "PrismaticJointR", "fixed": "FixedJointR"}


#: Features the worker handles exactly (within the nonsmooth time stepping), with how.
_NATIVE_FEATURES = {
    "gravity": "constant force in computeFExt",
    "contacts": "one NewtonImpactFrictionNSL interaction per candidate, exact (nonsmooth)",
    "friction": "Coulomb cone of NewtonImpactFrictionNSL, exact (nonsmooth)",
    "restitution": "Newton impact law of NewtonImpactFrictionNSL",
    "rings": "ring geometry of the shared kernels",
    "arcs": "arc geometry of the shared kernels",
    "clearance_joints": "expanded into their contact pairs (shared expansion)",
    "closed_loop": "GenericMechanical with Gauss-Seidel over all blocks (redundant joint rows)",
    "point_forces": "computeFExt / computeMExt at the step ends (theta-weighted)",
    "moments": "computeMExt at the step ends (theta-weighted)",
    "time_switched_loads": "switch tested at the times Moreau-Jean evaluates the loads (the "
                           "step ends): resolved to one step",
    "fixed_bodies": "no dynamical system (contacts with one dynamical system)",
}
#: Configuration-dependent forces applied explicitly, with what they are.
_EXPLICIT_FORCES = {
    "springs": "force",
    "torsional_springs": "moment",
    "angle_law_loads": "law scalar (scenarios.loads.AngleLawLoad) and its applications",
    "distance_law_loads": "law scalar (scenarios.loads.DistanceLawLoad) and its applications",
}


#: Why the combined projection cannot take pairs that drop candidates.
PROJECTION_DROPPED_SLOTS = (
    "TimeSteppingCombinedProjection projects the active contacts with a positive reaction "
    "(index set 2) as equalities (it iterates while |y| >= tolerance): a candidate dropped "
    "(off a bounded face, outside a bore) while active is pulled back from its inactive gap; "
    "c60-trip diverged at 2.15 ms, the hook and the tripping bar thrown 1e10 mm apart")


def _pair_capability(kind_a: str, kind_b: str, projection: bool = False) -> Capability:
    reason = worker_geometry.unsupported_reason(kind_a, kind_b)
    if reason:
        return Capability(Support.UNSUPPORTED, reason)
    if projection and worker_geometry.drops_candidates(kind_a, kind_b):
        return Capability(Support.UNSUPPORTED, PROJECTION_DROPPED_SLOTS)
    detail = ("Python NewtonEuler3DR relation with the shared closed-form gap, points and "
              "contact frame")
    if worker_geometry.drops_candidates(kind_a, kind_b):
        detail += ("; one interaction per candidate slot, a slot the face or bore drops is "
                   f"handed the gap {worker_geometry.DROPPED_GAP:g} (inactive) until "
                   "the candidate returns")
    return Capability(Support.NATIVE, detail)


@functools.cache
def availability() -> tuple[bool, str]:
    """Whether Debian's interpreter imports the Siconos kernel and joints (never raises)."""
    available, why = interpreter_imports(
        "siconos.kernel, siconos.mechanics.joints, siconos.numerics")
    if not available:
        return False, why
    try:
        version = subprocess.run(
            ["dpkg-query", "-W", "-f=${Version}", "python3-siconos"],
            capture_output=True, text=True, timeout=30).stdout.strip()
    except (OSError, subprocess.TimeoutExpired):
        version = ""
    return True, f"Debian python3-siconos {version}".strip() + f" under {SICONOS_PYTHON}"


def create(preset: str = "default") -> SiconosEngine:
    return SiconosEngine(preset)


class SiconosEngine(Engine):
    """Siconos 4.4 kernel (Moreau-Jean, fc3d / GenericMechanical) in a worker process."""

    name = "siconos"
    RIGID_CONTACTS = True
    PRESETS = PRESETS
    OPTIONS = OPTIONS

    # ------------------------------------------------------------------ capabilities
    def plain_capability(self, context, name: str) -> Capability | None:
        if name in _EXPLICIT_FORCES:
            return Capability(
                Support.APPROXIMATED, _EXPLICIT_FORCES[name] + " from the current "
                "iterate in computeFExt / computeMExt, theta-weighted by Moreau-Jean "
                "without a stiffness Jacobian: stable only for h < 2 / omega of the "
                "stiffest spring")
        if name == "drivers":
            return self._driver_capability(context.scene)
        if name == "ideal_joints":
            return Capability(
                Support.NATIVE, "Siconos joint relations at velocity level; position drift "
                "corrected only by the projection preset")
        if name in _NATIVE_FEATURES:
            return Capability(Support.NATIVE, _NATIVE_FEATURES[name])
        return None

    def shape_capability(self, context, kind: str) -> Capability | None:
        if kind in worker_geometry.SHAPE_KINDS:
            return Capability(Support.NATIVE, "shared closed-form geometry")
        return None

    def joint_capability(self, context, kind: str) -> Capability | None:
        if kind in _JOINT_CLASSES:
            return Capability(Support.NATIVE, f"{_JOINT_CLASSES[kind]} + EqualityConditionNSL")
        return None

    def pair_capability(self, context, kind_a: str, kind_b: str) -> Capability | None:
        known = worker_geometry.SHAPE_KINDS
        if kind_a not in known or kind_b not in known:
            return None
        # The preset's projection, or the run option's.
        projection = bool({**PRESETS[self.preset], **context.options}["projection"])
        return _pair_capability(kind_a, kind_b, projection)

    @staticmethod
    def _driver_capability(scene: Scene) -> Capability:
        notes, problems = [], []
        for driver in scene.drivers:
            if driver.quantity == "position":
                notes.append(f"{driver.name}: position profile imposed through its rate")
            if driver.is_rotation:
                body = scene.body(driver.body)
                rotation = quat_to_matrix(quat_normalize(np.asarray(body.orientation, float)))
                alignment = rotation[driver.axis_index, :]
                if abs(np.max(np.abs(alignment)) - 1.0) > 1e-9:
                    problems.append(f"{driver.name}: no axis of body {driver.body!r} is aligned "
                                    f"with world {driver.component[-1]} at t = 0 (Siconos "
                                    "prescribes body-axis angular velocities)")
                else:
                    notes.append(f"{driver.name}: body-axis angular velocity aligned with "
                                 f"world {driver.component[-1]} at t = 0 (exact while a joint "
                                 "keeps that axis fixed)")
        if problems:
            return Capability(Support.UNSUPPORTED, "; ".join(problems))
        if notes:
            return Capability(Support.APPROXIMATED,
                              "BoundaryCondition on the twist; " + "; ".join(notes))
        return Capability(Support.NATIVE, "BoundaryCondition on the twist (prescribed velocity)")

    # ------------------------------------------------------------------ settings
    def resolved_options(self, scene: Scene, settings: RunSettings) -> dict:
        """Preset + defaults + ``settings.options`` (checked against :data:`OPTIONS`)."""
        self.check_options(settings.options)
        options = dict(DEFAULTS)
        options.update(PRESETS[self.preset])
        options.update(settings.options)
        lengths = feature_lengths(scene)
        smallest = min(lengths) if lengths else 1.0
        # 1e-8 of the smallest feature (docs/engines/siconos.md: about 1e-8 works): far
        # below what the metrics resolve, far enough above round-off that the projection loop
        # terminates.
        options.setdefault("constraint_tolerance", 1e-8 * smallest)
        # MoreauJeanOSI activates a contact when y + h/2 y' <= threshold; Siconos's 0 lets a
        # resting contact flicker off on round-off (a box resting on a plane then rocks and
        # sinks 14 um at the first steps); 1e-10 of the smallest feature, as the reference's
        # activation margin, removes that and is far below any gap the metrics resolve.
        options.setdefault("activation_threshold", 1e-10 * smallest)
        if options["gmp_reduction"] == "auto":
            # Assembling the equality rows with the contacts converged in one sweep on the
            # Flores slider, where Gauss-Seidel over all blocks (Siconos's default) needed 10^4
            # sweeps per step and stalled at 1e-7 (joint rows redundant with guide contacts);
            # but an assembled system with redundant joint rows (a planar closed loop rebuilt
            # in 3D) is singular: the slider-crank aborted on NaN. Gauss-Seidel there.
            options["gmp_reduction"] = "gs" if "closed_loop" in scene.features else "assemble"
        return options

    # ------------------------------------------------------------------ run
    def _run(self, scene: Scene, settings: RunSettings) -> Trajectory:
        options = self.resolved_options(scene, settings)
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
            status=status, message=str(data["message"]), metadata=metadata,
        )

