"""The contract every engine adapter implements, and the bookkeeping the base class does for it
(scipy ``integrate/_ivp`` style: the base checks and dispatches, each engine does only its own
part).

An engine is a subpackage of :mod:`clearbench.adapters` (listed in
:data:`clearbench.adapters.ENGINES`) whose ``__init__`` exposes ``availability() -> (bool, str)``
and ``create(preset) -> Engine``. Its :class:`Engine` subclass declares:

- ``name`` and its presets :attr:`Engine.PRESETS` (name -> option values) and run options
  :attr:`Engine.OPTIONS` (an :class:`~clearbench.adapters.options.OptionTable`: each option's
  type, range and allowed values); the base refuses an unknown preset when the engine is
  created, and an unknown option or a bad option value before anything runs
  (:meth:`Engine.check_options`), for every engine alike;
- what it does with each scene feature, one feature kind at a time: the base parses every
  feature of ``Scene.features`` once (:func:`clearbench.scenarios.features.parse_feature`) and
  asks :meth:`Engine.plain_capability`, :meth:`Engine.shape_capability`,
  :meth:`Engine.joint_capability` or :meth:`Engine.pair_capability`; an answer of None (the
  engine does not know the feature) is UNSUPPORTED with the same reason in every engine
  (:func:`unknown_feature`);
- :meth:`Engine._run`, which runs a supported scene into a
  :class:`~clearbench.adapters.trajectory.Trajectory` (recording it with
  :class:`~clearbench.adapters.recording.SampleRecorder` where it steps in this process).

:meth:`Engine.run` is the one entry point: options checked, unsupported scenes answered with
an UNSUPPORTED trajectory and their reasons, then ``_run``. Failures of a run are statuses
(crashed, diverged, ...) with messages; exceptions are for misuse (unknown preset, unknown option
or bad option value).
"""

from __future__ import annotations

import enum
import importlib
import time
from abc import ABC, abstractmethod
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, ClassVar

from clearbench.adapters.options import OptionTable
from clearbench.adapters.recording import step_count
from clearbench.adapters.stepping import StepRunner, step_loop
from clearbench.adapters.trajectory import RunStatus, Trajectory
from clearbench.scenarios.features import FeatureKind, parse_feature
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.units import SI
from clearbench.scenarios.validation import LENGTH, TIME


class Support(enum.Enum):
    NATIVE = "native"
    APPROXIMATED = "approximated"
    UNSUPPORTED = "unsupported"


@dataclass(frozen=True)
class Capability:
    """How an engine handles one scene feature."""

    support: Support
    detail: str = ""


#: What every engine that lines a bore with pieces does with a partial bore's ``depth`` (how
#: far its solid reaches behind the surface: deeper partners are behind it, not in it).
BORE_DEPTH_NOTE = ("a bore's depth is not modelled: the lining's own thickness stands for the "
                   "solid behind the surface")


def unknown_feature(engine: str, feature: str) -> Capability:
    """The answer of every engine for a feature it does not know."""
    return Capability(Support.UNSUPPORTED,
                      f"the {engine} adapter does not know feature {feature!r}")


@dataclass(frozen=True)
class RunSettings:
    """What a run asks of an engine (times in the scene's time unit).

    ``time_step`` and ``horizon`` default to the scene's; ``record_every`` keeps one sample
    every that many steps (the last step is always kept); ``options`` are engine-specific
    overrides of the preset.
    """

    time_step: float | None = None
    horizon: float | None = None
    record_every: int = 1
    options: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.time_step is not None and not self.time_step > 0:
            raise ValueError(f"time_step must be > 0, got {self.time_step!r}")
        if self.horizon is not None and not self.horizon > 0:
            raise ValueError(f"horizon must be > 0, got {self.horizon!r}")
        if self.record_every < 1:
            raise ValueError(f"record_every must be >= 1, got {self.record_every!r}")


@dataclass(frozen=True)
class FeatureQuery:
    """What the capability hooks of an engine are asked about: the scene and the run options
    (for a :class:`ModuleEngine`, its settings resolved from the preset and the options).
    Engines that derive more from them once per scene (a MuJoCo tree plan) return their own
    object from :meth:`Engine.feature_context`."""

    scene: Scene
    options: Mapping = field(default_factory=dict)


