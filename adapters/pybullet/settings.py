"""PyBullet presets and run options, validated before any run.

Pure Python (no ``pybullet`` import): the capabilities and the checks of a run can be stated
without a physics server.

Every field of :class:`PybulletSettings` is an option (``RunSettings.options``) that overrides
the preset. Lengths, velocities and forces are in the model's internal units (SI unless
``internal_units = 'scene'``), because PyBullet's tolerances are absolute (0.001 m margins,
1e-5 m slop, -0.04 m split-impulse threshold, 0.2 m/s restitution threshold) except
``contactBreakingThreshold``, which is a factor on each shape's bounding radius.

Presets (each a separate engine variant ``pybullet[<preset>]``):

- ``default``: what a user gets who writes nothing beyond the scene's own values. PyBullet's
  server defaults (PhysicsServerCommandProcessor.cpp of bullet3 3.2.x, checked in the docs):
  50 iterations, residual threshold 1e-7, contactERP 0.08, erp 0.2, frictionERP 0.2, split
  impulse on but only below -0.04 m, breaking threshold 0.02 (process-global: set every run),
  slop 1e-5 m, restitution threshold 0.2 m/s, cone friction flag on, no deterministic pairs,
  warm-starting 0.1; bodies are Featherstone multibodies (``createMultiBody``'s default) with
  their default damping (0.04 linear and angular, multibodies only), joint speeds clamped at
  100 rad/s or m/s, 0.001 m margins on boxes, cylinders and planes, no friction anchors,
  speculative contacts (processing threshold BT_LARGE_FLOAT).
- ``tuned``: what an expert sets for accuracy: damping 0; bodies outside joint trees (with one
  contact pair of at most 16 pieces) as rigid bodies in maximal coordinates, whose contacts use
  split impulse, always (threshold 1e9 m); restitution threshold and slop 0; friction anchors;
  200 iterations and residual threshold 1e-24 (PyBullet's 1e-7 is on the largest squared
  velocity change of a row in a sweep: it stops at 0.3 mm/s, i.e. 0.3 um per step of 1 ms);
  deterministic overlapping pairs; joint speed clamp
  1e6; margins 0.01 of the smallest feature (clearance, offset, box or cylinder size); model
  units chosen so that the smallest feature is at least 0.001 units (mm-g-ms below 1 mm); and
  speculative contacts cut to 1 um (contactProcessingThreshold 1e-6 m: with PyBullet's
  unlimited ones a ball with e > 0 rebounds before it arrives and ends hovering, e = 0.9 lost
  its bounces after the 4th; with 0 resting contacts flicker and a box on the incline creeps 40
  instead of 9 um; the docs), at the price of an impact penetration of up to one step's travel.

Joint motors are switched off in both presets (``switch_off_joint_motors``): leaving them on is
not a physical choice but a trap, and the run stops with a guard when one is left on.
"""

from __future__ import annotations

from dataclasses import dataclass

from clearbench.adapters.engine_settings import GUARD_OPTIONS, EngineSettings
from clearbench.adapters.options import OptionTable, boolean, choice, integer, number
from clearbench.adapters.primitive_pieces import PIECE_OPTIONS, PieceSettings

#: Compound shapes of PyBullet keep at most this many children (MAX_COMPOUND_COLLISION_SHAPES of
#: SharedMemoryCommands.h); more are dropped silently (docs/engines/pybullet.md).
MAX_COMPOUND_CHILDREN = 16

#: Named presets; each is a separate engine variant ``pybullet[<preset>]`` in results.
PRESETS: dict[str, dict] = {
    "default": {},
    "tuned": {
        "num_solver_iterations": 200,
        "solver_residual_threshold": 1e-24,
        "split_impulse_penetration_threshold": 1e9,
        "contact_slop": 0.0,
        "restitution_velocity_threshold": 0.0,
        "deterministic_overlapping_pairs": True,
        "body_model": "rigid",
        "linear_damping": 0.0,
        "angular_damping": 0.0,
        "max_joint_velocity": 1e6,
        "friction_anchor": True,
        "collision_margin_relative": 0.01,
        "contact_processing_threshold": 1e-6,
        "internal_units": "auto",
    },
}


