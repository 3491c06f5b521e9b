"""The PyBullet engine: a scene rebuilt in PyBullet (see :mod:`.build`), stepped with guards
(:mod:`.run`), and read out into the common :class:`~clearbench.adapters.trajectory.Trajectory`.

Presets (each a separate engine variant ``pybullet[<preset>]``; see :mod:`.settings`):
``default`` (what a user gets writing nothing beyond the scene) and ``tuned`` (what an expert
sets for accuracy). ``RunSettings.options`` override any field of
:class:`~.settings.PybulletSettings`, checked before anything runs; what each scene feature
becomes: :mod:`.capabilities`.

Units: PyBullet's tolerances are absolute (margins 0.001, slop 1e-5, split-impulse threshold
-0.04, restitution threshold 0.2, and a GJK/EPA resolution of about 1e-6 of the length unit),
so the model works in ``internal_units`` (:func:`internal_units`; ``default``: SI, as a user
would write it; ``tuned``: 'auto', mm-g-ms for scenes whose smallest feature is below 1 mm,
because in SI Bullet misreads the C-60's gaps by up to 0.26 mm: docs/engines/pybullet.md) and
the results are converted back; the metadata records the internal units.
"""

from __future__ import annotations

from clearbench.adapters import installed_package
from clearbench.adapters.base import SteppingEngine
from clearbench.adapters.pybullet import capabilities
from clearbench.adapters.pybullet.capabilities import ring_summary
from clearbench.adapters.pybullet.geometry import margin_feature_length
from clearbench.adapters.pybullet.settings import (
    OPTIONS,
    PRESETS,
    PybulletSettings,
    resolve_settings,
)
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.units import MM_G_MS, SI, UnitSystem
from clearbench.scenarios.validation import LENGTH, TIME, VELOCITY

__all__ = ["AUTO_MILLIMETRE_BELOW", "OPTIONS", "PRESETS", "PybulletEngine", "create",
           "internal_units"]

#: Below this smallest feature [m], ``internal_units = 'auto'`` models in mm-g-ms instead of SI.
AUTO_MILLIMETRE_BELOW = 1e-3


def create(preset: str = "default") -> PybulletEngine:
    """A :class:`PybulletEngine` with ``preset`` (ValueError for an unknown one)."""
    return PybulletEngine(preset)


class PybulletEngine(SteppingEngine):
    """PyBullet (velocity-level sequential impulses, Featherstone trees) with a named preset."""

    name = "pybullet"
    TITLE = "PyBullet"
    PRESETS = PRESETS
    OPTIONS = OPTIONS
    CAPABILITIES = capabilities
    RESOLVE_SETTINGS = staticmethod(resolve_settings)

    def capability_scene(self, scene: Scene, settings: PybulletSettings) -> Scene:
        return internal_scene(scene, settings)

    def internal_scene(self, scene: Scene, config: PybulletSettings) -> Scene:
        return internal_scene(scene, config)

    def build(self, internal: Scene, config: PybulletSettings, dt: float):
        # Lazy import of the engine package (pybullet) through the world builder and the loop.
        from clearbench.adapters.pybullet.build import build_world

        return build_world(internal, config, dt)

    def runner(self, internal: Scene, built, config: PybulletSettings, steps: int,
               record_every: int):
        from clearbench.adapters.pybullet.run import Runner

        return Runner(internal, built, config, steps, record_every)

    def release(self, built) -> None:
        from clearbench.adapters.pybullet.build import disconnect

        disconnect(built)

    def metadata(self, scene: Scene, internal: Scene, config: PybulletSettings, built,
                 runner) -> dict:
        to_internal = scene.units.factor_to(internal.units, TIME)
        topology = built.topology
        return {
            "pybullet_version": installed_package("pybullet")[1],
            "settings": config.as_dict(),
            "time_step_internal": built.time_step,
            "time_step_scene": built.time_step / to_internal,
            "collision_margin_internal": built.margin,
            "contact_breaking_threshold_set": config.contact_breaking_threshold,
            "warnings": list(built.warnings),
            "guards": runner.monitor.guard.notes,
            "static_bodies": list(topology.static),
            "rigid_bodies": list(topology.rigid),
            "multibodies": [[link.body for link in tree.links] for tree in topology.trees],
            "loop_closures": list(topology.closures),
            "collision_objects": len(built.objects),
            "rings": ring_summary(internal, config),
            "initial_velocity_residual": built.initial_velocity_residual
            * internal.units.factor_to(scene.units, VELOCITY),
            "energy_initial": runner.monitor.guard.energy_initial,
            "max_contacts": runner.max_contacts,
        }


def internal_units(scene: Scene, config: PybulletSettings) -> UnitSystem:
    """The unit system PyBullet works in for ``scene``: as ``config.internal_units`` says, and
    for 'auto' mm-g-ms when the scene has contacts and its smallest feature
    (:func:`~.geometry.margin_feature_length`) is below :data:`AUTO_MILLIMETRE_BELOW`, else
    SI."""
    if config.internal_units == "scene":
        return scene.units
    if config.internal_units == "SI":
        return SI
    if config.internal_units == "mm-g-ms":
        return MM_G_MS
    if not scene.all_contacts:  # no collision geometry: nothing to resolve
        return SI
    smallest = margin_feature_length(scene) * scene.units.factor_to(SI, LENGTH)
    return SI if smallest >= AUTO_MILLIMETRE_BELOW else MM_G_MS


def internal_scene(scene: Scene, config: PybulletSettings) -> Scene:
    """``scene`` in :func:`internal_units`."""
    units = internal_units(scene, config)
    return scene if units == scene.units else scene.rescaled(units)
