"""The reference engine: our nonsmooth Moreau–Jean solver with the combined projection.

Presets and options: :mod:`.settings`; features: :mod:`.capabilities`; building a run (the
scene's array form, compiled kernels): :mod:`.build`. This module steps the run and records
it. The metadata of a run counts the ``split_steps`` (steps computed in substeps), the steps
whose contact problem or projection did not converge, and the steps accepted on the solver's
round-off floor.
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from clearbench.adapters.base import ModuleEngine, RunSettings
from clearbench.adapters.options import OptionError
from clearbench.adapters.recording import SampleRecorder, step_count
from clearbench.adapters.reference import HARNESS_DEFAULTS, capabilities
from clearbench.adapters.reference.build import build
from clearbench.adapters.reference.settings import (
    OPTIONS,
    PRESETS,
    resolve_settings,
    stepper_settings,
)
from clearbench.adapters.reference.step_loop import choose_step_loop, run_compiled
from clearbench.adapters.trajectory import RunStatus, Trajectory
from clearbench.kernels.quaternion import quat_rotate_batch
from clearbench.ref_solver.stepper import StepperSettings
from clearbench.ref_solver.system import State
from clearbench.scenarios.scene import Scene

__all__ = ["OPTIONS", "PRESETS", "ReferenceEngine", "create"]


def create(preset: str = "default") -> ReferenceEngine:
    """A :class:`ReferenceEngine` with ``preset`` (ValueError for an unknown one)."""
    return ReferenceEngine(preset)


class ReferenceEngine(ModuleEngine):
    """Our nonsmooth reference solver (see :mod:`clearbench.ref_solver.stepper`)."""

    name = "reference"
    RIGID_CONTACTS = HARNESS_DEFAULTS.rigid_contacts
    PRESETS = PRESETS
    OPTIONS = OPTIONS
    CAPABILITIES = capabilities
    RESOLVE_SETTINGS = staticmethod(resolve_settings)

    def check_option_combination(self, options: Mapping) -> None:
        # An explicit localise_impacts = true needs the projection (without it, the preset's
        # localisation is switched off by stepper_settings).
        projection = {**PRESETS[self.preset], **options}["projection"]
        if options.get("localise_impacts") and not projection:
            raise OptionError(self.name, "localise_impacts", True,
                              "needs projection = true (it relies on the activation loop of "
                              "the combined projection)")

    def stepper_settings(self, scene: Scene, settings: RunSettings) -> StepperSettings:
        """Preset + options (checked), with tolerances relative to the scene's smallest
        feature (:func:`.settings.stepper_settings`)."""
        self.check_options(settings.options)
        return stepper_settings(self.preset, scene, settings)

    def _run(self, scene: Scene, settings: RunSettings) -> Trajectory:
        start = time.perf_counter()
        config = self.stepper_settings(scene, settings)
        model = build(scene, config)
        stepper, state = model.stepper, model.state
        h = config.time_step
        steps = step_count(settings.horizon or scene.horizon, h)
        recorder = SampleRecorder(model.system.body_count, model.system.pair_count, steps,
                                  settings.record_every)
        com = np.array([b.center_of_mass for b in scene.bodies], dtype=float)
        statistics = _RunStatistics(config.solver.tolerance)
        recorder.store(*_body_sample(state, com))
        loop = choose_step_loop(settings.options.get("step_loop", "auto"), stepper)
        build_seconds = time.perf_counter() - start
        status, message = RunStatus.OK, ""
        stepping = 0.0
        taken = 0
        if loop.compiled:
            status, message, stepping, taken = run_compiled(stepper, state, steps, recorder,
                                                            com, statistics)
        for k in range(1, 0 if loop.compiled else steps + 1):
            tick = time.perf_counter()
            try:
                result = stepper.step(state)
            except (ArithmeticError, ValueError, np.linalg.LinAlgError) as error:
                # A failure inside a kernel is an outcome of the run: the state the step
                # started from is kept as the last sample, to reproduce it.
                if not recorder.is_full:
                    recorder.store(*_body_sample(state, com))
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
            stats = result.statistics
            recorder.accumulate(stats.solver_iterations, stats.solver_converged,
                                stats.solver_residual)
            statistics.add(k, stats)
            if recorder.is_due(k) or (not finite and not recorder.is_full):
                recorder.store(*_body_sample(state, com), contacts=_contact_sample(
                    result, h, model.system.pair_count))
            if not finite:
                status, message = RunStatus.DIVERGED, f"non-finite state at step {k}"
                break
        metadata = {
            "theta": config.theta, "projection": config.projection,
            "solver": config.method, "tolerance": config.solver.tolerance,
            "position_tolerance": config.position_tolerance,
            "unconverged_steps": statistics.unconverged,
            "roundoff_steps": statistics.roundoff_steps,
            "unconverged_projections": statistics.unconverged_projection,
            "solver_seconds": statistics.solver_seconds,
            "contact_sweeps": statistics.contact_sweeps,
            "localise_impacts": config.localise_impacts,
            "split_steps": statistics.split_steps,
            **loop.metadata(),
        }
        if statistics.unconverged or statistics.unconverged_projection:
            message = "; ".join(filter(None, [message, (
                f"{len(statistics.unconverged)} step(s) whose contact problem did not converge "
                f"(first: {statistics.unconverged[:5]}); "
                f"{len(statistics.unconverged_projection)} step(s) whose projection did not "
                f"converge (first: {statistics.unconverged_projection[:5]})")]))
        return recorder.trajectory(
            scene, h, engine=self.name, preset=self.preset, build_seconds=build_seconds,
            stepping_seconds=stepping, steps=taken, status=status, message=message,
            metadata=metadata)


def _body_sample(state: State, com: np.ndarray) -> tuple:
    """(t, body-frame origins (nb, 3), quaternions (nb, 4), velocities (nb, 3), angular
    velocities (nb, 3)) of a solver state, whose positions are centres of mass ``com``
    (nb, 3) [L] (body frame)."""
    return (state.t, state.x - quat_rotate_batch(state.p, com), state.p, state.v,
            state.omega)


def _contact_sample(result, h: float, pair_count: int) -> tuple:
    """Per pair, the normal force (np,) and the world force on body B (np, 3) [F], averaged
    over the step of length ``h`` [T], and the count of active contacts of the step."""
    pairs, slots = np.nonzero(result.contact_active)
    impulse = result.contact_impulse[pairs, slots]          # (k, 3) in contact frames
    world = np.einsum("kr,krj->kj", impulse, result.contact_frame[pairs, slots])
    normal = np.bincount(pairs, impulse[:, 0], pair_count) / h
    force = np.zeros((pair_count, 3))
    for axis in range(3):
        force[:, axis] = np.bincount(pairs, world[:, axis], pair_count) / h
    return normal, force, result.statistics.active_contacts


@dataclass
class _RunStatistics:
    """The reference's own statistics of a run, over every step (recorded or not)."""

    tolerance: float
    roundoff_steps: int = 0  # accepted on the round-off floor (residual above tolerance)
    solver_seconds: float = 0.0
    contact_sweeps: int = 0
    split_steps: int = 0  # computed in substeps (localised impacts)
    unconverged: list[int] = field(default_factory=list)
    unconverged_projection: list[int] = field(default_factory=list)

    def add(self, step: int, stats) -> None:
        """Count the statistics of step ``step`` (1-based)."""
        self.solver_seconds += stats.solver_seconds
        self.contact_sweeps += stats.contact_sweeps
        self.split_steps += stats.substeps > 1
        if stats.solver_converged and stats.solver_residual > self.tolerance:
            self.roundoff_steps += 1
        if not stats.solver_converged:
            self.unconverged.append(step)
        if not stats.projection_converged:
            self.unconverged_projection.append(step)
