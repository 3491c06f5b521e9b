"""The Drake engine: a scene rebuilt as a discrete ``MultibodyPlant`` (see :mod:`.build`),
stepped with guards (:mod:`.run`), and read out into the common
:class:`~clearbench.adapters.trajectory.Trajectory`.

Presets (each a separate engine variant ``drake[<preset>]``; see :mod:`.settings`):

- ``default``: Drake's own ``MultibodyPlantConfig()`` (pydrake 1.51): the Lagged discrete
  approximation, ``hydroelastic_with_fallback`` (point contact for these primitives), stiffness
  and Hunt–Crossley dissipation estimated from ``penetration_allowance`` 1 mm, stiction
  tolerance 1e-4 m/s; only the scene's friction set on the geometries;
- ``tuned``: SAP, point contact with hydroelastic boxes, stiffness of a 2-step contact half
  period, dissipation time constant of 4 steps (e = 0; e > 0 mapped), stiction tolerance
  1e-6 m/s (docs/engines/drake.md).

``RunSettings.options`` override any field of :class:`~.settings.DrakeSettings`, checked
before anything runs; what each scene feature becomes: :mod:`.capabilities`.

Units: Drake's defaults (penetration allowance, stiction tolerance, SAP's 0.1 s) are absolute
SI values, so a scene in other units is rescaled to SI for Drake and its results converted
back; the trajectory metadata says so.
"""

from __future__ import annotations

from clearbench.adapters import installed_package
from clearbench.adapters.base import SteppingEngine
from clearbench.adapters.drake import capabilities
from clearbench.adapters.drake.capabilities import ring_summary
from clearbench.adapters.drake.settings import (
    OPTIONS,
    PRESETS,
    DrakeSettings,
    resolve_settings,
)
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.validation import LENGTH, TIME

__all__ = ["OPTIONS", "PRESETS", "DrakeEngine", "create"]


def create(preset: str = "default") -> DrakeEngine:
    """A :class:`DrakeEngine` with ``preset`` (ValueError for an unknown one)."""
    return DrakeEngine(preset)


class DrakeEngine(SteppingEngine):
    """Drake (discrete MultibodyPlant, compliant point contact) with a named preset."""

    name = "drake"
    TITLE = "Drake"
    PRESETS = PRESETS
    OPTIONS = OPTIONS
    CAPABILITIES = capabilities
    RESOLVE_SETTINGS = staticmethod(resolve_settings)

    def build(self, internal: Scene, config: DrakeSettings, dt: float):
        # Lazy import of the engine package (pydrake) through the plant builder.
        from clearbench.adapters.drake.build import build_plant

        return build_plant(internal, config, dt)

    def runner(self, internal: Scene, built, config: DrakeSettings, steps: int,
               record_every: int):
        from clearbench.adapters.drake.run import Runner

        return Runner(internal, built, config, steps, record_every)

    def metadata(self, scene: Scene, internal: Scene, config: DrakeSettings, built,
                 runner) -> dict:
        to_internal = scene.units.factor_to(internal.units, TIME)
        to_scene = internal.units.factor_to(scene.units, LENGTH)
        plant = built.plant
        return {
            "drake_version": installed_package("pydrake", "drake")[1],
            "settings": config.as_dict(),
            "time_step_internal": built.time_step,
            "time_step_scene": built.time_step / to_internal,
            "discrete_contact_approximation": str(plant.get_discrete_contact_approximation()),
            "contact_model": str(plant.get_contact_model()),
            "pair_materials": [m.__dict__ for m in built.materials],
            "rings": ring_summary(internal, config),
            "tree_joints": [e.joint.name for e in built.topology.edges],
            "free_bodies": list(built.topology.free),
            "loop_closures": [j.name for j in built.topology.closures],
            "energy_initial": runner.monitor.guard.energy_initial,
            "guards": runner.monitor.guard.notes,
            "max_contacts": runner.max_contacts,
            "drake_penetration_max": runner.penetration_max * to_scene,
            "solver_statistics": "not exposed by pydrake: iterations 0, residual NaN",
        }
