"""What a run is: a scene, an engine with its preset, and run settings; and its deterministic key.

A :class:`RunSpec` is built by :func:`make_run_spec`, which validates everything (scene name and
parameters or scene file, engine, preset, time step, horizon, ...) and raises
:class:`~.engine_choice.RunInputError` naming the field and value at fault before any engine
runs. The run key is a sha256 of what determines the trajectory: the scene's content hash, the
engine, its preset, version and settings, and the physics sources
(:data:`clearbench.PHYSICS_SUBPACKAGES`): the same run asked twice (by any command) has the same
key, so the results store records it once and an interrupted sweep resumes where it stopped,
and an edit of the harness (measuring, report, CLI) reruns no engine. The measurement key
(:attr:`RunSpec.measure_key`) adds the measuring sources: a stored run whose measurement key
changed is measured again from its stored trajectory, and no engine runs.

The options are checked once, here (by the engine's own declaration); the run's capabilities
are computed once, from the spec (:attr:`RunSpec.capabilities`), and handed to the worker.
"""

from __future__ import annotations

import functools
import hashlib
import importlib
import importlib.metadata
import inspect
import json
import math
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

import clearbench
from clearbench.harness.run.engine_choice import (
    EngineChoice,
    RunInputError,
    check_options,
    resolve_engine,
)
from clearbench.scenarios.library import get_entry, scene_names
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.serialization import load_scene_file
from clearbench.scenarios.validation import SceneError

#: Wall-clock limit of one run when none is given [s].
DEFAULT_TIMEOUT = 600.0


def parse_assignment(text: str, field: str) -> tuple[str, object]:
    """``'key=value'`` -> ``(key, value)``, the value read as a TOML literal (number, boolean,
    string, array), or kept as a string when it is not one (``method=newton``)."""
    key, sep, raw = str(text).partition("=")
    key = key.strip()
    if not sep or not key:
        raise RunInputError(field, text, "expected KEY=VALUE")
    try:
        value = tomllib.loads(f"v = {raw.strip()}")["v"]
    except tomllib.TOMLDecodeError:
        value = raw.strip()
    if isinstance(value, list):
        value = tuple(value)
    return key, value


@dataclass(frozen=True)
class SceneSource:
    """Where a scene came from: a registry name with factory parameters, or a scene file."""

    registry_name: str | None = None
    parameters: tuple = ()
    file: str | None = None

    def describe(self) -> str:
        if self.file:
            return self.file
        if self.parameters:
            args = ", ".join(f"{k}={v!r}" for k, v in self.parameters)
            return f"{self.registry_name}({args})"
        return str(self.registry_name)

    def to_dict(self) -> dict:
        return {"registry_name": self.registry_name, "parameters": dict(self.parameters),
                "file": self.file}


def resolve_scene(scene: str | Path | Scene, parameters: Mapping | None = None) -> tuple[
        Scene, SceneSource]:
    """Build the scene: a :class:`Scene` as given, a registered name (with ``parameters`` for its
    factory) or a path to a TOML/JSON scene file.

    Raises
    ------
    RunInputError
        Unknown scene name or factory parameter, invalid scene, missing file.
    """
    parameters = dict(parameters or {})
    if isinstance(scene, Scene):
        if parameters:
            raise RunInputError("scene parameters", parameters,
                                "parameters apply only to registered scenes")
        return scene, SceneSource(registry_name=scene.name)
    text = str(scene)
    path = Path(text)
    if path.suffix.lower() in (".toml", ".json") or path.exists():
        if parameters:
            raise RunInputError("scene parameters", parameters,
                                "parameters apply only to registered scenes, not to files")
        if not path.is_file():
            raise RunInputError("scene", text, "no such scene file")
        try:
            return load_scene_file(path), SceneSource(file=str(path))
        except SceneError as error:
            raise RunInputError("scene", text, f"invalid scene file: {error}") from None
    try:
        entry = get_entry(text)
    except KeyError:
        raise RunInputError("scene", text, "neither a registered scene nor a scene file; "
                            f"registered scenes: {', '.join(scene_names())}") from None
    accepted = _factory_parameters(entry.factory)
    for key in parameters:
        if accepted is not None and key not in accepted:
            raise RunInputError(f"scene parameter {key!r}", parameters[key],
                                f"{text} takes {', '.join(accepted) or 'no parameters'}")
    try:
        built = entry.build(**parameters)
    except SceneError as error:
        raise RunInputError("scene", text, f"invalid with {parameters}: {error}") from None
    except (TypeError, ValueError, ZeroDivisionError) as error:
        raise RunInputError("scene parameters", parameters, f"{text}: {error}") from None
    return built, SceneSource(registry_name=text, parameters=tuple(sorted(parameters.items())))


