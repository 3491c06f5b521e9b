"""Drake presets and run options, checked before any run. Pure Python (no ``pydrake`` import).

Drake's contact is compliant. A point-contact pair has a stiffness k [F/L] and a dissipation:
Hunt–Crossley d [T/L] (force k x (1 + d v), used by TAMSI, Lagged and Similar) or a linear
dissipation time constant tau [T] (force k (x + tau v), used by SAP). Where a geometry carries
no value the plant derives it from ``penetration_allowance`` (the static sink of the heaviest
body) and, for SAP, takes tau = 0.1 s. Per geometry, Drake combines stiffness in series
(k1 k2 / (k1 + k2)), SAP's tau as a sum, Hunt–Crossley d weighted by the stiffnesses and
friction as 2 mu1 mu2 / (mu1 + mu2); the adapter gives each pair side a geometry of its own
carrying 2k, tau / 2, d and mu, so that the pair gets exactly k, tau, d and mu
(:func:`side_material`).

Drake uses only the dynamic friction coefficient in discrete mode (the static one is ignored);
the adapter sets both to the pair's mu. Sliding below ``stiction_tolerance`` [L/T] is
regularised: a body that must stick creeps at up to that speed (the "stiction-tolerance creep").
"""

from __future__ import annotations

from dataclasses import dataclass

from clearbench.adapters.engine_settings import GUARD_OPTIONS, EngineSettings
from clearbench.adapters.options import OptionError, OptionTable, boolean, choice, number
from clearbench.adapters.primitive_pieces import PIECE_OPTIONS, PieceSettings

#: Drake's own MultibodyPlantConfig defaults (pydrake 1.51: ``MultibodyPlantConfig()``).
DRAKE_DEFAULTS = {
    "discrete_contact_approximation": "lagged",
    "contact_model": "hydroelastic_with_fallback",
    "penetration_allowance": 1e-3,
    "stiction_tolerance": 1e-4,
}

#: Named presets; each is a separate engine variant ``drake[<preset>]`` in results.
PRESETS: dict[str, dict] = {
    # What a user gets from MultibodyPlantConfig() with only the scene's friction on the
    # geometries: Lagged approximation, hydroelastic_with_fallback (point contact for these
    # primitives: none carries hydroelastic properties), stiffness and Hunt-Crossley
    # dissipation derived from penetration_allowance 1 mm, stiction_tolerance 1e-4 m/s.
    "default": {},
    # docs/engines/drake.md: SAP (convex: no step-size instability, constraints for loop
    # closures), point contact with a stiffness of 2 steps of contact time for the lightest
    # body in contact (near-rigid), dissipation time constant of 4 steps for e = 0 pairs (a
    # ball dropped 1 m rebounds 25 mm; 118 mm with one step), stiction tolerance 1e-6 m/s (SAP
    # ignores it; it acts when another approximation is chosen), and boxes as compliant
    # hydroelastic geometry against rigid half-spaces (point contact gives one point per
    # box-plane pair: the box rocks on a corner and creeps 0.86-1.8 mm in 1 s on the incline;
    # hydroelastic 0.5 um).
    "tuned": {
        "discrete_contact_approximation": "sap",
        "stiffness_steps": 2.0,
        "relaxation_steps": 4.0,
        "stiction_tolerance": 1e-6,
        "hydroelastic_boxes": True,
    },
}