class Engine(ABC):
    """An engine with a preset, able to run scenes (see the module docstring).

    Parameters
    ----------
    preset : str
        A key of :attr:`PRESETS`; ValueError naming the known presets otherwise.
    """

    #: Engine name, as in results (``name[preset]``).
    name: ClassVar[str] = ""
    #: Named presets: preset -> option values it sets (each a separate engine variant).
    PRESETS: ClassVar[Mapping[str, Mapping]] = {"default": {}}
    #: The options a run may set (``RunSettings.options``): name, type, range, choices.
    OPTIONS: ClassVar[OptionTable] = OptionTable("", ())
    #: Whether contacts are rigid (impulses, no contact spring: nonsmooth engines) rather than
    #: compliant; recorded in each trajectory's metadata as ``rigid_contacts``. A rigid engine
    #: stores no elastic energy in its contacts (``harness.measure.series.contact_energy``).
    #: An engine subpackage sets it from its declaration to the harness
    #: (``HARNESS_DEFAULTS.rigid_contacts``, :mod:`clearbench.adapters.harness_defaults`).
    RIGID_CONTACTS: ClassVar[bool] = False

    def __init__(self, preset: str = "default"):
        if preset not in self.PRESETS:
            raise ValueError(f"unknown {self.name} preset {preset!r}; presets: "
                             f"{list(self.PRESETS)}")
        self.preset = preset

    @property
    def label(self) -> str:
        """``engine[preset]`` as used in results."""
        return f"{self.name}[{self.preset}]"

    def check_options(self, options: Mapping | None) -> None:
        """:class:`~clearbench.adapters.options.OptionError` (a ValueError) naming the first
        option of ``options`` the engine does not have, or whose value its declaration
        (:attr:`OPTIONS`) refuses, or that does not go with the preset and the other options
        (:meth:`check_option_combination`)."""
        self.OPTIONS.check(options)
        self.check_option_combination(dict(options or {}))

    def check_option_combination(self, options: Mapping) -> None:
        """OptionError when options valid one by one do not go together with the preset or
        with each other (default: they always do)."""
        return None

    # ------------------------------------------------------------------ capabilities
    def capabilities(self, scene: Scene, options: Mapping | None = None
                     ) -> dict[str, Capability]:
        """Support of each feature of ``scene.features`` with the preset and ``options``
        (checked first: OptionError naming the option and value)."""
        options = dict(options or {})
        self.check_options(options)
        return self.checked_capabilities(scene, options)

    def checked_capabilities(self, scene: Scene, options: Mapping) -> dict[str, Capability]:
        """:meth:`capabilities` with ``options`` already checked (:meth:`check_options`: by
        the run's spec, :mod:`clearbench.harness.run.spec`)."""
        context = self.feature_context(scene, options)
        problems = self.feature_problems(context)
        out = {}
        for text in sorted(scene.features):
            if problems.get(text):
                out[text] = Capability(Support.UNSUPPORTED, "; ".join(problems[text]))
                continue
            feature = parse_feature(text)
            if feature.kind is FeatureKind.PAIR:
                capability = self.pair_capability(context, *feature.parts)
            elif feature.kind is FeatureKind.SHAPE:
                capability = self.shape_capability(context, *feature.parts)
            elif feature.kind is FeatureKind.JOINT:
                capability = self.joint_capability(context, *feature.parts)
            else:
                capability = self.plain_capability(context, *feature.parts)
            out[text] = capability if capability is not None else unknown_feature(self.name,
                                                                                  text)
        return out

    def feature_context(self, scene: Scene, options: Mapping) -> Any:
        """What the capability hooks receive (default: a :class:`FeatureQuery`)."""
        return FeatureQuery(scene, options)

    def feature_problems(self, context) -> Mapping[str, Sequence[str]]:
        """Features of the scene this engine cannot represent here, whatever their kind,
        with the reasons (feature text -> reasons; default: none)."""
        return {}

    def plain_capability(self, context, name: str) -> Capability | None:
        """Support of a plain feature (``friction``, ``drivers``, ...); None: not known."""
        return None

    def shape_capability(self, context, kind: str) -> Capability | None:
        """Support of the shape kind ``kind`` (feature ``shape:<kind>``); None: not known."""
        return None

    def joint_capability(self, context, kind: str) -> Capability | None:
        """Support of the ideal joint kind ``kind`` (feature ``joint:<kind>``); None: not
        known."""
        return None

    def pair_capability(self, context, kind_a: str, kind_b: str) -> Capability | None:
        """Support of contacts between shape kinds ``kind_a`` <= ``kind_b`` (feature
        ``pair:<a>-<b>``); None: not known."""
        return None

    def unsupported_reasons(self, scene: Scene, options: Mapping | None = None) -> list[str]:
        """Why the scene cannot run here with ``options`` (empty when it can)."""
        return [
            f"{feature}: {capability.detail}"
            for feature, capability in sorted(self.capabilities(scene, options).items())
            if capability.support is Support.UNSUPPORTED
        ]

    # ------------------------------------------------------------------ running
    def run(self, scene: Scene, settings: RunSettings | None = None,
            capabilities: Mapping[str, Capability] | None = None) -> Trajectory:
        """Run ``scene``; an unsupported scene gives an UNSUPPORTED trajectory, not an error.

        ``capabilities``: the engine's :meth:`capabilities` for this scene and these options,
        computed once by the caller that checked the options (the harness's run spec); None:
        the options are checked and the capabilities computed here.

        Raises
        ------
        OptionError
            An option the engine does not have, or a value it refuses (before anything
            runs).
        """
        settings = settings or RunSettings()
        if capabilities is None:
            self.check_options(settings.options)
            capabilities = self.checked_capabilities(scene, settings.options)
        reasons = [f"{feature}: {capability.detail}"
                   for feature, capability in sorted(capabilities.items())
                   if capability.support is Support.UNSUPPORTED]
        if reasons:
            return Trajectory.empty(self.name, self.preset, scene, RunStatus.UNSUPPORTED,
                                    "; ".join(reasons))
        trajectory = self._run(scene, settings)
        trajectory.rigid_contacts = bool(self.RIGID_CONTACTS)
        trajectory.engine_version = self.version()
        return trajectory

    def version(self) -> str:
        """The engine and its version as the ``availability()`` of its adapter's package
        states them ('' when the package has no probe)."""
        package = importlib.import_module(type(self).__module__.rpartition(".")[0]
                                          or type(self).__module__)
        probe = getattr(package, "availability", None)
        return str(probe()[1]) if probe is not None else ""

    @abstractmethod
    def _run(self, scene: Scene, settings: RunSettings) -> Trajectory:
        """Run a supported scene with checked options."""


