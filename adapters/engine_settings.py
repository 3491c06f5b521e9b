"""The settings base of every engine that steps in this process: the fields the shared step loop
reads (the energy guard's tolerance and interval), the model's internal units, the check of
every field against the engine's option table and the plain-dict form kept in a run's
metadata. An engine's settings dataclass derives from :class:`EngineSettings` (with
:class:`~clearbench.adapters.primitive_pieces.PieceSettings` where it builds rings and bores
from primitives), adds its own fields, lists them in its option table with
:data:`GUARD_OPTIONS`, and names that table in its ``OPTIONS`` class attribute
(:func:`checked_by`).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import ClassVar

from clearbench.adapters.options import OptionTable, integer, number

__all__ = ["GUARD_OPTIONS", "EngineSettings"]

#: The option entries of :class:`EngineSettings`'s guard fields, for every engine's table.
GUARD_OPTIONS = (number("energy_gain_tolerance", above=0.0), integer("guard_interval", at_least=1))


@dataclass(frozen=True)
class EngineSettings:
    """Every option of a stepping engine's run that the shared loop reads.

    Attributes
    ----------
    energy_gain_tolerance : float
        Energy above its initial value by more than this fraction of the energy scale stops
        the run as diverged, on scenes whose energy may only decrease
        (:class:`~clearbench.adapters.energy_guard.EnergyGuard`).
    guard_interval : int
        Steps between energy checks (also checked at every recorded sample).
    internal_units : str
        The units the engine's model works in (``"SI"``, ``"scene"``, ...: the engine's
        option table lists its choices; the engine converts the results back).
    """

    energy_gain_tolerance: float = 0.1
    guard_interval: int = 10
    internal_units: str = "SI"

    #: The engine's option table: type, range and allowed values of every field.
    OPTIONS: ClassVar[OptionTable | None] = None

    def __post_init__(self) -> None:
        if self.OPTIONS is not None:
            self.OPTIONS.check_settings(self)

    def as_dict(self) -> dict:
        """Plain-dict form for trajectory metadata."""
        return {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}

