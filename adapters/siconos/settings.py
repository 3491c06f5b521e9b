"""Presets and options of the Siconos engine (each a separate engine variant ``siconos[preset]``;
what they mean: :mod:`.engine`)."""

from __future__ import annotations

from collections.abc import Mapping

from clearbench.adapters.options import OptionTable, boolean, choice, integer, number
from clearbench.scenarios.scales import feature_lengths
from clearbench.scenarios.scene import Scene

PRESETS: dict[str, dict] = {
    "default": {"theta": 0.5, "projection": False, "solver": "nsgs"},
    "projection": {"theta": 0.5, "projection": True, "solver": "nsgs"},
    "nsn-ac": {"theta": 0.5, "projection": False, "solver": "nsn-ac"},
}
#: Defaults of the options every preset shares.
DEFAULTS: dict = {
    "tolerance": 1e-10,
    "max_iterations": 10_000,
    "newton_iterations": 50,     # Siconos's default
    "newton_tolerance": 1e-6,    # Siconos's default
    "projection_max_iterations": 50,
    "projection_solver": "enum",
    "contact_frame": "shared",
    # GenericMechanical's handling of equality rows (iparam ISREDUCED), see
    # SiconosEngine.run_settings.
    "gmp_reduction": "auto",
    "timeout": 3600.0,
    "fault": "",
}
SOLVERS = ("nsgs", "nsn-ac")
CONTACT_FRAMES = ("shared", "siconos-builtin")
PROJECTION_SOLVERS = ("enum", "pgs")
FAULTS = ("", "segfault", "hang", "exception")
GMP_REDUCTIONS = ("auto", "gs", "substitute", "assemble", "mlcp")
#: Type, range and allowed values of every option (lengths [L] in the scene's unit; theta: the
#: theta-method in (0, 1]; tolerance: Siconos's normalised residual; timeout [s]).
OPTIONS = OptionTable("siconos", (
    number("theta", above=0.0, at_most=1.0),
    boolean("projection"),
    choice("solver", SOLVERS),
    number("tolerance", above=0.0),
    integer("max_iterations", at_least=1),
    integer("newton_iterations", at_least=1),
    number("newton_tolerance", above=0.0),
    integer("projection_max_iterations", at_least=1),
    choice("projection_solver", PROJECTION_SOLVERS),
    choice("contact_frame", CONTACT_FRAMES),
    choice("gmp_reduction", GMP_REDUCTIONS),
    number("timeout", above=0.0),
    choice("fault", FAULTS),
    number("constraint_tolerance", above=0.0),
    number("activation_threshold", at_least=0.0),
))
OPTION_NAMES = OPTIONS.names


def resolve_settings(preset: str, options: Mapping | None = None) -> dict:
    """Defaults, then the preset, then ``options`` (checked by the caller against
    :data:`OPTIONS`), before the scene is known."""
    resolved = dict(DEFAULTS)
    resolved.update(PRESETS[preset])
    resolved.update(options or {})
    return resolved


def resolve_options(preset: str, scene: Scene, options: Mapping | None = None) -> dict:
    """:func:`resolve_settings` completed for ``scene``: tolerances relative to its smallest
    feature and GenericMechanical's handling of equality rows."""
    options = resolve_settings(preset, options)
    lengths = feature_lengths(scene)
    smallest = min(lengths) if lengths else 1.0
    # 1e-8 of the smallest feature (docs/engines/siconos.md: about 1e-8 works): far
    # below what the metrics resolve, far enough above round-off that the projection loop
    # terminates.
    options.setdefault("constraint_tolerance", 1e-8 * smallest)
    # MoreauJeanOSI activates a contact when y + h/2 y' <= threshold; Siconos's 0 lets a
    # resting contact flicker off on round-off (a box resting on a plane then rocks and
    # sinks 14 um at the first steps); 1e-10 of the smallest feature, as the reference's
    # activation margin, removes that and is far below any gap the metrics resolve.
    options.setdefault("activation_threshold", 1e-10 * smallest)
    if options["gmp_reduction"] == "auto":
        # Assembling the equality rows with the contacts converged in one sweep on the
        # Flores slider, where Gauss-Seidel over all blocks (Siconos's default) needed 10^4
        # sweeps per step and stalled at 1e-7 (joint rows redundant with guide contacts);
        # but an assembled system with redundant joint rows (a planar closed loop rebuilt
        # in 3D) is singular: the slider-crank aborted on NaN. Gauss-Seidel there.
        options["gmp_reduction"] = "gs" if "closed_loop" in scene.features else "assemble"
    return options
