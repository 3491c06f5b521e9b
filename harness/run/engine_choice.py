"""Engine choices as users write them (``mujoco[elliptic]``), resolved and checked before any
engine runs.

An engine is found through :data:`clearbench.adapters.ENGINES`, or through extra adapter
modules given by the caller (``{"mine": "my_package.my_adapter"}``), which follow the same
contract (:mod:`clearbench.adapters.base`): ``availability() -> (bool, str)`` and
``create(preset) -> Engine``. The preset and the option names are checked by the engine itself
(``create`` refuses an unknown preset, ``Engine.check_options`` unknown options and values its
declaration refuses), here turned into input errors naming the field.
"""

from __future__ import annotations

import importlib
import re
from collections.abc import Mapping
from dataclasses import dataclass

from clearbench.adapters import ENGINES, engine_availability
from clearbench.adapters.harness_defaults import HarnessDefaults, declared_defaults
from clearbench.adapters.options import OptionError

_LABEL = re.compile(r"^\s*([A-Za-z0-9_.-]+)\s*(?:\[\s*([A-Za-z0-9_.+-]*)\s*\])?\s*$")


class RunInputError(ValueError):
    """Bad input to a run (unknown scene, engine or preset, bad setting): names the field and
    the value at fault. Raised before any engine runs."""

    def __init__(self, field: str, value, reason: str):
        self.field = field
        self.value = value
        self.reason = reason
        super().__init__(f"{field} = {value!r}: {reason}")


@dataclass(frozen=True)
class EngineChoice:
    """A resolved engine: its name, preset, adapter module path and what it said about itself."""

    name: str
    preset: str
    module: str
    detail: str

    @property
    def label(self) -> str:
        """``name[preset]`` as used in results."""
        return f"{self.name}[{self.preset}]"


def parse_engine_label(text: str, field: str = "engine") -> tuple[str, str]:
    """``'mujoco[elliptic]'`` -> ``('mujoco', 'elliptic')``; ``'reference'`` -> default preset."""
    match = _LABEL.match(str(text))
    if not match:
        raise RunInputError(field, text,
                            "expected ENGINE or ENGINE[PRESET], e.g. reference[newton]")
    name, preset = match.group(1), match.group(2)
    return name, preset or "default"


def engine_module_path(name: str, extra_modules: Mapping[str, str] | None = None) -> str:
    """Fully qualified adapter module of engine ``name``."""
    if extra_modules and name in extra_modules:
        return extra_modules[name]
    if name in ENGINES:
        return ENGINES[name]
    known = sorted(set(ENGINES) | set(extra_modules or {}))
    raise RunInputError("engine", name, f"unknown engine; engines: {', '.join(known)}")


def engine_names(extra_modules: Mapping[str, str] | None = None) -> list[str]:
    """Every engine of :data:`~clearbench.adapters.ENGINES`, then those of ``extra_modules``
    (a name in both is the extra module's), in that order."""
    return list(dict.fromkeys([*ENGINES, *(extra_modules or {})]))


def engine_defaults(name: str, extra_modules: Mapping[str, str] | None = None
                    ) -> HarnessDefaults:
    """What engine ``name`` declares to the harness (its module's ``HARNESS_DEFAULTS``,
    :mod:`clearbench.adapters.harness_defaults`); imports the adapter's subpackage or module,
    which imports neither its engine modules nor the engine's package.

    Raises
    ------
    RunInputError
        Unknown engine, or a module that fails to load or declares something else.
    """
    module_path = engine_module_path(name, extra_modules)
    try:
        return declared_defaults(importlib.import_module(module_path))
    except Exception as error:  # a plug-in that cannot even load is bad input
        raise RunInputError("engine", name,
                            f"adapter {module_path} failed to load: {error}") from None


def resolve_engine(text: str, extra_modules: Mapping[str, str] | None = None,
                   options: Mapping | None = None, field: str = "engine") -> EngineChoice:
    """Parse, find, and check an engine choice (availability, preset, option names).

    Raises
    ------
    RunInputError
        Unknown engine, engine not available here, unknown preset or option, bad option value.
    """
    name, preset = parse_engine_label(text, field)
    module_path = engine_module_path(name, extra_modules)
    if extra_modules and name in extra_modules:
        try:
            module = importlib.import_module(module_path)
            available, detail = module.availability()
        except Exception as error:  # an adapter that cannot even report is unavailable
            raise RunInputError(field, text, f"adapter {module_path} failed to load: {error}") \
                from None
    else:
        availability = engine_availability(name)
        available, detail = availability.available, availability.detail
        module = importlib.import_module(module_path) if available else None
    if not available:
        raise RunInputError(field, text, f"engine not available here: {detail}")
    try:
        engine = module.create(preset)
    except Exception as error:  # the engine's own preset check (Engine.__init__)
        raise RunInputError(f"{field} preset", preset, f"{name} refused it: {error}") \
            from None
    _check_engine_options(engine, options)
    return EngineChoice(name, preset, module_path, str(detail))


def check_options(choice: EngineChoice, options: Mapping | None) -> None:
    """RunInputError when the engine of ``choice`` does not have an option of ``options`` or
    refuses its value."""
    if options:
        engine = importlib.import_module(choice.module).create(choice.preset)
        _check_engine_options(engine, options)


def _check_engine_options(engine, options: Mapping | None) -> None:
    """The engine's own option check (``Engine.check_options``: names, types, ranges and
    allowed values from its declaration, :mod:`clearbench.adapters.options`) as an input
    error naming the engine, the option and the value."""
    try:
        engine.check_options(options)
    except OptionError as error:
        raise RunInputError(f"{error.engine} option {error.name}", error.value,
                            error.reason) from None
    except ValueError as error:  # an engine outside the package with its own check
        raise RunInputError(f"{engine.name} options", dict(options or {}), str(error)) \
            from None
