"""The unit of every stored figure of a run, for the tables that print them (``clearbench run``,
the report's per-scene tables).

A figure is either dimensioned (exponents of length, mass, time: written in the scene's own
units, ``mm/ms``) or a ratio, which says what it is relative to (``of the radial clearance``).
Run figures (:mod:`.figures`) are keyed by name; expectation figures (``EXPECTATION.FIGURE``)
by the expectation's kind and the figure's name, because the same name means different things
in two kinds (``energy_drift``: relative to m g d in ``pendulum``, an energy in
``energy_conserved``); ``output_error.NAME`` has the unit of output NAME. A figure missing from
these tables has no stated unit (:func:`figure_unit` returns None), never a guessed one.
"""

from __future__ import annotations

from dataclasses import dataclass

from clearbench.harness.measure.figures import ENERGY_BALANCE
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.units import UnitSystem
from clearbench.scenarios.validation import ACCELERATION, FORCE, LENGTH, TIME, VELOCITY

#: Exponents (length, mass, time) of an energy (a force times a length).
ENERGY = (2, 1, -2)


@dataclass(frozen=True)
class FigureUnit:
    """A dimension (exponents of length, mass, time), or a ratio with what it is of (``of``),
    or a plain count / angle / number (``word``: ``rad``, ``count``, ``-``)."""

    dimension: tuple | None = None
    of: str = ""
    word: str = ""

    def text(self, units: UnitSystem) -> str:
        """The unit as printed beside a value, in ``units`` (``mm``, ``of energy_scale``)."""
        if self.dimension is not None:
            return dimension_text(self.dimension, units)
        if self.of:
            return f"of {self.of}"
        return self.word

    def short(self, units: UnitSystem) -> str:
        """The unit in a table header: ``mm``, ``rel.``, ``rad`` (empty for counts)."""
        if self.dimension is not None:
            return dimension_text(self.dimension, units)
        if self.of:
            return "rel."
        return "" if self.word in COUNT_WORDS else self.word


#: Words of plain counts (no unit in a table header).
COUNT_WORDS = ("count", "steps", "iterations")


def _of(what: str) -> FigureUnit:
    return FigureUnit(of=what)


L, T, V, A, E = (FigureUnit(LENGTH), FigureUnit(TIME), FigureUnit(VELOCITY),
                 FigureUnit(ACCELERATION), FigureUnit(ENERGY))
RAD, COUNT, PURE = FigureUnit(word="rad"), FigureUnit(word="count"), FigureUnit(word="-")

#: Run figures (harness/measure/figures.py) -> unit.
RUN_FIGURES: dict[str, FigureUnit] = {
    "penetration_max": L, "penetration_beyond_rebuild_max": L,
    "penetration_relative": _of("the pair's smallest feature"),
    "penetration_swept_max": L, "clearance_eccentricity_max": L, "clearance_excess_max": L,
    "clearance_excess_relative": _of("the radial clearance"), "joint_distance_max": L,
    "joint_angle_max": RAD, "driver_offset_max": L, "driver_angle_offset_max": RAD,
    "quaternion_norm_error_max": PURE, "stiction_displacement": L, "stiction_creep_rate": V,
    "energy_scale": E, "energy_drift": _of("energy_scale"), "energy_growth": _of("energy_scale"),
    "energy_growth_contact_free": _of("energy_scale"), "error": _of("the reference value"),
    "solver_unconverged_steps": FigureUnit(word="steps"),
    "solver_residual_max": FigureUnit(word="engine's measure"),
    "solver_iterations_mean": FigureUnit(word="iterations"),
    "instrument_penetration_max": L, "instrument_resolution_max": L,
    "instrument_difference_max": L, "instrument_clearance_excess_max": L,
    "unseen_penetration": L, "unseen_penetration_time": T,
}

