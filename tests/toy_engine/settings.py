"""The toy's presets and options, checked before any run.

``contact_steps``: an impact lasts about that many steps (the contact spring's half period);
the shared fields (the energy guard, the model's units) come from
:class:`~clearbench.adapters.engine_settings.EngineSettings`.
"""

from __future__ import annotations

from dataclasses import dataclass

from clearbench.adapters.engine_settings import GUARD_OPTIONS, EngineSettings
from clearbench.adapters.options import OptionTable, choice, number

#: Named presets; each is a separate engine variant ``toy[<preset>]`` in results.
PRESETS: dict[str, dict] = {"default": {"contact_steps": 20.0}}


@dataclass(frozen=True)
class ToySettings(EngineSettings):
    """Every option of a toy run.

    Attributes
    ----------
    contact_steps : float
        Steps an impact lasts (the penalty spring's half period).
    internal_units : {'scene'}
        The toy works in the scene's own units (its stiffness and damping derive from the
        scene's masses and the step).
    energy_gain_tolerance, guard_interval
        The shared energy guard (:class:`~clearbench.adapters.engine_settings.EngineSettings`).
    """

    contact_steps: float = 20.0
    internal_units: str = "scene"


#: Type, range and allowed values of every field of :class:`ToySettings`.
OPTIONS = OptionTable("toy", (
    number("contact_steps", at_least=4.0),
    choice("internal_units", ("scene",)),
    *GUARD_OPTIONS,
))
ToySettings.OPTIONS = OPTIONS


def resolve_settings(preset: str, options: dict | None = None) -> ToySettings:
    """Values of the preset (a key of :data:`PRESETS`) overridden by ``options``."""
    return ToySettings(**{**PRESETS[preset], **dict(options or {})})
