"""Presets and run options of the reference engine, resolved into the stepper's settings.

Presets (each a separate engine variant in results):

- ``default``: theta = 1/2, combined projection on, NSGS with exact Alart–Curnier local solves
  switching to the semismooth Newton solver when NSGS stalls (``hybrid``), tolerance 1e-12
  (|F| / max(|q|, |r|, |u|)), impacts with e > 0 localised at their crossing time.
- ``no-projection``: plain Moreau–Jean (Moreau's activation g + h/2 u_N <= 0), no impact
  localisation (it needs the activation loop of the projection).
- ``nsgs``: as default with NSGS alone.
- ``newton``: as default with the semismooth Newton one-step solver.
- ``implicit``: theta = 1 (more dissipative, unconditionally stable for stiff springs).

Options (``RunSettings.options``) override: ``theta``, ``projection``, ``method``,
``tolerance``, ``max_iterations``, ``position_tolerance``, ``activation_margin`` (default
1e-10 x the smallest feature: contacts open by less at a step's start are active from its
start), ``activation`` (``gap``, the study's rule; ``held``: the first activation round also
holds the contacts that carried an impulse in the previous step while open by at most
``activation_hold``, default 1e-2 x the smallest feature; ``predicted``: also the contacts the
free motion closes within the step; ref_solver/activation.py),
``restitution_threshold`` (default 2 |g| h: slower impacts are plastic),
``joint_law`` (``midpoint`` or ``end``), ``localise_impacts`` (true or false; every preset
with the projection has it on: an impact with e > 0 is applied at its crossing time within the
step instead of over the whole step, which takes the bouncing-ball apex errors at h = 1e-3 s
from 8e-3 to 2e-5),
``roundoff_floor``, ``step_loop`` (``auto``, ``python`` or ``compiled``: :mod:`.run`) and
``proximal_rescue`` (default 1e-8: an attempt of the hybrid chain by proximal-point Newton
when its Newton attempts (from NSGS's end, the warm start and zero) failed, its weight
relative to W's largest diagonal entry, ref_solver/fc3d_proximal.py; 0: off),
``hybrid_last_sweeps`` (default 100: the sweeps of each of the hybrid chain's two last NSGS
attempts, after everything else failed; ``max_iterations`` is the ``nsgs`` method's cap) and
``max_projection_iterations`` (default 100, the projection's Gauss–Newton cap); see
:class:`~clearbench.ref_solver.stepper.StepperSettings`.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from clearbench.adapters.base import RunSettings
from clearbench.adapters.options import OptionTable, boolean, choice, integer, number
from clearbench.ref_solver.activation import RULES as ACTIVATION_RULES
from clearbench.ref_solver.contact_problem import METHODS, SolverOptions
from clearbench.ref_solver.fc3d_proximal import DEFAULT_RELATIVE_WEIGHT
from clearbench.ref_solver.stepper import StepperSettings
from clearbench.scenarios.scales import feature_lengths
from clearbench.scenarios.scene import Scene

PRESETS: dict[str, dict] = {
    "default": {"theta": 0.5, "projection": True, "method": "hybrid", "localise_impacts": True},
    "no-projection": {"theta": 0.5, "projection": False, "method": "hybrid",
                      "localise_impacts": False},
    "nsgs": {"theta": 0.5, "projection": True, "method": "nsgs", "localise_impacts": True},
    "newton": {"theta": 0.5, "projection": True, "method": "newton", "localise_impacts": True},
    "implicit": {"theta": 1.0, "projection": True, "method": "hybrid", "localise_impacts": True},
}
#: Type, range and allowed values of every option (theta: the theta-method is stable for
#: [1/2, 1]; tolerance: relative residual; position_tolerance [L]; restitution_threshold [L/T]).
OPTIONS = OptionTable("reference", (
    number("theta", at_least=0.5, at_most=1.0),
    boolean("projection"),
    choice("method", ("hybrid", *METHODS)),
    number("tolerance", above=0.0),
    integer("max_iterations", at_least=1),
    number("position_tolerance", above=0.0),
    number("activation_margin", above=0.0),
    choice("activation", tuple(ACTIVATION_RULES)),
    number("activation_hold", at_least=0.0),
    number("restitution_threshold", at_least=0.0),
    choice("joint_law", ("midpoint", "end")),
    boolean("localise_impacts"),
    boolean("roundoff_floor"),
    choice("step_loop", ("auto", "python", "compiled")),
    number("proximal_rescue", at_least=0.0),
    integer("hybrid_last_sweeps", at_least=1),
    integer("max_projection_iterations", at_least=1),
))
OPTION_NAMES = OPTIONS.names


def stepper_settings(preset: str, scene: Scene, settings: RunSettings) -> StepperSettings:
    """The preset overridden by ``settings.options`` (names and values checked by the engine
    against :data:`OPTIONS`), with tolerances relative to the scene's smallest feature."""
    options = dict(PRESETS[preset])
    localise = settings.options.get("localise_impacts")
    options.update(settings.options)
    if localise is None:
        # The preset's choice, where it applies: localisation needs the projection.
        options["localise_impacts"] = options["localise_impacts"] and \
            bool(options["projection"])
    lengths = feature_lengths(scene)
    smallest = min(lengths) if lengths else 1.0
    largest = max(lengths) if lengths else 1.0
    method = options["method"]
    solver = SolverOptions(method="nsgs" if method == "hybrid" else method,
                           tolerance=float(options.get("tolerance", 1e-12)),
                           max_iterations=int(options.get("max_iterations", 10_000)),
                           # a residual below its own rounding error is a solution; on
                           # by default, ``roundoff_floor=false`` asks for the tolerance
                           # alone (fc3d_residual.roundoff_floor)
                           roundoff_floor=bool(options.get("roundoff_floor", True)))
    return StepperSettings(
        time_step=settings.time_step or scene.time_step,
        theta=float(options["theta"]),
        projection=bool(options["projection"]),
        solver=solver,
        # 1e-10 of the smallest feature (a clearance, an offset, a radius): far below
        # anything the metrics resolve, far above round-off of positions.
        position_tolerance=float(options.get("position_tolerance", 1e-10 * smallest)),
        activation_margin=float(options.get("activation_margin", 1e-10 * smallest)),
        activation=str(options.get("activation", "gap")),
        # 1e-2 of the smallest feature (1e-5 mm on the C-60): on c60-on at 1 us it holds the
        # contacts that reopen by round-off and close again (docs/reference-solver-speed.md).
        activation_hold=float(options.get("activation_hold", 1e-2 * smallest)),
        length_scale=largest,
        method=method,
        joint_law=str(options.get("joint_law", "midpoint")),
        localise_impacts=options["localise_impacts"],
        proximal_rescue=float(options.get("proximal_rescue", DEFAULT_RELATIVE_WEIGHT)),
        # The iteration caps: StepperSettings' own defaults unless set.
        **{cap: int(options[cap]) for cap in ("hybrid_last_sweeps", "max_projection_iterations")
           if cap in options},
        # Bounces slower than two steps' worth of gravity cannot be resolved by the fixed
        # step; they are taken as plastic so that bodies come to rest (see StepperSettings).
        restitution_threshold=float(options.get(
            "restitution_threshold",
            2.0 * float(np.linalg.norm(scene.gravity)) * (settings.time_step
                                                           or scene.time_step))),
    )


def resolve_settings(preset: str, options: Mapping | None = None) -> dict:
    """The preset overridden by ``options`` (checked by the engine against :data:`OPTIONS`),
    before the scene is known: what the capability functions are given."""
    return {**PRESETS[preset], **(options or {})}
