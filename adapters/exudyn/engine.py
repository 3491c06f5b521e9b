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

from clearbench.adapters.base import BuildError, SteppingEngine
from clearbench.adapters.exudyn import capabilities
from clearbench.adapters.exudyn.build import build_system, load_exudyn
from clearbench.adapters.exudyn.capabilities import clearance_summary
from clearbench.adapters.exudyn.run import Runner
from clearbench.adapters.exudyn.settings import (
    OPTIONS,
    PRESETS,
    ExudynSettings,
    resolve_settings,
)
from clearbench.scenarios.scene import Scene

__all__ = ["OPTIONS", "PRESETS", "ExudynEngine", "create"]


def create(preset: str = "default") -> ExudynEngine:
    """A :class:`ExudynEngine` with ``preset`` (ValueError for an unknown one)."""
    return ExudynEngine(preset)


class ExudynEngine(SteppingEngine):
    """Exudyn (implicit multibody, index-3 joints, penalty contact connectors)."""

    name = "exudyn"
    TITLE = "Exudyn"
    PRESETS = PRESETS
    OPTIONS = OPTIONS
    CAPABILITIES = capabilities
    RESOLVE_SETTINGS = staticmethod(resolve_settings)

    def build(self, internal: Scene, config: ExudynSettings, dt: float):
        try:
            return build_system(internal, config, dt)
        except Exception as error:  # an Exudyn item refused: a recorded outcome
            raise BuildError(f"building the Exudyn system failed: "
                             f"{type(error).__name__}: {error}") from error

    def runner(self, internal: Scene, built, config: ExudynSettings, steps: int,
               record_every: int) -> Runner:
        return Runner(internal, built, config, steps, record_every)

    def steps_taken(self, runner: Runner, steps: int, dt: float) -> int:
        # Exudyn reduces its step on its own: the steps of dt the recorded time covers.
        return min(steps, int(round(_last_time(runner) / dt)))

    def rebuild_overlap(self, built) -> dict:
        return {plan.contact.name: plan.overlap for plan in built.pair_plans}

    def metadata(self, scene: Scene, internal: Scene, config: ExudynSettings, built,
                 runner: Runner) -> dict:
        last_time = _last_time(runner)
        return {
            "exudyn_version": load_exudyn().__version__,
            "settings": config.as_dict(),
            "time_step_internal": built.time_step,
            "connectors": built.connector_count,
            "connectors_per_pair": {p.contact.name: len(p.connectors) for p in built.pair_plans},
            "pairs": {p.contact.name: p.how for p in built.pair_plans},
            "shape_error_per_pair": {p.contact.name: p.shape_error for p in built.pair_plans},
            "contact_stiffness": built.stiffness,
            "clearance_joints": clearance_summary(scene, config),
            "warnings": list(built.warnings),
            "guards": runner.monitor.guard.notes,
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
            "energy_initial": runner.monitor.guard.energy_initial,
            # Exudyn does not clip the normal force at zero: the most negative recorded sum of a
            # pair (model units; 0 when none pulled).
            "min_normal_force": runner.min_normal_force,
        }


def _last_time(runner: Runner) -> float:
    """The time of the last recorded sample [T, internal units]."""
    recorder = runner.recorder
    return recorder.times[max(recorder.count - 1, 0)]
