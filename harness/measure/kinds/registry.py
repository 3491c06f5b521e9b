"""The one registry of expectation kinds: each kind is one :class:`MeasuredKind`, and every
table the harness keeps about kinds is read from it (the figure handlers that
:func:`~clearbench.harness.measure.expectation_figures.evaluate` calls, the criteria and their
words, the analytic-error figure, the units of the figures, the columns of the physics
tables).

A kind is either *declared*, written by a scene (its scene side, parameters with units and
domains, is a :class:`~clearbench.scenarios.expectation_kinds.ExpectationKind`), or *implied*,
judged on every run where it applies without a scene listing it (the energy balance).
"""

from __future__ import annotations

import contextlib
import fnmatch
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, field
from types import MappingProxyType

from clearbench.harness.measure.criteria import Criterion
from clearbench.harness.measure.quantities import FigureUnit
from clearbench.scenarios.expectation_kinds import (
    EXPECTATION_KINDS,
    ExpectationKind,
    declare_kind,
    withdraw_kind,
)

#: What a figure handler returns: (figures: name -> value in the scene's units, the name of the
#: headline figure, a note). A handler may add ``"where"`` (text: the place of the judged
#: figure) to the figures.
Figures = tuple[dict, str, str]


@dataclass(frozen=True)
class TableColumn:
    """A figure of a kind shown in the physics tables (``clearbench bench physics-table``):
    key in the kind's figures, label, display factor and unit (factor applied to values in SI
    scene units), and ``shown(parameters)``: whether the row applies to an expectation with
    those parameters (a rest height only for e = 0)."""

    key: str
    label: str
    factor: float = 1.0
    unit: str = ""
    shown: Callable[[Mapping], bool] = field(default=lambda parameters: True, compare=False)


@dataclass(frozen=True)
class MeasuredKind:
    """One expectation kind, declared once: everything the harness knows about it.

    Parameters
    ----------
    name : str
        The kind's name (a scene's ``kind``; an implied check's name).
    figures : callable
        Declared kinds: ``figures(scene, trajectory, expectation) -> Figures``; implied kinds:
        ``figures(scene, trajectory, run_figures) -> Figures or None`` (None: the check does
        not apply to this run). Figures in the scene's units, never a verdict.
    units : mapping figure name -> FigureUnit
        The unit of every figure the handler returns; a name may be an ``fnmatch`` pattern
        (``apex_*_relative_error``).
    criterion : Criterion
        What passes, in words, and the rule that judges the figures.
    declaration : ExpectationKind or None
        The scene side (parameters with dimensions and domains, statement); None for an
        implied kind.
    analytic_error : tuple of (figure, normaliser or None)
        The figure that is the run's relative error against the analytic solution (the first
        present is used), divided by the normaliser figure if one is named.
    table : tuple of TableColumn
        The figures the physics tables show.
    """

    name: str
    figures: Callable[..., Figures | None]
    units: Mapping[str, FigureUnit]
    criterion: Criterion
    declaration: ExpectationKind | None = None
    analytic_error: tuple[tuple[str, str | None], ...] = ()
    table: tuple[TableColumn, ...] = ()

    def __post_init__(self) -> None:
        object.__setattr__(self, "units", MappingProxyType(dict(self.units)))
        if self.declaration is not None and self.declaration.name != self.name:
            raise ValueError(f"kind {self.name!r}: its declaration is {self.declaration.name!r}")
        named = [f for f, _ in self.analytic_error] + [n for _, n in self.analytic_error if n]
        named += [column.key for column in self.table]
        unknown = [f for f in named if self.unit_of(f) is None]
        if unknown:
            raise ValueError(f"kind {self.name!r}: figures without a unit {unknown}")
        if not self.criterion.passes_when:
            raise ValueError(f"kind {self.name!r}: its criterion says nothing")

    @property
    def implied(self) -> bool:
        """An implied check (judged where it applies, never listed by a scene)."""
        return self.declaration is None

    def unit_of(self, figure: str) -> FigureUnit | None:
        """The unit of ``figure`` (None when the kind states none)."""
        if figure in self.units:
            return self.units[figure]
        for pattern, unit in self.units.items():
            if fnmatch.fnmatchcase(figure, pattern):
                return unit
        return None


#: Every expectation kind the harness measures and judges, in registration order.
KINDS: dict[str, MeasuredKind] = {}


def register(kind: MeasuredKind) -> MeasuredKind:
    """Add ``kind`` to :data:`KINDS` and its declaration to the scene's vocabulary
    (:data:`~clearbench.scenarios.expectation_kinds.EXPECTATION_KINDS`): one call makes a kind
    written by scenes, measured, judged, tabled and reported. A second kind under a taken
    name is refused."""
    known = KINDS.get(kind.name)
    if known is not None and known is not kind:
        raise ValueError(f"expectation kind {kind.name!r} registered twice")
    if kind.declaration is not None:
        declare_kind(kind.declaration)
    KINDS[kind.name] = kind
    return kind


def unregister(name: str) -> None:
    """Remove the kind ``name`` (and its declaration) from both registries."""
    kind = KINDS.pop(name, None)
    if kind is not None and kind.declaration is not None:
        withdraw_kind(name)


@contextlib.contextmanager
def registered(kind: MeasuredKind) -> Iterator[MeasuredKind]:
    """``kind`` registered for the duration of a ``with`` block (a test's kind)."""
    register(kind)
    try:
        yield kind
    finally:
        unregister(kind.name)


def measured_kind(name: str) -> MeasuredKind:
    """The kind called ``name``; KeyError naming the known kinds otherwise."""
    if name not in KINDS:
        raise KeyError(f"unknown expectation kind {name!r}; kinds: {', '.join(KINDS)}")
    return KINDS[name]


def implied_kinds() -> list[MeasuredKind]:
    """The implied checks, in registration order."""
    return [kind for kind in KINDS.values() if kind.implied]


def unmeasured_declarations() -> list[str]:
    """Kinds a scene may write that no registered kind measures (a gap to report)."""
    return sorted(set(EXPECTATION_KINDS) - {k for k, v in KINDS.items() if not v.implied})
