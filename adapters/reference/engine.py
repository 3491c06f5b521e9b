"""The reference engine: our nonsmooth Moreau–Jean solver with the combined projection.

Presets (each a separate engine variant in results):

- ``default``: theta = 1/2, combined projection on, NSGS with exact Alart–Curnier local solves
  switching to the semismooth Newton solver when NSGS stalls (``hybrid``), tolerance 1e-12
  (|F| / max(|q|, |r|, |u|)), impacts with e > 0 localised at their crossing time.
- ``no-projection``: plain Moreau–Jean (Moreau's activation g + h/2 u_N <= 0), no impact
  localisation (it needs the activation loop of the projection).
- ``newton``: as default with the semismooth Newton one-step solver.
- ``implicit``: theta = 1 (more dissipative, unconditionally stable for stiff springs).

Options (``RunSettings.options``) override: ``theta``, ``projection``, ``method``,
``tolerance``, ``max_iterations``, ``position_tolerance``, ``restitution_threshold`` (default
2 |g| h: slower impacts are plastic), ``joint_law`` (``midpoint`` or ``end``),
``localise_impacts`` (true or false; every preset with the projection has it on: an impact
with e > 0 is applied at its crossing time within the step instead of over the whole step,
which takes the bouncing-ball apex errors at h = 1e-3 s from 8e-3 to 2e-5); see
:class:`~clearbench.ref_solver.stepper.StepperSettings`.
The metadata of a run counts the ``split_steps`` (steps computed in substeps).
"""

from __future__ import annotations

import math
import time

import numpy as np

from clearbench.adapters.base import Capability, Engine, RunSettings, Support
from clearbench.adapters.trajectory import RunStatus, Trajectory
from clearbench.kernels.quaternion import quat_rotate_batch
from clearbench.ref_solver.contact_problem import SolverOptions
from clearbench.ref_solver.scene_system import build_system, initial_state
from clearbench.ref_solver.stepper import MoreauJeanStepper, StepperSettings
from clearbench.scenarios.scales import feature_lengths
from clearbench.scenarios.scene import Scene

PRESETS: dict[str, dict] = {
    "default": {"theta": 0.5, "projection": True, "method": "hybrid", "localise_impacts": True},
    "no-projection": {"theta": 0.5, "projection": False, "method": "hybrid",
                      "localise_impacts": False},
    "nsgs": {"theta": 0.5, "projection": True, "method": "nsgs", "localise_impacts": True},
    "newton": {"theta": 0.5, "projection": True, "method": "newton", "localise_impacts": True},
    "implicit": {"theta": 1.0, "projection": True, "method": "hybrid", "localise_impacts": True},
}
OPTION_NAMES = ("theta", "projection", "method", "tolerance", "max_iterations",
                "position_tolerance", "restitution_threshold", "joint_law", "localise_impacts",
                "roundoff_floor")


def availability() -> tuple[bool, str]:
    import clearbench

    return True, f"built in (clearbench {clearbench.__version__})"


def create(preset: str = "default") -> ReferenceEngine:
    return ReferenceEngine(preset)


