"""The unit of every stored figure of a run, for the tables that print them (``clearbench run``,
the report's per-scene tables).

A figure is either dimensioned (exponents of length, mass, time: written in the scene's own
units, ``mm/ms``) or a ratio, which says what it is relative to (``of the radial clearance``).
Run figures (:mod:`.figures`) are keyed by name (:data:`RUN_FIGURES`); expectation figures
(``EXPECTATION.FIGURE``) by the expectation's kind, whose declaration states their units
(:mod:`.kinds`), because the same name means different things in two kinds (``energy_drift``:
relative to m g d in ``pendulum``, an energy in ``energy_conserved``); ``output_error.NAME``
has the unit of output NAME. A figure missing from these has no stated unit
(:func:`figure_unit` returns None), never a guessed one.
"""

from __future__ import annotations

from clearbench.harness.measure.kinds import KINDS
from clearbench.harness.measure.kinds.outputs import OUTPUT_VALUE_FIGURES
from clearbench.harness.measure.quantities import (
    COUNT_WORDS,
    PURE,
    RAD,
    E,
    FigureUnit,
    L,
    T,
    V,
    dimension_text,
    of,
)
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.units import UnitSystem

__all__ = ["COUNT_WORDS", "RUN_FIGURES", "FigureUnit", "dimension_text", "figure_unit",
           "unit_text"]

#: Run figures (harness/measure/figures.py) -> unit.
RUN_FIGURES: dict[str, FigureUnit] = {
    "penetration_max": L, "penetration_beyond_rebuild_max": L,
    "penetration_relative": of("the pair's smallest feature"),
    "penetration_swept_max": L, "clearance_eccentricity_max": L, "clearance_excess_max": L,
    "clearance_excess_relative": of("the radial clearance"), "joint_distance_max": L,
    "joint_angle_max": RAD, "driver_offset_max": L, "driver_angle_offset_max": RAD,
    "quaternion_norm_error_max": PURE, "stiction_displacement": L, "stiction_creep_rate": V,
    "energy_scale": E, "energy_drift": of("energy_scale"), "energy_growth": of("energy_scale"),
    "energy_growth_contact_free": of("energy_scale"), "error": of("the reference value"),
    "solver_unconverged_steps": FigureUnit(word="steps"),
    "solver_residual_max": FigureUnit(word="engine's measure"),
    "solver_iterations_per_step": FigureUnit(word="iterations"),
    "instrument_penetration_max": L, "instrument_resolution_max": L,
    "instrument_difference_max": L, "instrument_clearance_excess_max": L,
    "unseen_penetration": L, "unseen_penetration_time": T,
}

def figure_unit(name: str, scene: Scene | None = None,
                expectation_kinds: dict[str, str] | None = None) -> FigureUnit | None:
    """The unit of figure ``name`` of a run (None when it has none stated here).

    Parameters
    ----------
    scene : Scene, optional
        For ``output_error.NAME`` (the unit of output NAME) and the expectation kinds.
    expectation_kinds : dict, optional
        Expectation name -> kind, when the scene is not at hand (a stored row's results).
    """
    if name in RUN_FIGURES:
        return RUN_FIGURES[name]
    head, _, figure = name.partition(".")
    if head == "output_error" and scene is not None:
        output = next((o for o in scene.outputs if o.name == figure), None)
        if output is not None:
            return RAD if output.kind == "body_angle" else FigureUnit(tuple(output.dimension))
        return None
    kinds = {kind.name: kind.name for kind in KINDS.values() if kind.implied}
    kinds.update(expectation_kinds or {})
    if scene is not None:
        kinds.update({e.name: e.kind for e in scene.expectations})
        output_unit = _output_value_unit(scene, head, figure)
        if output_unit is not None:
            return output_unit
    kind = KINDS.get(kinds.get(head, ""))
    return kind.unit_of(figure) if kind is not None else None


def _output_value_unit(scene: Scene, expectation: str, figure: str) -> FigureUnit | None:
    """The unit of an ``output_value`` expectation's value figures: its output's."""
    exp = next((e for e in scene.expectations if e.name == expectation), None)
    if exp is None or exp.kind != "output_value" or figure not in OUTPUT_VALUE_FIGURES:
        return None
    output = next((o for o in scene.outputs if o.name == exp.output), None)
    if output is None:
        return None
    return RAD if output.kind == "body_angle" else FigureUnit(tuple(output.dimension))


def unit_text(name: str, scene: Scene | None, expectation_kinds: dict[str, str] | None = None,
              short: bool = False) -> str:
    """The unit of figure ``name`` in ``scene``'s units (SI without a scene), as printed
    beside a value (``short``: as in a table header); "" when none is stated."""
    unit = figure_unit(name, scene, expectation_kinds)
    if unit is None:
        return ""
    units = scene.units if scene is not None else UnitSystem()
    return unit.short(units) if short else unit.text(units)
