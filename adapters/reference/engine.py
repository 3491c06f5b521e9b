"""The reference engine: our nonsmooth Moreau–Jean solver with the combined projection.

Presets and options: :mod:`.settings`; features: :mod:`.capabilities`; building a run (the
scene's array form, compiled kernels): :mod:`.build`; its step loops: :mod:`.run`. This module
resolves a run's settings and turns what the loop recorded into the trajectory. The metadata
of a run counts the ``split_steps`` (steps computed in substeps), the steps whose projection
did not converge and the steps accepted on the solver's round-off floor; the trajectory's
typed fields the steps whose contact problem did not converge.
"""

from __future__ import annotations

import time
from collections.abc import Mapping

import numpy as np

from clearbench.adapters.base import ModuleEngine, RunSettings
from clearbench.adapters.options import OptionError
from clearbench.adapters.recording import SampleRecorder, step_count
from clearbench.adapters.reference import HARNESS_DEFAULTS, capabilities
from clearbench.adapters.reference.build import build, warm_python_step
from clearbench.adapters.reference.run import (
    RunStatistics,
    body_sample,
    choose_step_loop,
    run_steps,
)
from clearbench.adapters.reference.settings import (
    OPTIONS,
    PRESETS,
    resolve_settings,
    stepper_settings,
)
from clearbench.adapters.step_monitor import UNCONVERGED_KEPT
from clearbench.adapters.trajectory import Trajectory
from clearbench.ref_solver.stepper import StepperSettings
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
        # localisation is switched off by run_settings).
        projection = {**PRESETS[self.preset], **options}["projection"]
        if options.get("localise_impacts") and not projection:
            raise OptionError(self.name, "localise_impacts", True,
                              "needs projection = true (it relies on the activation loop of "
                              "the combined projection)")

    def resolve_run_settings(self, scene: Scene, settings: RunSettings) -> StepperSettings:
        """Preset + options, with tolerances relative to the scene's smallest feature
        (:func:`.settings.stepper_settings`)."""
        return stepper_settings(self.preset, scene, settings)

    def _run(self, scene: Scene, settings: RunSettings) -> Trajectory:
        start = time.perf_counter()
        config = self.resolve_run_settings(scene, settings)
        model = build(scene, config, python_step=False)
        stepper, state = model.stepper, model.state
        h = config.time_step
        steps = step_count(settings.horizon or scene.horizon, h)
        recorder = SampleRecorder(model.system.body_count, model.system.pair_count, steps,
                                  settings.record_every)
        com = np.array([b.center_of_mass for b in scene.bodies], dtype=float)
        statistics = RunStatistics(config.solver.tolerance)
        recorder.store(*body_sample(state, com))
        loop = choose_step_loop(settings.options.get("step_loop", "auto"), stepper)
        if not loop.compiled:
            warm_python_step(model)
        build_seconds = time.perf_counter() - start
        status, message, stepping, taken = run_steps(loop, stepper, state, steps, recorder, com,
                                                     statistics)
        metadata = {
            "theta": config.theta, "projection": config.projection,
            "solver": config.method, "tolerance": config.solver.tolerance,
            "position_tolerance": config.position_tolerance,
            "roundoff_steps": statistics.roundoff_steps,
            "unconverged_projections": statistics.unconverged_projection,
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
            unconverged_steps=tuple(statistics.unconverged[:UNCONVERGED_KEPT]),
            unconverged_count=len(statistics.unconverged),
            solver_seconds=statistics.solver_seconds, internal_units=scene.units.describe(),
            metadata=metadata)
