"""The MuJoCo engine: a scene rebuilt in MuJoCo (see :mod:`.build`), stepped with guards
(:mod:`.run`), and read out into the common :class:`~clearbench.adapters.trajectory.Trajectory`.

Presets (each a separate engine variant ``mujoco[<preset>]``; see :mod:`.settings`):

- ``default``: MuJoCo's own defaults (pyramidal cone, solref (0.02, 1), solimp
  (0.9, 0.95, 0.001), Euler, Newton, 100 iterations, no noslip);
- ``tuned``: elliptic cone + 10 noslip iterations, solref (2 dt, 1), solimp
  (0.99, 0.999, 1e-5) for contacts and loop closures (docs/engines/mujoco.md); plastic pairs
  (e = 0) mapped to dampratio 3 like every other restitution.

Every pair with e > 0 gets dampratio zeta(e) of a unilateral spring-damper in both presets
(MuJoCo has no restitution parameter; see :mod:`.settings`).

``RunSettings.options`` override any field of :class:`~.settings.MujocoSettings`; what each
scene feature becomes: :mod:`.capabilities`.

Units: MuJoCo's absolute defaults (solimp width 1 mm, collision tolerance 1e-6) assume metres
and seconds, so a scene in other units is rescaled to SI for MuJoCo (``internal_units``) and
its results converted back; the trajectory metadata says so.

Guards: before the run, every soft constraint's stiffness*dt^2 and damping*dt (per unit mass)
is checked against 1 and a warning recorded; during the run a non-finite state or a MuJoCo
warning (bad acceleration, contact buffer full) stops the run as DIVERGED, and so does an
energy gain above ``energy_gain_tolerance`` of the energy scale on scenes whose expectations
say energy may only decrease (``energy_non_increasing``, ``energy_conserved``).
"""

from __future__ import annotations

from clearbench.adapters.base import SteppingEngine
from clearbench.adapters.mujoco import capabilities
from clearbench.adapters.mujoco.capabilities import (
    bore_summary,
    clearance_summary,
    ring_summary,
)
from clearbench.adapters.mujoco.run import Runner
from clearbench.adapters.mujoco.settings import (
    OPTIONS,
    PRESETS,
    MujocoSettings,
    resolve_settings,
)
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.validation import TIME, VELOCITY

__all__ = ["OPTIONS", "PRESETS", "MujocoEngine", "create"]


def create(preset: str = "default") -> MujocoEngine:
    """A :class:`MujocoEngine` with ``preset`` (ValueError for an unknown one)."""
    return MujocoEngine(preset)


class MujocoEngine(SteppingEngine):
    """MuJoCo (soft contacts, joint-coordinate trees) with a named preset."""

    name = "mujoco"
    TITLE = "MuJoCo"
    PRESETS = PRESETS
    OPTIONS = OPTIONS
    CAPABILITIES = capabilities
    RESOLVE_SETTINGS = staticmethod(resolve_settings)

    def build(self, internal: Scene, config: MujocoSettings, dt: float):
        # Lazy import of the optional engine package (mujoco) through the model builder.
        from clearbench.adapters.mujoco.build import build_model

        return build_model(internal, config, dt)

    def runner(self, internal: Scene, built, config: MujocoSettings, steps: int,
               record_every: int) -> Runner:
        return Runner(internal, built, config, steps, record_every)

    def metadata(self, scene: Scene, internal: Scene, config: MujocoSettings, built,
                 runner: Runner) -> dict:
        to_internal = scene.units.factor_to(internal.units, TIME)
        return {
            "mujoco_version": runner.mujoco.__version__,
            "settings": config.as_dict(),
            "time_step_internal": built.model.opt.timestep,
            "time_step_scene": built.model.opt.timestep / to_internal,
            "warnings": list(built.warnings) + runner.warnings,
            "guards": runner.monitor.guard.notes,
            "contact_solref": [list(p.solref) for p in built.contact_parameters],
            "contact_dampratio": [p.damping_ratio for p in built.contact_parameters],
            "rings": ring_summary(scene, config),
            "bores": bore_summary(scene, config),
            "clearance_joints": clearance_summary(scene, config),
            "tree": [[link.body, link.parent, link.kind, link.joint]
                     for link in built.topology.links],
            "loop_closures": list(built.topology.closures),
            "initial_velocity_residual": built.initial_velocity_residual
            * internal.units.factor_to(scene.units, VELOCITY),
            "mujoco_warnings": runner.mujoco_warnings,
            "energy_initial": runner.monitor.guard.energy_initial,
            "max_contacts": runner.max_contacts,
        }