@dataclass(frozen=True)
class DrakeSettings(PieceSettings, EngineSettings):
    """Every option of a Drake run (lengths in the model's internal units, SI).

    Attributes
    ----------
    discrete_contact_approximation : {'lagged', 'similar', 'sap', 'tamsi'}
        Drake's discrete contact solver / model approximation.
    contact_model : {'point', 'hydroelastic_with_fallback'}
        Contact geometry model; the adapter's primitives carry no hydroelastic properties, so
        both give point contact (recorded as Drake's choice).
    penetration_allowance : float
        [L] Static sink Drake aims at when it derives a stiffness itself (no stiffness set).
    stiction_tolerance : float
        [L/T] Slip speed below which friction is regularised.
    point_stiffness : float or None
        [F/L] Contact stiffness of every pair; None: ``stiffness_steps`` or Drake's estimate.
    stiffness_steps : float or None
        Stiffness from a contact period: k = m (pi / (steps dt))^2 with m the lightest moving
        body of the pair (a half period of the contact spring lasts ``steps`` steps). None:
        ``point_stiffness`` or Drake's estimate.
    hunt_crossley_dissipation : float or None
        [T/L] Dissipation of TAMSI, Lagged and Similar; None: Drake's estimate.
    relaxation_time : float or None
        [T] SAP's dissipation time constant; None: ``relaxation_steps`` or Drake's 0.1 s.
    relaxation_steps : float or None
        SAP's dissipation time constant in steps.
    sap_near_rigid_threshold : float
        SAP's near-rigid regime threshold (Drake's default 1).
    hydroelastic_boxes : bool
        Boxes (and faces built as boxes) become compliant hydroelastic geometry and planes
        rigid hydroelastic half-spaces (with ``contact_model = 'hydroelastic_with_fallback'``):
        a box-plane or box-box pair then touches on a pressure surface instead of Drake's
        single deepest point. The hydroelastic modulus is the pair stiffness times the box's
        smallest half extent over its largest face area.
    ring_pieces, ring_piece_radius, bore_pieces, bore_piece_radius, face_thickness,
    plane_box_size
        Rings, bores and bounded faces from primitives
        (:mod:`clearbench.adapters.primitive_pieces`).
    driver_armature_ratio : float
        Reflected inertia of a driven joint relative to its body's inertia (the coordinate is
        reset to its profile at each step start; the armature holds it during the step).
    energy_gain_tolerance, guard_interval
        The shared energy guard (:class:`~clearbench.adapters.engine_settings.EngineSettings`).
    adjacent_bodies_collision_filters : bool
        Drake's filter of contacts between bodies joined by a joint. The adapter sets False by
        default: the scene names the pairs that collide, and a pair between joined bodies is
        meant (guarded by a test).
    """

    discrete_contact_approximation: str = DRAKE_DEFAULTS["discrete_contact_approximation"]
    contact_model: str = DRAKE_DEFAULTS["contact_model"]
    penetration_allowance: float = DRAKE_DEFAULTS["penetration_allowance"]
    stiction_tolerance: float = DRAKE_DEFAULTS["stiction_tolerance"]
    point_stiffness: float | None = None
    stiffness_steps: float | None = None
    hunt_crossley_dissipation: float | None = None
    relaxation_time: float | None = None
    relaxation_steps: float | None = None
    sap_near_rigid_threshold: float = 1.0
    hydroelastic_boxes: bool = False
    driver_armature_ratio: float = 1e6
    adjacent_bodies_collision_filters: bool = False
    #: Units of the Drake model (not an option): Drake's defaults (penetration allowance,
    #: stiction tolerance, relaxation time) are absolute SI values.
    internal_units: str = "SI"

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.hydroelastic_boxes and self.contact_model == "point":
            raise OptionError("drake", "hydroelastic_boxes", True,
                              "needs contact_model 'hydroelastic_with_fallback' (with 'point' "
                              "Drake ignores hydroelastic properties)")


    @property
    def uses_sap_dissipation(self) -> bool:
        """True when the pair dissipation is SAP's time constant (else Hunt–Crossley's)."""
        return self.discrete_contact_approximation == "sap"


#: Type, range and allowed values of every field of :class:`DrakeSettings`.
OPTIONS = OptionTable("drake", (
    choice("discrete_contact_approximation", ("lagged", "similar", "sap", "tamsi")),
    choice("contact_model", ("point", "hydroelastic_with_fallback")),
    number("penetration_allowance", above=0.0),
    number("stiction_tolerance", above=0.0),
    number("point_stiffness", above=0.0, optional=True),
    number("stiffness_steps", above=0.0, optional=True),
    number("hunt_crossley_dissipation", at_least=0.0, optional=True),
    number("relaxation_time", at_least=0.0, optional=True),
    number("relaxation_steps", at_least=0.0, optional=True),
    number("sap_near_rigid_threshold", at_least=0.0),
    boolean("hydroelastic_boxes"),
    *PIECE_OPTIONS,
    number("driver_armature_ratio", above=0.0),
    *GUARD_OPTIONS,
    boolean("adjacent_bodies_collision_filters"),
))
DrakeSettings.OPTIONS = OPTIONS


def resolve_settings(preset: str, options: dict | None = None) -> DrakeSettings:
    """Values of the preset (a key of :data:`PRESETS`) overridden by ``options``.

    An explicit ``point_stiffness`` switches off the preset's ``stiffness_steps`` and an
    explicit ``relaxation_time`` its ``relaxation_steps`` unless given as well.
    """
    options = dict(options or {})
    values = dict(PRESETS[preset])
    if "point_stiffness" in options and "stiffness_steps" not in options:
        values.pop("stiffness_steps", None)
    if "relaxation_time" in options and "relaxation_steps" not in options:
        values.pop("relaxation_steps", None)
    values.update(options)
    return DrakeSettings(**values)
