"""The Exudyn engine: a scene rebuilt in Exudyn (see :mod:`.build`), stepped with guards
(:mod:`.run`), and read out into the common :class:`~clearbench.adapters.trajectory.Trajectory`.

Presets (``exudyn[<preset>]``, see :mod:`.settings`):

- ``default``: implicit generalized-alpha as it comes (spectral radius 0.9, modified Newton,
  adaptive step reduction), Gonthier impact model, v_reg = 1e-3 m/s, stiffness from the rule
  k = m (2 pi / (10 dt))^2 (Exudyn's own default stiffness is 0: no contact);
- ``tuned``: v_reg = 1e-7 m/s, minimum impact velocity 0.01 m/s (damped resting contacts),
  contact period 4 steps of the scene's comfortable step (one contact model for every dt),
  e = 0 pairs at e = 0.05 (no pulling contact force);
- ``mechanism``: ``tuned`` with Newton's absolute tolerance 3e-6 of the scene's force scale
  and v_reg = 1e-5 m/s (the C-60: Newton's residual floor, friction direction flips).

``RunSettings.options`` override any field of :class:`~.settings.ExudynSettings` (checked
before the run: ValueError naming the option and value).

Units: Exudyn has no absolute length or time tolerance that matters here (its velocity
thresholds are velocities, and mm/ms = m/s), so a scene runs in its own units by default
(``internal_units = 'scene'``; the C-60's mm-g-ms keeps its mass matrix well scaled); 'SI'
rescales it. The trajectory metadata says which.
"""

from __future__ import annotations

import time

from clearbench.adapters.base import Capability, Engine, RunSettings
from clearbench.adapters.exudyn import capabilities
from clearbench.adapters.exudyn.build import build_system, load_exudyn
from clearbench.adapters.exudyn.capabilities import FeatureContext, clearance_summary
from clearbench.adapters.exudyn.run import Runner
from clearbench.adapters.exudyn.settings import (
    OPTIONS,
    PRESETS,
    ExudynSettings,
    resolve_settings,
)
from clearbench.adapters.recording import step_count
from clearbench.adapters.trajectory import RunStatus, Trajectory
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.units import SI
from clearbench.scenarios.validation import TIME

__all__ = ["OPTIONS", "PRESETS", "ExudynEngine", "availability", "create"]


def availability() -> tuple[bool, str]:
    """(True, version) when ``exudyn`` imports, else (False, why); never raises."""
    try:
        exudyn = load_exudyn()
    except ImportError as error:  # pragma: no cover - exudyn is a dependency
        return False, f"exudyn does not import: {error}"
    return True, f"exudyn {exudyn.__version__}"


def create(preset: str = "default") -> ExudynEngine:
    """An :class:`ExudynEngine` with ``preset`` (ValueError for an unknown one)."""
    return ExudynEngine(preset)


class ExudynEngine(Engine):
    """Exudyn (implicit multibody, index-3 joints, penalty contact connectors)."""

    name = "exudyn"
    PRESETS = PRESETS
    OPTIONS = OPTIONS

    def settings(self, options: dict | None = None) -> ExudynSettings:
        """The preset overridden by ``options`` (names and values checked: ValueError)."""
        self.check_options(options)
        return resolve_settings(self.preset, options)

    def feature_context(self, scene: Scene, options) -> FeatureContext:
        return capabilities.feature_context(scene, self.settings(options))

    def feature_problems(self, context: FeatureContext) -> dict[str, list[str]]:
        return capabilities.feature_problems(context)

    def plain_capability(self, context: FeatureContext, name: str) -> Capability | None:
        return capabilities.plain_capability(context, name)

    def shape_capability(self, context: FeatureContext, kind: str) -> Capability | None:
        return capabilities.shape_capability(context, kind)

    def joint_capability(self, context: FeatureContext, kind: str) -> Capability | None:
        return capabilities.joint_capability(context, kind)

    def pair_capability(self, context: FeatureContext, kind_a: str,
                        kind_b: str) -> Capability | None:
        return capabilities.pair_capability(context, kind_a, kind_b)

    def _run(self, scene: Scene, settings: RunSettings) -> Trajectory:
        config = self.settings(settings.options)
        start = time.perf_counter()
        internal = scene.rescaled(SI) if (config.internal_units == "SI"
                                          and scene.units != SI) else scene
        to_internal = scene.units.factor_to(internal.units, TIME)
        dt = (settings.time_step or scene.time_step) * to_internal
        horizon = (settings.horizon or scene.horizon) * to_internal
        steps = step_count(horizon, dt)
        try:
            built = build_system(internal, config, dt)
        except Exception as error:  # an Exudyn item refused: a recorded outcome
            return Trajectory.empty(self.name, self.preset, scene, RunStatus.CRASHED,
                                    f"building the Exudyn system failed: "
                                    f"{type(error).__name__}: {error}",
                                    time_step=dt / to_internal)
        runner = Runner(internal, built, config, steps, settings.record_every)
        build_seconds = time.perf_counter() - start
        status, message = runner.run()
        recorder = runner.recorder
        last_time = recorder.times[max(recorder.count - 1, 0)]
        return recorder.trajectory(
            scene, dt, recorded_units=internal.units, engine=self.name, preset=self.preset,
            build_seconds=build_seconds, stepping_seconds=runner.stepping_seconds,
            steps=min(steps, int(round(last_time / dt))), status=status, message=message,
            metadata=_metadata(scene, internal, config, built, runner))


def _metadata(scene: Scene, internal: Scene, config: ExudynSettings, built, runner) -> dict:
    if internal.units != scene.units:
        units = (f"scene in {scene.units.describe()} rescaled to {internal.units.describe()} "
                 "for Exudyn; results converted back")
    else:
        units = f"run in the scene's units ({scene.units.describe()})"
    recorder = runner.recorder
    last_time = recorder.times[max(recorder.count - 1, 0)]
    return {
        "exudyn_version": load_exudyn().__version__,
        "settings": config.as_dict(),
        "units": units,
        "time_step_internal": built.time_step,
        "connectors": built.connector_count,
        "connectors_per_pair": {p.contact.name: len(p.connectors) for p in built.pair_plans},
        "pairs": {p.contact.name: p.how for p in built.pair_plans},
        "shape_error_per_pair": {p.contact.name: p.shape_error for p in built.pair_plans},
        "contact_stiffness": built.stiffness,
        "clearance_joints": clearance_summary(scene, config),
        "warnings": list(built.warnings),
        "guards": runner.guard_notes,
        "force_scale": runner.force_scale_value,
        "newton_absolute_tolerance": runner.newton_absolute_tolerance,
        "solver_steps": runner.solver_steps,
        "solver_statistics": runner.solver_statistics(),
        "nominal_steps": runner.steps,
        "reduced_steps": max(0, runner.solver_steps - int(round(last_time / built.time_step))),
        "discontinuous_iteration_failures": runner.discontinuous_failures_total,
        "solver_error": runner.error_string,
        "failed_loop": runner.failed_loop,
        # Exudyn's GetErrorString as it is: its Newton and discontinuous-iteration flags are
        # printed inverted (see adapters/exudyn/failure.py).
        "exudyn_error_string": runner.exudyn_error_string,
        "captured_stdout": runner.captured_stdout[-2000:],
        "energy_initial": runner.guard.energy_initial,
        "energy_max_gain": runner.guard.max_gain,
        # Exudyn does not clip the normal force at zero: the most negative recorded sum of a
        # pair (model units; 0 when none pulled).
        "min_normal_force": runner.min_normal_force,
    }