@dataclass(frozen=True)
class PybulletSettings(PieceSettings, EngineSettings):
    """Every option of a PyBullet run (internal units, SI by default).

    Attributes
    ----------
    num_solver_iterations : int
        ``numSolverIterations``: sweeps of the sequential-impulse solver per step.
    solver_residual_threshold : float
        ``solverResidualThreshold``: the solver stops when the largest squared velocity change
        of a row in a sweep falls below it [(L / T)^2].
    warm_starting_factor : float
        ``warmStartingFactor`` (PyBullet sets 0.1, Bullet's own default is 0.85).
    contact_erp : float
        ``contactERP`` (Bullet's erp2): Baumgarte factor of contact penetration, and of the
        split-impulse position pass.
    erp : float
        ``erp``: Baumgarte factor of joints and constraints (loop closures, motors). PyBullet's
        ``changeConstraint(erp=...)`` does not change point-to-point constraints: this global
        value does (docs/engines/pybullet.md).
    friction_erp : float
        ``frictionERP``: position correction of friction anchors.
    global_cfm : float
        ``globalCFM``: constraint force mixing of every row.
    use_split_impulse : bool
        ``useSplitImpulse``: rigid-body contacts correct penetration in a separate position
        pass that adds no velocity (multibody contacts never do).
    split_impulse_penetration_threshold : float
        ``splitImpulsePenetrationThreshold`` [L]: split impulse applies only to penetrations
        deeper than minus this (-0.04 m: only below 4 cm; 1e9: always).
    contact_breaking_threshold : float
        ``contactBreakingThreshold``: factor on each shape's bounding-sphere radius below which
        contact points are kept (relative, process-global; set before every run).
    contact_slop : float
        ``contactSlop`` [L]: penetration tolerated without correction.
    restitution_velocity_threshold : float
        ``restitutionVelocityThreshold`` [L/T]: impacts slower than this do not bounce.
    enable_cone_friction : bool
        ``enableConeFriction`` (acts only with two friction directions, which PyBullet's solver
        mode does not enable).
    deterministic_overlapping_pairs : bool
        ``deterministicOverlappingPairs``: sort the broadphase pairs.
    body_model : {'multibody', 'rigid'}
        How bodies outside joint trees are built: Featherstone multibodies (PyBullet's
        default) or rigid bodies in maximal coordinates where possible (one contact pair of at
        most 16 pieces, no joint, no driver).
    linear_damping, angular_damping : float or None
        Body damping (``changeDynamics``); None leaves PyBullet's (0.04 for multibodies, 0 for
        rigid bodies).
    max_joint_velocity : float or None
        ``maxJointVelocity`` of every multibody [1/T or L/T]; None leaves PyBullet's 100.
    friction_anchor : bool
        ``frictionAnchor`` on every collision object: friction also corrects the drift of the
        contact point (``friction_erp``).
    contact_processing_threshold : float or None
        ``contactProcessingThreshold`` [L]: contacts farther apart are not solved; None leaves
        BT_LARGE_FLOAT (speculative contacts up to the breaking threshold).
    collision_margin : float or None
        Margin of box, cylinder and plane pieces [L]; None leaves PyBullet's 0.001 m (spheres
        and capsules have their radius as margin and are not affected).
    collision_margin_relative : float or None
        Margin as this fraction of the scene's smallest feature (overrides
        ``collision_margin``).
    switch_off_joint_motors : bool
        Switch off the default velocity motor of every joint that is not driven.
    ring_pieces, ring_piece_radius, bore_pieces, bore_piece_radius, face_thickness,
    plane_box_size
        Rings, bores and bounded faces from primitives
        (:class:`clearbench.adapters.primitive_pieces.PieceSettings`).
    closure_spacing : float or None
        Distance between the two point-to-point constraints of a loop-closing revolute joint
        [L]; None: the larger radius of gyration of the two bodies.
    driver_max_force : float
        Force (torque) limit of a driver's velocity motor, relative to the driven body's
        weight m |g| times its largest size (or m x 1 L/T^2 without gravity).
    internal_units : {'SI', 'scene', 'mm-g-ms', 'auto'}
        Units of the PyBullet model. 'auto': SI when the scene's smallest feature is at least
        1 mm, else mm-g-ms: Bullet's GJK has an absolute resolution of about 1e-6 of its length
        unit (measured: a 100 um clearance reads 100.8 um in metres; the C-60's 2.6 um gap reads
        15 um in metres and 2.8 um in millimetres), and its default margin 0.001 must
        stay below every box and cylinder size.
    energy_gain_tolerance, guard_interval
        The shared energy guard (:class:`~clearbench.adapters.engine_settings.EngineSettings`).
    """

    num_solver_iterations: int = 50
    solver_residual_threshold: float = 1e-7
    warm_starting_factor: float = 0.1
    contact_erp: float = 0.08
    erp: float = 0.2
    friction_erp: float = 0.2
    global_cfm: float = 0.0
    use_split_impulse: bool = True
    split_impulse_penetration_threshold: float = -0.04
    contact_breaking_threshold: float = 0.02
    contact_slop: float = 1e-5
    restitution_velocity_threshold: float = 0.2
    enable_cone_friction: bool = True
    deterministic_overlapping_pairs: bool = False
    body_model: str = "multibody"
    linear_damping: float | None = None
    angular_damping: float | None = None
    max_joint_velocity: float | None = None
    friction_anchor: bool = False
    contact_processing_threshold: float | None = None
    collision_margin: float | None = None
    collision_margin_relative: float | None = None
    switch_off_joint_motors: bool = True
    closure_spacing: float | None = None
    driver_max_force: float = 1e6
    internal_units: str = "SI"



