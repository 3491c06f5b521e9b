"""Expectation kinds, each declared once as a :class:`~.registry.MeasuredKind` in one
registry (:data:`~.registry.KINDS`), from which every table about kinds is read.

Importing this package registers the library's kinds, grouped by what they are about:
:mod:`.impacts`, :mod:`.friction`, :mod:`.mechanisms`, :mod:`.edges` (a body crossing the
bound of a face), :mod:`.invariants` (energy, penetration and the implied energy checks) and
:mod:`.outputs`.

How to add a kind
-----------------
In one module: declare its scene side (an
:class:`~clearbench.scenarios.expectation_kinds.ExpectationKind`: parameters with dimension
and domain, relations, statement), write its figure handler ``(scene, trajectory,
expectation) -> (figures, headline, note)`` and its criterion
(:class:`~clearbench.harness.measure.criteria.Criterion`: the words and the judge), and call
:func:`register` with a :class:`MeasuredKind` that holds them, the units of its figures, its
analytic-error figure if it has one and its table columns. Nothing else changes:
``tests/expectation_kind_example.py`` is such a module, measured, judged, tabled and reported
by the harness as it is. A kind of the library whose scenes use it declares its scene side in
:mod:`clearbench.scenarios.expectation_kinds` (scenes are validated without the harness) and
its measuring side in a module here.
"""

from __future__ import annotations

from clearbench.harness.measure.kinds import (  # noqa: F401  (each registers its kinds)
    edges,
    friction,
    impacts,
    invariants,
    mechanisms,
    outputs,
)
from clearbench.harness.measure.kinds.registry import (
    KINDS,
    Figures,
    MeasuredKind,
    TableColumn,
    implied_kinds,
    measured_kind,
    register,
    registered,
    unmeasured_declarations,
    unregister,
)

__all__ = ["KINDS", "Figures", "MeasuredKind", "TableColumn", "implied_kinds",
           "measured_kind", "register", "registered", "unmeasured_declarations", "unregister"]