class ModuleEngine(Engine):
    """An engine whose run options are the fields of one settings object resolved from its
    preset (:attr:`RESOLVE_SETTINGS`), and whose capability hooks are the functions of one
    module (:attr:`CAPABILITIES`: ``plain_capability``, ``shape_capability``,
    ``joint_capability``, ``pair_capability``, each taking the context first, and where the
    engine needs them ``feature_context(scene, settings)`` (default: a :class:`FeatureQuery`
    of the scene and the resolved settings) and ``feature_problems(context)`` (default:
    none)), as every engine of the repository is built.
    """

    #: The engine's capabilities module.
    CAPABILITIES: ClassVar[Any] = None
    #: ``resolve(preset, options) -> settings`` (values checked by the settings object).
    RESOLVE_SETTINGS: ClassVar[Any] = None

    def settings(self, options: Mapping | None = None) -> Any:
        """The preset overridden by ``options`` (checked against :attr:`OPTIONS` by the
        settings object: OptionError naming the option and value)."""
        self.OPTIONS.check(options)
        return self.resolve(options)

    def resolve(self, options: Mapping | None) -> Any:
        """The preset overridden by ``options`` as the engine's settings object (which checks
        the values it holds: OptionError naming the option and value)."""
        return type(self).RESOLVE_SETTINGS(self.preset, options)

    def check_option_combination(self, options: Mapping) -> None:
        self.resolve(options)

    def run_settings(self, scene: Scene, settings: RunSettings) -> Any:
        """The settings of one run of ``scene``: :meth:`resolve_run_settings` with
        ``settings.options`` checked first (OptionError naming the option and value)."""
        self.check_options(settings.options)
        return self.resolve_run_settings(scene, settings)

    def resolve_run_settings(self, scene: Scene, settings: RunSettings) -> Any:
        """The settings of one run of ``scene``, its options already checked (by
        :meth:`Engine.run`): the preset overridden by ``settings.options``. An engine whose
        settings depend on the scene (tolerances relative to its sizes) overrides it."""
        return self.resolve(settings.options)

    def capability_scene(self, scene: Scene, settings) -> Scene:
        """The scene the capabilities are stated for (default: as given; an engine that
        models it in other units returns it rescaled)."""
        return scene

    def feature_context(self, scene: Scene, options: Mapping) -> Any:
        settings = self.resolve(options)
        scene = self.capability_scene(scene, settings)
        make = getattr(self.CAPABILITIES, "feature_context", None)
        return make(scene, settings) if make else FeatureQuery(scene, settings)

    def feature_problems(self, context) -> Mapping[str, Sequence[str]]:
        problems = getattr(self.CAPABILITIES, "feature_problems", None)
        return problems(context) if problems else {}

    def plain_capability(self, context, name: str) -> Capability | None:
        return self.CAPABILITIES.plain_capability(context, name)

    def shape_capability(self, context, kind: str) -> Capability | None:
        return self.CAPABILITIES.shape_capability(context, kind)

    def joint_capability(self, context, kind: str) -> Capability | None:
        return self.CAPABILITIES.joint_capability(context, kind)

    def pair_capability(self, context, kind_a: str, kind_b: str) -> Capability | None:
        return self.CAPABILITIES.pair_capability(context, kind_a, kind_b)


class BuildError(Exception):
    """The engine refused the scene while building it: a CRASHED run with this message
    (raised by :meth:`SteppingEngine.build`)."""


