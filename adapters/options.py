"""The one declaration form of engine run options: each option's type, range and allowed values.

Every engine declares its options as an :class:`OptionTable` of :class:`OptionSpec` (built with
:func:`integer`, :func:`number`, :func:`boolean`, :func:`choice`, :func:`numbers`), and the base
class (:meth:`clearbench.adapters.base.Engine.check_options`) checks a run's options against it
before anything runs: an unknown name or a value of the wrong type, outside its range or not
among its choices raises :class:`OptionError` naming the engine, the option, the value and what
is allowed (the harness turns it into exit status 2). Engines whose settings are a dataclass run
the same table on the resolved settings (:meth:`OptionTable.check_settings`), so presets are
held to the same declarations.

Bounds are open (``above``, ``below``) or closed (``at_least``, ``at_most``); a number is a
finite real (an integer value is accepted where a number is asked), an integer refuses
booleans and floats; ``optional`` accepts None (the setting's "engine decides").
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass


class OptionError(ValueError):
    """A bad run option: ``<engine> option NAME=VALUE: must be ...``."""

    def __init__(self, engine: str, name: str, value, reason: str):
        self.engine = engine
        self.name = name
        self.value = value
        self.reason = reason
        super().__init__(f"{engine} option {name}={value!r}: {reason}")


@dataclass(frozen=True)
class OptionSpec:
    """What one option accepts.

    Attributes
    ----------
    name : str
    kind : {'integer', 'number', 'boolean', 'choice', 'numbers'}
        'numbers': a sequence of ``length`` finite numbers.
    above, at_least, below, at_most : float or None
        Open and closed bounds of an integer or a number (each element of 'numbers').
    choices : tuple
        Allowed values of a 'choice'.
    length : int
        Length of a 'numbers' value.
    optional : bool
        None is accepted too.
    """

    name: str
    kind: str
    above: float | None = None
    at_least: float | None = None
    below: float | None = None
    at_most: float | None = None
    choices: tuple = ()
    length: int = 0
    optional: bool = False

    def allowed(self) -> str:
        """What the option accepts, in words (``an integer >= 1``, ``a number in (0, 1]``)."""
        if self.kind == "boolean":
            text = "true or false"
        elif self.kind == "choice":
            text = "one of " + ", ".join(repr(c) for c in self.choices)
        else:
            noun = {"integer": "an integer", "number": "a finite number",
                    "numbers": f"{self.length} finite numbers"}[self.kind]
            text = f"{noun}{self._range_text()}"
        return text + (" (or none)" if self.optional else "")

    def _range_text(self) -> str:
        low = (self.above, "(", ">") if self.above is not None else (
            (self.at_least, "[", ">=") if self.at_least is not None else None)
        high = (self.below, ")", "<") if self.below is not None else (
            (self.at_most, "]", "<=") if self.at_most is not None else None)
        each = " each" if self.kind == "numbers" else ""
        if low and high:
            return f"{each} in {low[1]}{low[0]:g}, {high[0]:g}{high[1]}"
        if low:
            return f"{each} {low[2]} {low[0]:g}"
        if high:
            return f"{each} {high[2]} {high[0]:g}"
        return ""

    def problem(self, value) -> str | None:
        """Why ``value`` is not accepted (None when it is)."""
        if value is None and self.optional:
            return None
        if self.kind == "boolean":
            ok = isinstance(value, bool)
        elif self.kind == "choice":
            ok = any(value == c and type(value) is type(c) for c in self.choices)
        elif self.kind == "numbers":
            ok = (isinstance(value, list | tuple) and len(value) == self.length
                  and all(self._in_range(v) for v in value))
        elif self.kind == "integer":
            ok = isinstance(value, int) and not isinstance(value, bool) and \
                self._in_range(value)
        else:
            ok = self._in_range(value)
        return None if ok else f"must be {self.allowed()}"

    def _in_range(self, value) -> bool:
        if isinstance(value, bool) or not isinstance(value, int | float):
            return False
        return (math.isfinite(value)
                and (self.above is None or value > self.above)
                and (self.at_least is None or value >= self.at_least)
                and (self.below is None or value < self.below)
                and (self.at_most is None or value <= self.at_most))


def integer(name: str, *, at_least: int | None = None, at_most: int | None = None,
            optional: bool = False) -> OptionSpec:
    """An integer option within closed bounds."""
    return OptionSpec(name, "integer", at_least=at_least, at_most=at_most, optional=optional)


def number(name: str, *, above: float | None = None, at_least: float | None = None,
           below: float | None = None, at_most: float | None = None,
           optional: bool = False) -> OptionSpec:
    """A finite real option within open (``above``, ``below``) or closed bounds."""
    return OptionSpec(name, "number", above=above, at_least=at_least, below=below,
                      at_most=at_most, optional=optional)


def boolean(name: str) -> OptionSpec:
    """A true / false option."""
    return OptionSpec(name, "boolean")


def choice(name: str, choices: Iterable) -> OptionSpec:
    """An option taking one of ``choices``."""
    return OptionSpec(name, "choice", choices=tuple(choices))


def numbers(name: str, length: int, **bounds) -> OptionSpec:
    """A sequence of ``length`` finite numbers (each within ``bounds``, as :func:`number`)."""
    return OptionSpec(name, "numbers", length=length, **bounds)


class OptionTable:
    """The options of one engine, by name, in declaration order.

    Parameters
    ----------
    engine : str
        The engine's name (in error messages).
    specs : iterable of OptionSpec
    """

    def __init__(self, engine: str, specs: Iterable[OptionSpec]):
        self.engine = engine
        self.specs: dict[str, OptionSpec] = {}
        for spec in specs:
            if spec.name in self.specs:
                raise ValueError(f"{engine}: option {spec.name!r} declared twice")
            self.specs[spec.name] = spec

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(self.specs)

    def check(self, options: Mapping | None) -> None:
        """:class:`OptionError` for the first unknown option or bad value of ``options``."""
        for name, value in (options or {}).items():
            spec = self.specs.get(name)
            if spec is None:
                raise OptionError(self.engine, name, value,
                                  f"unknown {self.engine} option; options: "
                                  f"{', '.join(self.names)}")
            reason = spec.problem(value)
            if reason:
                raise OptionError(self.engine, name, value, reason)

    def check_settings(self, settings) -> None:
        """Check every declared option on the attributes of a resolved settings object."""
        self.check({name: getattr(settings, name) for name in self.names})