#: Type, range and allowed values of every field of :class:`PybulletSettings` (ERP factors and
#: damping are fractions per step: [0, 1]).
OPTIONS = OptionTable("pybullet", (
    integer("num_solver_iterations", at_least=1),
    number("solver_residual_threshold", at_least=0.0),
    number("warm_starting_factor", at_least=0.0, at_most=1.0),
    number("contact_erp", at_least=0.0, at_most=1.0),
    number("erp", above=0.0, at_most=1.0),
    number("friction_erp", at_least=0.0, at_most=1.0),
    number("global_cfm", at_least=0.0),
    boolean("use_split_impulse"),
    number("split_impulse_penetration_threshold"),
    number("contact_breaking_threshold", above=0.0),
    number("contact_slop", at_least=0.0),
    number("restitution_velocity_threshold", at_least=0.0),
    boolean("enable_cone_friction"),
    boolean("deterministic_overlapping_pairs"),
    choice("body_model", ("multibody", "rigid")),
    number("linear_damping", at_least=0.0, at_most=1.0, optional=True),
    number("angular_damping", at_least=0.0, at_most=1.0, optional=True),
    number("max_joint_velocity", above=0.0, optional=True),
    boolean("friction_anchor"),
    number("contact_processing_threshold", at_least=0.0, optional=True),
    number("collision_margin", above=0.0, optional=True),
    number("collision_margin_relative", above=0.0, optional=True),
    boolean("switch_off_joint_motors"),
    *PIECE_OPTIONS,
    number("closure_spacing", above=0.0, optional=True),
    number("driver_max_force", above=0.0),
    choice("internal_units", ("SI", "scene", "mm-g-ms", "auto")),
    *GUARD_OPTIONS,
))
PybulletSettings.OPTIONS = OPTIONS
OPTION_NAMES = OPTIONS.names


def resolve_settings(preset: str, options: dict | None = None) -> PybulletSettings:
    """Values of the preset (a key of :data:`PRESETS`) overridden by ``options`` (fields of
    :class:`PybulletSettings`; the engine checks their names, the dataclass their values:
    ValueError naming the option and value, before anything runs)."""
    values = dict(PRESETS[preset])
    values.update(options or {})
    return PybulletSettings(**values)