def _factory_parameters(factory) -> list[str] | None:
    """Keyword parameters of a registry factory (through the registry's wrapper)."""
    target = getattr(factory, "__wrapped__", None) or factory
    closure = getattr(target, "__closure__", None) or ()
    for cell in closure:  # the registry wraps the library factory in a closure
        inner = cell.cell_contents
        if callable(inner) and hasattr(inner, "__code__") and inner is not target:
            target = inner
            break
    try:
        signature = inspect.signature(target)
    except (TypeError, ValueError):
        return None
    if any(p.kind is p.VAR_KEYWORD for p in signature.parameters.values()):
        return None
    return [name for name, p in signature.parameters.items()
            if p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)]


def _check_positive(field: str, value) -> float:
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise RunInputError(field, value, "must be a number") from None
    if not math.isfinite(number) or number <= 0:
        raise RunInputError(field, value, "must be finite and > 0")
    return number


def _jsonable(field: str, value):
    try:
        json.dumps(value, allow_nan=False)
    except (TypeError, ValueError):
        raise RunInputError(field, value, "must be plain JSON data (numbers, strings, lists)") \
            from None
    return value


@dataclass(frozen=True)
class RunSpec:
    """One fully resolved run.

    Attributes
    ----------
    scene : Scene
    source : SceneSource
    engine : EngineChoice
    time_step, horizon : float
        Resolved (the scene's own when not given) [scene time unit].
    record_every : int
        One sample kept every that many steps (the last one always).
    options : tuple of (str, value)
        Engine-specific overrides of the preset, sorted by name.
    timeout : float
        Wall-clock limit of the run in its worker [s] (not part of the key).
    campaign : str
        Which command or suite asked for it (``sweep``, ``stability``, ...; not part of the key).
    """

    scene: Scene
    source: SceneSource
    engine: EngineChoice
    time_step: float
    horizon: float
    record_every: int = 1
    options: tuple = ()
    timeout: float = DEFAULT_TIMEOUT
    campaign: str = field(default="", compare=False)

    @property
    def options_dict(self) -> dict:
        return dict(self.options)

    @property
    def key_fields(self) -> dict:
        """What determines the trajectory (hashed into :attr:`key`): the scene, the engine,
        its version and settings, the physics sources (:func:`clearbench.source_digest`),
        numpy's and numba's versions, and the source of an engine module outside the package
        (a plug-in)."""
        return {
            "physics": clearbench.source_digest(clearbench.PHYSICS_SUBPACKAGES),
            "libraries": _library_versions(),
            "plug_in": _plug_in_digest(self.engine.module),
            "scene_hash": self.scene.content_hash,
            "engine": self.engine.name,
            "engine_version": self.engine.detail,
            "preset": self.engine.preset,
            "time_step": float(self.time_step),
            "horizon": float(self.horizon),
            "record_every": int(self.record_every),
            "options": self.options_dict,
        }

    @property
    def key(self) -> str:
        """Deterministic run key: sha256 of the canonical JSON of :attr:`key_fields`, 24 hex."""
        return _digest(self.key_fields)

    @property
    def measure_key(self) -> str:
        """What determines the run's measurement, 24 hex: its run key and the measuring
        sources (:data:`clearbench.MEASURING_SOURCES`). (The run its error is measured
        against is the batch's choice: a stored measurement is served whatever it was.)"""
        return _digest({"run": self.key,
                        "measuring": clearbench.source_digest(clearbench.MEASURING_SOURCES)})

    @property
    def label(self) -> str:
        return f"{self.scene.name} {self.engine.label} dt={self.time_step:g}"

    @functools.cached_property
    def capabilities(self) -> dict[str, list[str]]:
        """Feature -> [support, detail] of the engine for this scene and options (computed
        once, when first asked: when the run is dispatched; the options were checked when the
        spec was made)."""
        engine = importlib.import_module(self.engine.module).create(self.engine.preset)
        return {feature: [capability.support.value, capability.detail]
                for feature, capability in sorted(
                    engine.checked_capabilities(self.scene, self.options_dict).items())}