class ReferenceEngine(Engine):
    """Our nonsmooth reference solver (see :mod:`clearbench.ref_solver.stepper`)."""

    name = "reference"

    def __init__(self, preset: str = "default"):
        if preset not in PRESETS:
            raise ValueError(f"unknown reference preset {preset!r}; presets: {list(PRESETS)}")
        self.preset = preset

    def capabilities(self, scene: Scene) -> dict[str, Capability]:
        from clearbench.scenarios.geometry import supported_pair

        out = {}
        for feature in scene.features:
            if feature.startswith("pair:"):
                a, b = feature[5:].split("-")
                ok = supported_pair(a, b)
                out[feature] = Capability(
                    Support.NATIVE if ok else Support.UNSUPPORTED,
                    "closed-form gap" if ok else f"no gap function for {a} against {b}")
            else:
                out[feature] = Capability(Support.NATIVE, "exact (nonsmooth)")
        return out

    def stepper_settings(self, scene: Scene, settings: RunSettings) -> StepperSettings:
        """Preset + options, with tolerances relative to the scene's smallest feature."""
        options = dict(PRESETS[self.preset])
        unknown = sorted(set(settings.options) - set(OPTION_NAMES))
        if unknown:
            raise ValueError(f"unknown reference options {unknown}; options: {OPTION_NAMES}")
        for flag in ("localise_impacts", "roundoff_floor"):
            value = settings.options.get(flag)
            if value is not None and not isinstance(value, bool):
                raise ValueError(f"reference option {flag} must be true or false, got "
                                 f"{value!r}")
        localise = settings.options.get("localise_impacts")
        options.update(settings.options)
        if localise is None:
            # The preset's choice, where it applies: localisation needs the projection.
            options["localise_impacts"] = options["localise_impacts"] and \
                bool(options["projection"])
        lengths = feature_lengths(scene)
        smallest = min(lengths) if lengths else 1.0
        largest = max(lengths) if lengths else 1.0
        method = options["method"]
        solver = SolverOptions(method="nsgs" if method == "hybrid" else method,
                               tolerance=float(options.get("tolerance", 1e-12)),
                               max_iterations=int(options.get("max_iterations", 10_000)),
                               # a residual below its own rounding error is a solution; on
                               # by default, ``roundoff_floor=false`` asks for the tolerance
                               # alone (fc3d_residual.roundoff_floor)
                               roundoff_floor=bool(options.get("roundoff_floor", True)))
        return StepperSettings(
            time_step=settings.time_step or scene.time_step,
            theta=float(options["theta"]),
            projection=bool(options["projection"]),
            solver=solver,
            # 1e-10 of the smallest feature (a clearance, an offset, a radius): far below
            # anything the metrics resolve, far above round-off of positions.
            position_tolerance=float(options.get("position_tolerance", 1e-10 * smallest)),
            activation_margin=1e-10 * smallest,
            length_scale=largest,
            method=method,
            joint_law=str(options.get("joint_law", "midpoint")),
            localise_impacts=options["localise_impacts"],
            # Bounces slower than two steps' worth of gravity cannot be resolved by the fixed
            # step; they are taken as plastic so that bodies come to rest (see StepperSettings).
            restitution_threshold=float(options.get(
                "restitution_threshold",
                2.0 * float(np.linalg.norm(scene.gravity)) * (settings.time_step
                                                               or scene.time_step))),
        )

    def _run(self, scene: Scene, settings: RunSettings) -> Trajectory:
        start = time.perf_counter()
        system = build_system(scene)
        config = self.stepper_settings(scene, settings)
        stepper = MoreauJeanStepper(system, config)
        state = initial_state(scene)
        # Compile every kernel before the clock starts (numba compiles on first use in a
        # process, or loads its cache): compilation counts as building, not as stepping.
        _warm_up()
        MoreauJeanStepper(system, config).step(state.copy())
        h = config.time_step
        horizon = settings.horizon or scene.horizon
        steps = int(math.ceil(horizon / h - 1e-9))
        record = list(range(0, steps + 1, settings.record_every))
        if record[-1] != steps:
            record.append(steps)
        recorder = _Recorder(scene, system, len(record), h, config.solver.tolerance)
        recorder.store(0, state, None)
        build_seconds = time.perf_counter() - start
        status, message = RunStatus.OK, ""
        next_record = 1
        stepping = 0.0
        taken = 0
        for k in range(1, steps + 1):
            tick = time.perf_counter()
            try:
                result = stepper.step(state)
            except (ArithmeticError, ValueError, np.linalg.LinAlgError) as error:
                # A failure inside a kernel is an outcome of the run: the state the step
                # started from is kept as the last sample, to reproduce it.
                if next_record < len(record):
                    recorder.store(next_record, state, None)
                    next_record += 1
                status = RunStatus.CRASHED
                message = (f"{type(error).__name__} in step {k} (from t = {state.t:.9g}; the "
                           f"last sample is that step's start): {error}")
                break
            finally:
                stepping += time.perf_counter() - tick
            state = result.state
            taken = k
            finite = np.isfinite(state.x).all() and np.isfinite(state.v).all() and \
                np.isfinite(state.omega).all()
            recorder.accumulate(result)
            if next_record < len(record) and (k == record[next_record] or not finite):
                recorder.store(next_record, state, result)
                next_record += 1
            if not finite:
                status, message = RunStatus.DIVERGED, f"non-finite state at step {k}"
                break
        trajectory = recorder.trajectory(next_record)
        trajectory.engine = self.name
        trajectory.preset = self.preset
        trajectory.build_seconds = build_seconds
        trajectory.stepping_seconds = stepping
        trajectory.steps = taken
        trajectory.status = status
        trajectory.message = message
        trajectory.metadata = {
            "theta": config.theta, "projection": config.projection,
            "solver": config.method, "tolerance": config.solver.tolerance,
            "position_tolerance": config.position_tolerance,
            "unconverged_steps": recorder.unconverged,
            "roundoff_steps": recorder.roundoff_steps,
            "unconverged_projections": recorder.unconverged_projection,
            "solver_seconds": recorder.solver_seconds,
            "contact_sweeps": recorder.contact_sweeps,
            "localise_impacts": config.localise_impacts,
            "split_steps": recorder.split_steps,
        }
        if recorder.unconverged or recorder.unconverged_projection:
            trajectory.message = "; ".join(filter(None, [message, (
                f"{len(recorder.unconverged)} step(s) whose contact problem did not converge "
                f"(first: {recorder.unconverged[:5]}); {len(recorder.unconverged_projection)} "
                f"step(s) whose projection did not converge "
                f"(first: {recorder.unconverged_projection[:5]})")]))
        return trajectory


