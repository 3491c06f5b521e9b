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

import time
from importlib.metadata import PackageNotFoundError, version

from clearbench.adapters.base import ModuleEngine, RunSettings
from clearbench.adapters.pybullet import capabilities
from clearbench.adapters.pybullet.capabilities import ring_summary
from clearbench.adapters.pybullet.geometry import margin_feature_length
from clearbench.adapters.pybullet.settings import (
    OPTIONS,
    PRESETS,
    PybulletSettings,
    resolve_settings,
)
from clearbench.adapters.recording import step_count
from clearbench.adapters.trajectory import Trajectory
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.units import MM_G_MS, SI, UnitSystem
from clearbench.scenarios.validation import LENGTH, TIME, VELOCITY

__all__ = ["AUTO_MILLIMETRE_BELOW", "OPTIONS", "PRESETS", "PybulletEngine",
           "availability", "create", "internal_units"]

#: Below this smallest feature [m], ``internal_units = 'auto'`` models in mm-g-ms instead of SI.
AUTO_MILLIMETRE_BELOW = 1e-3


def availability() -> tuple[bool, str]:
    """(available, detail) of the pybullet package; never raises."""
    try:
        # lazy import of the engine package (only when asked), without its build-time banner
        from clearbench.adapters.pybullet.library import pb  # noqa: F401
    except ImportError as error:  # pragma: no cover - pybullet is a dependency
        return False, f"pybullet does not import: {error}"
    try:
        return True, f"pybullet {version('pybullet')}"
    except PackageNotFoundError:  # pragma: no cover - a source build without metadata
        return True, "pybullet (version unknown)"


def create(preset: str = "default") -> PybulletEngine:
    return PybulletEngine(preset)


class PybulletEngine(ModuleEngine):
    """PyBullet (velocity-level sequential impulses, Featherstone trees) with a named preset."""

    name = "pybullet"
    PRESETS = PRESETS
    OPTIONS = OPTIONS
    CAPABILITIES = capabilities
    RESOLVE_SETTINGS = staticmethod(resolve_settings)

    def capability_scene(self, scene: Scene, settings: PybulletSettings) -> Scene:
        return internal_scene(scene, settings)

    def _run(self, scene: Scene, settings: RunSettings) -> Trajectory:
        # Lazy import of the engine package (pybullet) through the world builder and the loop.
        from clearbench.adapters.pybullet.build import build_world, disconnect
        from clearbench.adapters.pybullet.run import Runner

        config = self.settings(settings.options)
        start = time.perf_counter()
        internal = internal_scene(scene, config)
        to_internal = scene.units.factor_to(internal.units, TIME)
        dt = (settings.time_step or scene.time_step) * to_internal
        horizon = (settings.horizon or scene.horizon) * to_internal
        built = build_world(internal, config, dt)
        try:
            runner = Runner(built, step_count(horizon, dt), settings.record_every)
            build_seconds = time.perf_counter() - start
            status, message = runner.run()
        finally:
            disconnect(built)
        return runner.recorder.trajectory(
            scene, dt, recorded_units=internal.units, engine=self.name, preset=self.preset,
            build_seconds=build_seconds, stepping_seconds=runner.stepping_seconds,
            steps=runner.steps_taken, status=status, message=message,
            metadata=_metadata(scene, internal, config, built, runner))


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


def _metadata(scene: Scene, internal: Scene, config: PybulletSettings, built, runner) -> dict:
    if internal.units != scene.units:
        units = (f"scene in {scene.units.describe()} rescaled to {internal.units.describe()} "
                 "for PyBullet; results converted back")
    else:
        units = f"run in the scene's units ({scene.units.describe()})"
    to_internal = scene.units.factor_to(internal.units, TIME)
    topology = built.topology
    return {
        "pybullet_version": availability()[1],
        "settings": config.as_dict(),
        "units": units,
        "internal_units": internal.units.describe(),
        "time_step_internal": built.time_step,
        "time_step_scene": built.time_step / to_internal,
        "collision_margin_internal": built.margin,
        "contact_breaking_threshold_set": config.contact_breaking_threshold,
        "warnings": list(built.warnings),
        "guards": runner.guard.notes,
        "static_bodies": list(topology.static),
        "rigid_bodies": list(topology.rigid),
        "multibodies": [[link.body for link in tree.links] for tree in topology.trees],
        "loop_closures": list(topology.closures),
        "collision_objects": len(built.objects),
        "rings": ring_summary(internal, config),
        "initial_velocity_residual": built.initial_velocity_residual
        * internal.units.factor_to(scene.units, VELOCITY),
        "energy_initial": runner.guard.energy_initial,
        "energy_max_gain": runner.guard.max_gain,
        "unconverged_steps": runner.unconverged[:1000],
        "unconverged_count": len(runner.unconverged),
        "max_contacts": runner.max_contacts,
    }