_STICK = {"displacement": L, "creep_rate": V}
#: Expectation kind -> figure -> unit (harness/measure/expectation_figures.py).
EXPECTATION_FIGURES: dict[str, dict[str, FigureUnit]] = {
    "bounce_apex": {"apex_max_relative_error": _of("the expected apex"), "rest_time": T,
                    "height_after_rest": L},
    "incline_stick": _STICK,
    "sticks": _STICK,
    "incline_slide": {"acceleration": A, "expected_acceleration": A,
                      "acceleration_relative_error": _of("the expected acceleration"),
                      "displacement_max_error": L},
    "sliding_stop": {"stop_distance": L, "expected_stop_distance": L, "stop_distance_error": L,
                     "stop_time": T, "stop_time_error": T, "slide_after_stop": L,
                     "final_speed": V},
    "rolling_transition": {"onset_time": T, "onset_time_error": T, "final_speed": V,
                           "final_speed_relative_error": _of("the expected final speed")},
    "pendulum": {"energy_drift": _of("m g d"), "expected_period": T, "period": T,
                 "period_relative_error": _of("the expected period")},
    "torque_free": {"angular_momentum_drift": _of("|L0|"),
                    "energy_drift": _of("the initial kinetic energy"),
                    "quaternion_norm_error": PURE, "flips": COUNT},
    "slider_crank": {"slider_position_max_error": L,
                     "slider_position_relative_error": _of("the crank length")},
    "approaches_ideal": {"clearance_excess": L,
                         "clearance_excess_relative": _of("the radial clearance"),
                         "eccentricity_max": L},
    "rocking_ratio": {"expected_ratio": PURE, "impacts": COUNT, "ratio_first_impact": PURE,
                      "ratio_relative_error": _of("the expected ratio")},
    "energy_non_increasing": {"energy_growth": E, "energy_growth_relative": _of("energy_scale")},
    "energy_balance": {"energy_growth": E, "energy_growth_relative": _of("energy_scale")},
    "rolling_incline": {"distance": L, "expected_distance": L,
                        "distance_relative_error": _of("the expected distance"),
                        "expected_acceleration": A, "expected_final_speed": V,
                        "slip_speed_max": V},
    "output_value": {"time": T},
    "energy_conserved": {"energy_drift": E, "energy_drift_relative": _of("energy_scale")},
    "no_penetration": {"penetration_max": L},
}


def dimension_text(dimension: tuple, units: UnitSystem) -> str:
    """``(1, 0, -1)`` in mm-g-ms -> ``mm/ms``; a force in a system whose force is the newton
    -> ``N``, an energy -> ``N*mm`` (``J`` in SI)."""
    force = units.force_unit()
    if tuple(dimension) == FORCE and force == "N":
        return "N"
    if tuple(dimension) == ENERGY and force == "N":
        return "J" if units.length == "m" else f"N*{units.length}"
    parts = {"up": [], "down": []}
    length, mass, time = dimension
    for name, exponent in ((units.mass, mass), (units.length, length), (units.time, time)):
        if exponent:
            power = f"^{abs(exponent)}" if abs(exponent) != 1 else ""
            parts["up" if exponent > 0 else "down"].append(f"{name}{power}")
    text = "*".join(parts["up"]) or "1"
    return text + ("/" + "/".join(parts["down"]) if parts["down"] else "")


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
    kinds = {ENERGY_BALANCE: ENERGY_BALANCE, **dict(expectation_kinds or {})}
    if scene is not None:
        kinds.update({e.name: e.kind for e in scene.expectations})
        output_unit = _output_value_unit(scene, head, figure)
        if output_unit is not None:
            return output_unit
    table = EXPECTATION_FIGURES.get(kinds.get(head, ""), {})
    if figure.startswith("apex_") and figure.endswith("_relative_error"):
        figure = "apex_max_relative_error"  # apex_K_relative_error: the same ratio per bounce
    return table.get(figure)


def _output_value_unit(scene: Scene, expectation: str, figure: str) -> FigureUnit | None:
    """The unit of an ``output_value`` expectation's value figures: its output's."""
    exp = next((e for e in scene.expectations if e.name == expectation), None)
    if exp is None or exp.kind != "output_value" or figure not in OUTPUT_VALUE_FIGURES:
        return None
    output = next((o for o in scene.outputs if o.name == exp.output), None)
    if output is None:
        return None
    return RAD if output.kind == "body_angle" else FigureUnit(tuple(output.dimension))


#: Figures of an ``output_value`` expectation in the unit of its output.
OUTPUT_VALUE_FIGURES = ("value", "expected", "deviation", "tolerance")


def unit_text(name: str, scene: Scene | None, expectation_kinds: dict[str, str] | None = None,
              short: bool = False) -> str:
    """The unit of figure ``name`` in ``scene``'s units (SI without a scene), as printed
    beside a value (``short``: as in a table header); "" when none is stated."""
    unit = figure_unit(name, scene, expectation_kinds)
    if unit is None:
        return ""
    units = scene.units if scene is not None else UnitSystem()
    return unit.short(units) if short else unit.text(units)