class SteppingEngine(ModuleEngine):
    """A :class:`ModuleEngine` that steps in this process: the one template of a new engine
    (docs/engines/adding.md). The base does the bookkeeping of a run (scipy's
    ``OdeSolver.step`` / ``_step_impl`` model): settings resolved once, the scene in the
    engine's internal units, step and horizon converted to them, build and stepping timed
    apart, the step loop (:func:`~clearbench.adapters.stepping.step_loop`: steps taken,
    recording cadence, guards, divergence), the recorded samples converted back into a
    :class:`Trajectory`. The engine supplies the hooks :meth:`build`, :meth:`runner` (its
    :class:`~clearbench.adapters.stepping.StepRunner`: what one step, a state read-out and a
    contact read-out are for it) and :meth:`metadata` (and, where it needs them,
    :meth:`internal_scene`, :meth:`release`, :meth:`steps_taken`, :meth:`rebuild_overlap`).

    Two engines keep a driver of their own, outside this template: the reference solver,
    whose whole time loop is compiled (numba; a Python runner called once per step would
    cost it more than its step, and its Python step loop is the compiled loop's oracle,
    :mod:`clearbench.adapters.reference.run`), and Siconos, which steps in a worker process
    under Debian's interpreter that cannot import clearbench (:mod:`clearbench.adapters.siconos`):
    both implement :meth:`Engine._run` and return the trajectory.
    """

    #: The engine's name in prose (``"MuJoCo"``), for notes of the run.
    TITLE: ClassVar[str] = ""

    def _run(self, scene: Scene, settings: RunSettings) -> Trajectory:
        config = self.resolve_run_settings(scene, settings)
        start = time.perf_counter()
        internal = self.internal_scene(scene, config)
        to_internal = scene.units.factor_to(internal.units, TIME)
        dt = (settings.time_step or scene.time_step) * to_internal
        horizon = (settings.horizon or scene.horizon) * to_internal
        steps = step_count(horizon, dt)
        try:
            built = self.build(internal, config, dt)
        except BuildError as error:
            return Trajectory.empty(self.name, self.preset, scene, RunStatus.CRASHED,
                                    str(error), time_step=dt / to_internal)
        try:
            runner = self.runner(internal, built, config, steps, settings.record_every)
            build_seconds = time.perf_counter() - start
            status, message = step_loop(runner, steps)
        finally:
            self.release(built)
        monitor = runner.monitor
        to_scene = internal.units.factor_to(scene.units, LENGTH)
        overlap = {name: depth * to_scene
                   for name, depth in self.rebuild_overlap(built).items() if depth > 0.0}
        return monitor.recorder.trajectory(
            scene, dt, recorded_units=internal.units, engine=self.name, preset=self.preset,
            build_seconds=build_seconds, stepping_seconds=monitor.stepping_seconds,
            steps=self.steps_taken(runner, steps, dt), status=status, message=message,
            internal_units=internal.units.describe(), **monitor.statistics(),
            rebuild_overlap=overlap, metadata=self.metadata(scene, internal, config, built,
                                                           runner))

    # ------------------------------------------------------------------ hooks
    def internal_scene(self, scene: Scene, config) -> Scene:
        """The scene in the units the engine works in (default: SI when the settings'
        ``internal_units`` is ``"SI"``, else the scene's own)."""
        if config.internal_units == "SI" and scene.units != SI:
            return scene.rescaled(SI)
        return scene

    @abstractmethod
    def build(self, internal: Scene, config, dt: float) -> Any:
        """The engine's model of ``internal`` with step ``dt`` (internal units); BuildError
        when the engine refuses it."""

    @abstractmethod
    def runner(self, internal: Scene, built, config, steps: int,
               record_every: int) -> StepRunner:
        """The engine's runner of this run (``Runner(internal, built, config, steps,
        record_every)`` of its ``run.py``)."""

    @abstractmethod
    def metadata(self, scene: Scene, internal: Scene, config, built, runner) -> dict:
        """The engine's notes of the run (settings, guards, solver statistics, ...)."""

    def rebuild_overlap(self, built) -> Mapping[str, float]:
        """Per contact pair name, how deep the exact surfaces can overlap while the model's
        rebuilt shapes only touch [internal length] (:attr:`Trajectory.rebuild_overlap`;
        default: the built model's ``rebuild_overlap`` mapping, or every pair exact)."""
        return getattr(built, "rebuild_overlap", {})

    def release(self, built) -> None:
        """Free what the model holds outside Python (default: nothing)."""

    def steps_taken(self, runner, steps: int, dt: float) -> int:
        """Steps the run took of its ``steps`` of ``dt`` (default: as the monitor counted)."""
        return runner.monitor.steps_taken
