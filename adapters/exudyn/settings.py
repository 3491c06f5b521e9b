"""Exudyn presets, run options, and the contact-parameter rules (stiffness, restitution).

Pure Python (no ``exudyn`` import): capabilities and option errors are stated without building a
system.

Exudyn's per-pair contact connectors (``ObjectContactSphereSphere``,
``ObjectContactSphereTriangle``) are penalty springs with a restitution model and regularised
Coulomb friction:

- normal force ``k delta^n + lambda delta^n v_n + d v_n`` with the impact model's ``lambda``;
  the Gonthier / Carvalho-Martins model (``impactModel = 2``) reproduces Newton's e (measured:
  first-apex error -1.7 % ... +4 % for e 0.2-0.9), Hunt-Crossley (1) does not (+2 % at e 0.9,
  +75 % at e 0.5, +500 % at e 0.2) and the linear model (0) only damps with ``d``;
- ``lambda = k f(e) / max(v_min, v_impact)``: a contact that starts at rest has no impact
  velocity and, with ``v_min = 0`` (Exudyn's default), no damping at all;
- the restitution coefficient must be > 0: e = 0 pairs get ``plastic_restitution``;
- friction ``mu N v_t / v_reg`` below the regularisation velocity ``v_reg``
  (``frictionProportionalZone``): a body that should stick on an incline of angle theta creeps
  at ``v_reg tan(theta) / mu`` (measured exactly when the normal contact is damped);
- Exudyn's default stiffness is 0 (no contact at all): the adapter derives one (see
  :func:`contact_stiffness`).

Physical option values are stated in SI (``*_velocity`` in m/s) and converted to the model's
units by the builder; ratios and counts are dimensionless.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from clearbench.adapters.engine_settings import GUARD_OPTIONS, EngineSettings
from clearbench.adapters.options import OptionTable, boolean, choice, integer, number

#: Named presets; each is a separate engine variant ``exudyn[<preset>]`` in results.
PRESETS: dict[str, dict] = {
    # Exudyn as it comes: generalized-alpha (spectral radius 0.9, modified Newton, adaptive
    # step reduction), Gonthier impact model, v_reg = 1e-3 m/s, no minimum impact velocity;
    # only the stiffness is the adapter's (Exudyn's default 0 is no contact).
    "default": {},
    # From the measurements in NOTES.md: v_reg 1e-7 m/s (creep 0.06 um/s predicted on the
    # 10 degree incline, 0.015-0.05 um/s measured), resting contacts damped through a minimum
    # impact velocity of 0.01 m/s (without it the undamped contact springs let the box ratchet
    # down the slope and the solver needs 15-18x more steps), stiffer contacts (period 4 steps:
    # 2 steps fail) computed from the scene's comfortable step (one model for every dt: the
    # run's dt = 1e-4 made k 100x stiffer and the incline and the ball fail), and e = 0 pairs
    # at e = 0.05 (at 1e-3 the undamped-then-overdamped Gonthier force pulls: -97 N in the
    # clearance pendulum; Exudyn does not clip the normal force at zero).
    "tuned": {
        "friction_regularisation_velocity": 1e-7,
        "minimum_impact_velocity": 0.01,
        "contact_period_steps": 4.0,
        "stiffness_time_step": "scene",
        "plastic_restitution": 0.05,
    },
}

# Mechanisms with clearance joints and friction latches (the C-60): 'tuned' with Newton's
# absolute tolerance scaled to the scene's force scale (the residual stalls at a round-off
# floor of 2.9e-8 of the initial residual in the C-60, 1.1e-5 N, far above Exudyn's 1e-10) and
# a friction regularisation velocity chosen by measurement on c60-on (docs/engines/exudyn.md,
# "The C-60 in Exudyn").
PRESETS["mechanism"] = {
    **PRESETS["tuned"],
    "newton_force_tolerance": 3e-6,
    "friction_regularisation_velocity": 1e-5,
}

SOLVERS = ("GeneralizedAlpha", "TrapezoidalIndex2")
ROTATION_COORDINATES = ("euler_parameters", "rotation_vector", "tait_bryan")
LINEAR_SOLVERS = ("EXUdense", "EigenSparse", "EigenDense")
RING_JOURNAL_MODELS = ("hollow_sphere", "in_plane", "facets")
LAW_LOAD_MODES = ("explicit", "implicit")
UNIT_CHOICES = ("scene", "SI")
STEP_LOOPS = ("horizon", "grid")
CULLING_CHOICES = ("auto", "on", "off")


@dataclass(frozen=True)
class ExudynSettings(EngineSettings):
    """Every option of an Exudyn run.

    Attributes
    ----------
    solver : {'GeneralizedAlpha', 'TrapezoidalIndex2'}
        Implicit second-order solver (``exu.DynamicSolverType``).
    spectral_radius : float
        Generalized-alpha spectral radius at infinity, in [0, 1] (Exudyn: 0.9).
    adaptive_step : bool
        Let Exudyn reduce the step when Newton or the discontinuous iteration fails, and to hit
        contact events (``recommendedStepSize``); the nominal step is restored afterwards.
    minimum_step_fraction : float
        Smallest reduced step as a fraction of the nominal one.
    modified_newton : bool
        Exudyn's modified Newton (Jacobian kept between iterations; its default).
    newton_relative_tolerance, newton_absolute_tolerance : float
        Newton tolerances (Exudyn: 1e-8, 1e-10).
    newton_force_tolerance : float or None
        Newton's absolute tolerance as a fraction of the scene's force scale (the largest
        applied force in the initial configuration, :func:`applied_force_scale`; Exudyn's
        residual is a force); None: ``newton_absolute_tolerance`` as given.
    newton_max_iterations : int
        Newton iterations per step before the step counts as failed (Exudyn: 25).
    discontinuous_max_iterations : int
        Contact/friction switching iterations per step (Exudyn: 5).
    discontinuous_tolerance : float
        Force error accepted by the switching iteration (Exudyn: 1).
    recommended_step : bool
        Let contact connectors shorten a step so that it ends at the contact instant
        (Exudyn's ``discontinuous.useRecommendedStepSize``; needs ``adaptive_step``).
    keep_jacobian : bool
        With ``step_loop = 'grid'``: keep modified Newton's Jacobian from one ``SolveSteps``
        call to the next (each call requests a new one at its start; within one call Exudyn
        keeps it until Newton stops contracting, also after a step reduction), so the grid
        loop computes Jacobians as one call over the horizon does.
    cull_idle_connectors : {'auto', 'on', 'off'}
        'on': switch off, before each step, the contact connectors that cannot touch during it
        (gap beyond a margin of two steps' motion; :mod:`.idle_connectors`), which Exudyn then
        skips in residuals and Jacobians. Their contribution would be exactly zero, so the
        results are the same bit for bit; the check costs tens of microseconds per step.
        'off': every connector in every step (Exudyn's own behaviour). 'auto': 'on' for
        systems of at least ``idle_connectors.MIN_CONNECTORS`` connectors, where the check
        costs less than it saves (measured: docs/engines/exudyn.md).
    step_loop : {'horizon', 'grid'}
        'horizon': one ``SolveSteps`` call over the whole run, Exudyn's step control left
        alone (after a reduced step it grows the step back only after
        ``adaptiveStepRecoverySteps`` good steps); a sample is the first step end at or after
        its time, so sample times leave the grid by less than a step after a reduction.
        'grid': one call per nominal step ending on the grid; every call restarts at the
        nominal step (``SolveSteps`` resets ``currentStepSize``), so a contact is integrated
        with full steps right after the instant it was localised at (bouncing ball e = 0.5,
        1st apex: +11 % default / +36 % tuned at dt 1e-3, against -0.8 % / -0.02 % with
        'horizon').
    rotation_coordinates : {'euler_parameters', 'rotation_vector', 'tait_bryan'}
        Rotation coordinates of the rigid-body nodes: Euler parameters (``NodeRigidBodyEP``,
        one algebraic unit-norm constraint per body), a rotation vector
        (``NodeRigidBodyRotVecLG``, no constraint, Lie-group update) or Tait-Bryan angles
        (``NodeRigidBodyRxyz``, no constraint, singular at a second angle of +-90 deg).
    linear_solver : {'EXUdense', 'EigenSparse'}
    ignore_singular_jacobian : bool
        Let the linear solver pass redundant constraints (Exudyn: only with 'EigenDense',
        whose full-pivot LU then solves in the least-squares sense).
    closed_loop_full_pivot : bool
        On scenes whose joints close a loop (a planar loop in 3D has redundant constraints:
        EXUdense stops with "matrix is not factorized"), use 'EigenDense' with
        ``ignore_singular_jacobian`` whatever the two options above say.
    impact_model : {0, 1, 2}
        Connector impact model: 0 linear, 1 Hunt-Crossley, 2 Gonthier/Carvalho-Martins.
    contact_stiffness : float or None
        Stiffness of every connector [force/length^n, model units]; None: the rule of
        :func:`contact_stiffness` with ``contact_period_steps``.
    contact_period_steps : float
        Steps per period of a connector's spring on the pair's reduced mass (rule above).
    stiffness_time_step : {'run', 'scene'}
        The step of that rule: the run's (the stiffness follows dt: a step sweep changes the
        model) or the scene's comfortable ``time_step`` (one model for every dt).
    contact_stiffness_exponent : float
        Exponent n of the normal force law (1: linear, 1.5: Hertz).
    contact_damping_ratio : float
        Extra linear damping d = 2 zeta sqrt(k m) of every connector (0: none; it adds to the
        impact model and lowers e).
    minimum_impact_velocity : float
        Lower bound of the impact velocity in the impact model [m/s]; > 0 damps resting
        contacts.
    friction_regularisation_velocity : float
        Exudyn's ``frictionProportionalZone`` [m/s].
    plastic_restitution : float
        Restitution given to pairs with e = 0 (Exudyn requires e > 0).
    ring_spheres : int
        Spheres per full circle along a ring, arc or circle rim.
    ring_sphere_radius : float
        Radius of those spheres relative to the ring radius (capped so that the compensated
        partner stays positive).
    journal_facets : int
        Flat facets per full circle of a cylinder or bore rebuilt as a prism.
    facet_window : float
        Half angle [rad] of the facets of a cylinder or bore a ring sphere is paired with,
        around the facet facing it at t = 0 (pi: all facets).
    journal_spheres : int
        Spheres along the axis of a journal inside a bore.
    ring_journal : {'hollow_sphere', 'in_plane', 'facets'}
        A full ring around a journal: one sphere-in-hollow-sphere connector (exact in the
        ring's plane), or as the other ring-cylinder and ring-bore pairs: 'in_plane' (each
        ring sphere against a sphere on the partner's axis at its level: exact for motion
        normal to the axis) or 'facets' (ring spheres against the partner as a prism of
        facets). 'hollow_sphere' uses 'in_plane' for the other pairs.
    corner_sphere_radius : float
        Radius of a box corner's sphere relative to the box's smallest half extent (the
        partner face is moved back by it, so the gap stays the corner's; a corner deeper than
        this passes through).
    plane_size : float
        Half size of the quad standing in for an unbounded plane, relative to the scene size.
    disc_segments : int
        Triangles of the fan standing in for a disc face.
    law_loads : {'explicit', 'implicit'}
        C-60 law loads evaluated once per step at its start (explicit, one step lag) or in
        every Newton residual through Python load user functions (implicit).
    internal_units : {'scene', 'SI'}
        Units of the Exudyn model: the scene's own or SI.
    energy_gain_tolerance, guard_interval
        The shared energy guard (:class:`~clearbench.adapters.engine_settings.EngineSettings`).
    """

    solver: str = "GeneralizedAlpha"
    spectral_radius: float = 0.9
    adaptive_step: bool = True
    minimum_step_fraction: float = 1e-5
    modified_newton: bool = True
    newton_relative_tolerance: float = 1e-8
    newton_absolute_tolerance: float = 1e-10
    newton_force_tolerance: float | None = None
    newton_max_iterations: int = 25
    discontinuous_max_iterations: int = 5
    discontinuous_tolerance: float = 1.0
    recommended_step: bool = True
    step_loop: str = "grid"
    keep_jacobian: bool = False
    cull_idle_connectors: str = "auto"
    rotation_coordinates: str = "euler_parameters"
    linear_solver: str = "EXUdense"
    ignore_singular_jacobian: bool = False
    closed_loop_full_pivot: bool = True
    impact_model: int = 2
    contact_stiffness: float | None = None
    contact_period_steps: float = 10.0
    stiffness_time_step: str = "run"
    contact_stiffness_exponent: float = 1.0
    contact_damping_ratio: float = 0.0
    minimum_impact_velocity: float = 0.0
    friction_regularisation_velocity: float = 1e-3
    plastic_restitution: float = 1e-3
    ring_spheres: int = 32
    ring_sphere_radius: float = 0.05
    journal_facets: int = 32
    facet_window: float = math.pi / 2
    journal_spheres: int = 3
    ring_journal: str = "hollow_sphere"
    corner_sphere_radius: float = 0.1
    plane_size: float = 100.0
    disc_segments: int = 16
    law_loads: str = "explicit"
    internal_units: str = "scene"



#: Type, range and allowed values of every field of :class:`ExudynSettings`.
OPTIONS = OptionTable("exudyn", (
    choice("solver", SOLVERS),
    number("spectral_radius", at_least=0.0, at_most=1.0),
    boolean("adaptive_step"),
    number("minimum_step_fraction", above=0.0, below=1.0),
    boolean("modified_newton"),
    number("newton_relative_tolerance", above=0.0),
    number("newton_absolute_tolerance", above=0.0),
    number("newton_force_tolerance", above=0.0, optional=True),
    integer("newton_max_iterations", at_least=1),
    integer("discontinuous_max_iterations", at_least=1),
    number("discontinuous_tolerance", above=0.0),
    boolean("recommended_step"),
    choice("step_loop", STEP_LOOPS),
    boolean("keep_jacobian"),
    choice("cull_idle_connectors", CULLING_CHOICES),
    choice("rotation_coordinates", ROTATION_COORDINATES),
    choice("linear_solver", LINEAR_SOLVERS),
    boolean("ignore_singular_jacobian"),
    boolean("closed_loop_full_pivot"),
    choice("impact_model", (0, 1, 2)),
    number("contact_stiffness", above=0.0, optional=True),
    number("contact_period_steps", above=0.0),
    choice("stiffness_time_step", ("run", "scene")),
    number("contact_stiffness_exponent", above=0.0),
    number("contact_damping_ratio", at_least=0.0),
    number("minimum_impact_velocity", at_least=0.0),
    number("friction_regularisation_velocity", above=0.0),
    number("plastic_restitution", above=0.0, at_most=1.0),
    integer("ring_spheres", at_least=3),
    number("ring_sphere_radius", above=0.0),
    integer("journal_facets", at_least=3),
    number("facet_window", above=0.0, at_most=math.pi),
    integer("journal_spheres", at_least=1),
    choice("ring_journal", RING_JOURNAL_MODELS),
    number("corner_sphere_radius", above=0.0),
    number("plane_size", above=0.0),
    integer("disc_segments", at_least=3),
    choice("law_loads", LAW_LOAD_MODES),
    choice("internal_units", UNIT_CHOICES),
    *GUARD_OPTIONS,
))
ExudynSettings.OPTIONS = OPTIONS
OPTION_NAMES = OPTIONS.names


def resolve_settings(preset: str, options: dict | None = None) -> ExudynSettings:
    """Values of the preset (a key of :data:`PRESETS`) overridden by ``options`` (fields of
    :class:`ExudynSettings`; the engine checks their names, the dataclass their values:
    ValueError naming the option and value at fault)."""
    return ExudynSettings(**{**PRESETS[preset], **dict(options or {})})


# ---------------------------------------------------------------------------- contact rules
def contact_stiffness(settings: ExudynSettings, reduced_mass: float, time_step: float) -> float:
    """Stiffness of one connector [force/length, model units].

    Rule (when ``contact_stiffness`` is None): the connector's spring on the pair's reduced
    mass m (a fixed partner counts as infinitely heavy) has a period of
    ``contact_period_steps`` steps: ``k = m (2 pi / (n dt))^2``. Per connector: a box resting
    on its 4 corners is 4 such springs in parallel (its normal period is n/2 steps).

    Parameters
    ----------
    reduced_mass : float
        m_a m_b / (m_a + m_b) [M], or the free body's mass against a fixed one.
    time_step : float
        Nominal step [T].
    """
    if settings.contact_stiffness is not None:
        return settings.contact_stiffness
    omega = 2.0 * math.pi / (settings.contact_period_steps * time_step)
    return reduced_mass * omega**2


def contact_damping(settings: ExudynSettings, stiffness: float, reduced_mass: float) -> float:
    """Extra linear damping d = 2 zeta sqrt(k m) of one connector [force time/length]."""
    return 2.0 * settings.contact_damping_ratio * math.sqrt(stiffness * reduced_mass)


def exudyn_restitution(restitution: float, settings: ExudynSettings) -> float:
    """Restitution given to Exudyn: e itself, or ``plastic_restitution`` for e = 0 (Exudyn
    requires e > 0; measured: e = 1e-3 leaves a 1 kg ball dropped 1 m at rest)."""
    if not 0.0 <= restitution <= 1.0:
        raise ValueError(f"restitution must be in [0, 1], got {restitution!r}")
    return restitution if restitution > 0.0 else settings.plastic_restitution


def incline_creep(settings: ExudynSettings, angle: float, friction: float) -> float:
    """Creep velocity of a body that should stick on an incline [m/s]: v_reg tan(theta)/mu."""
    return settings.friction_regularisation_velocity * math.tan(angle) / friction