def _digest(fields: Mapping) -> str:
    """sha256 of the canonical JSON of ``fields`` [hex, 24 chars]."""
    text = json.dumps(fields, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:24]


@functools.cache
def _library_versions() -> dict[str, str]:
    """The versions of the numerical libraries every engine's adapter computes with."""
    versions = {}
    for name in ("numpy", "numba"):
        try:
            versions[name] = importlib.metadata.version(name)
        except importlib.metadata.PackageNotFoundError:  # a source build without metadata
            versions[name] = "unknown"
    return versions


@functools.cache
def _plug_in_digest(module: str) -> str:
    """The source digest of an engine module outside clearbench (its package's modules, or
    the module); '' for an engine of the package (its sources are physics sources)."""
    if module == "clearbench" or module.startswith("clearbench."):
        return ""
    return clearbench.source_digest((module,))


def make_run_spec(scene: str | Path | Scene, engine: str, *,
                  scene_parameters: Mapping | None = None,
                  time_step: float | None = None, time_step_factor: float | None = None,
                  horizon: float | None = None, record_every: int = 1,
                  options: Mapping | None = None, timeout: float = DEFAULT_TIMEOUT,
                  extra_engine_modules: Mapping[str, str] | None = None,
                  engine_choice: EngineChoice | None = None,
                  campaign: str = "") -> RunSpec:
    """Validate every input of a run and return its :class:`RunSpec`.

    ``time_step`` [scene time unit] or ``time_step_factor`` (times the scene's comfortable step)
    default to the scene's step; ``horizon`` to the scene's horizon.

    Raises
    ------
    RunInputError
        Naming the field and value at fault.
    """
    built, source = resolve_scene(scene, scene_parameters)
    options = dict(options or {})
    for key, value in options.items():
        _jsonable(f"options.{key}", value)
    if engine_choice is not None:
        check_options(engine_choice, options)
    choice = engine_choice or resolve_engine(engine, extra_engine_modules, options)
    if time_step is not None and time_step_factor is not None:
        raise RunInputError("time_step", time_step, "give a time step or a factor, not both")
    if time_step is not None:
        dt = _check_positive("time_step", time_step)
    elif time_step_factor is not None:
        dt = _check_positive("time_step factor", time_step_factor) * built.time_step
    else:
        dt = built.time_step
    end = _check_positive("horizon", horizon) if horizon is not None else built.horizon
    if dt > end:
        raise RunInputError("time_step", dt, f"exceeds the horizon {end}")
    if isinstance(record_every, bool) or not isinstance(record_every, int) or record_every < 1:
        raise RunInputError("record_every", record_every, "must be an integer >= 1")
    limit = _check_positive("timeout", timeout)
    return RunSpec(built, source, choice, dt, end, record_every,
                   tuple(sorted(options.items())), limit, campaign)