_WARM = False


def _warm_up() -> None:
    """Run every code path of the stepper once in this process (contacts, Newton fall-back,
    projection, joints, drivers, springs), on small scenes, untimed."""
    global _WARM
    if _WARM:
        return
    _WARM = True
    from clearbench.ref_solver import ContactProblem, solve_contact_problem
    from clearbench.scenarios.library import get_scene

    for method in ("nsgs", "newton"):
        solve_contact_problem(ContactProblem(np.eye(3), np.array([-1.0, 0.5, 0.0]), [0.3]),
                              SolverOptions(method=method))
    for name in ("clearance-pendulum", "slider-crank", "stiff-spring", "box-grid"):
        scene = get_scene(name)
        stepper = MoreauJeanStepper(build_system(scene), StepperSettings(scene.time_step))
        state = initial_state(scene)
        for _ in range(5):
            state = stepper.step(state).state


class _Recorder:
    """Collects samples into preallocated arrays; statistics of skipped steps are
    accumulated so that an unconverged step is never lost by subsampling."""

    def __init__(self, scene: Scene, system, samples: int, h: float, tolerance: float):
        self.scene = scene
        self.h = h
        self.tolerance = tolerance
        # steps whose solve was accepted on its round-off floor (residual above tolerance)
        self.roundoff_steps = 0
        nb = system.body_count
        npair = system.pair_count
        self.com = np.array([b.center_of_mass for b in scene.bodies], dtype=float)
        self.times = np.zeros(samples)
        self.positions = np.zeros((samples, nb, 3))
        self.orientations = np.zeros((samples, nb, 4))
        self.velocities = np.zeros((samples, nb, 3))
        self.omegas = np.zeros((samples, nb, 3))
        self.normal = np.zeros((samples, npair))
        self.force = np.zeros((samples, npair, 3))
        self.iterations = np.zeros(samples, dtype=np.int64)
        self.residual = np.full(samples, np.nan)
        self.converged = np.ones(samples, dtype=bool)
        self.active = np.zeros(samples, dtype=np.int64)
        self.unconverged: list[int] = []
        self.solver_seconds = 0.0
        self.contact_sweeps = 0
        self.split_steps = 0  # steps computed in substeps (localised impacts)
        self.unconverged_projection: list[int] = []
        self._iterations = 0
        self._residual = 0.0
        self._converged = True
        self._step = 0

    def accumulate(self, result) -> None:
        self._step += 1
        stats = result.statistics
        self.solver_seconds += stats.solver_seconds
        self.contact_sweeps += stats.contact_sweeps
        self.split_steps += stats.substeps > 1
        self._iterations += stats.solver_iterations
        self._residual = max(self._residual, stats.solver_residual)
        if stats.solver_converged and stats.solver_residual > self.tolerance:
            self.roundoff_steps += 1
        if not stats.solver_converged:
            self._converged = False
            self.unconverged.append(self._step)
        if not stats.projection_converged:
            self.unconverged_projection.append(self._step)

    def store(self, i: int, state, result) -> None:
        self.times[i] = state.t
        self.positions[i] = state.x - quat_rotate_batch(state.p, self.com)
        self.orientations[i] = state.p
        self.velocities[i] = state.v
        self.omegas[i] = state.omega
        if result is not None:
            pairs, slots = np.nonzero(result.contact_active)
            impulse = result.contact_impulse[pairs, slots]          # (k, 3) in contact frames
            world = np.einsum("kr,krj->kj", impulse, result.contact_frame[pairs, slots])
            self.normal[i] = np.bincount(pairs, impulse[:, 0], self.normal.shape[1]) / self.h
            for axis in range(3):
                self.force[i, :, axis] = np.bincount(pairs, world[:, axis],
                                                     self.force.shape[1]) / self.h
            self.iterations[i] = self._iterations
            self.residual[i] = self._residual
            self.converged[i] = self._converged
            self.active[i] = result.statistics.active_contacts
            self._iterations, self._residual, self._converged = 0, 0.0, True

    def trajectory(self, count: int) -> Trajectory:
        scene = self.scene
        return Trajectory(
            engine="", preset="", scene_name=scene.name, scene_hash=scene.content_hash,
            units={"length": scene.units.length, "mass": scene.units.mass,
                   "time": scene.units.time},
            time_step=self.h, body_names=tuple(b.name for b in scene.bodies),
            contact_names=tuple(c.name for c in scene.all_contacts),
            times=self.times[:count], positions=self.positions[:count],
            orientations=self.orientations[:count], velocities=self.velocities[:count],
            angular_velocities=self.omegas[:count], contact_normal_force=self.normal[:count],
            contact_force=self.force[:count], solver_iterations=self.iterations[:count],
            solver_residual=self.residual[:count], solver_converged=self.converged[:count],
            active_contacts=self.active[:count],
        )
