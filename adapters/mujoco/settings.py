"""MuJoCo presets, run options, the restitution -> solref mapping and the time-step guard.

Pure Python (no ``mujoco`` import): the capabilities and the stability checks of a run can be
stated without compiling a model.

MuJoCo's contact is a soft constraint. With the impedance saturated (solimp d0 = dmax), the
normal motion of a contact obeys ``a = -b v - k r`` per unit mass, with ``b = 2 / timeconst``
and ``k = 1 / (timeconst dampratio)^2`` (solref = (timeconst, dampratio)), i.e. a linear
spring-damper of natural frequency ``1 / (timeconst dampratio)`` and damping ratio
``dampratio``. Because a contact can only push, the body leaves when the spring-damper force
reaches zero, before the spring is back at rest: the coefficient of restitution is
:func:`restitution_for_damping_ratio` (0.0744 for e = 0.8, not the 0.0709 of the textbook
formula that waits for the spring to relax). MuJoCo integrates that force explicitly, so
``k dt^2`` and ``b dt`` must stay below about 1 or contacts gain energy (docs/engines/mujoco.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from clearbench.adapters import primitive_pieces
from clearbench.adapters.engine_settings import GUARD_OPTIONS, EngineSettings
from clearbench.adapters.options import OptionTable, boolean, choice, integer, number, numbers

#: MuJoCo's own defaults (mjOption and the default geom solref/solimp of MuJoCo 3/4).
MUJOCO_DEFAULT_SOLREF = (0.02, 1.0)
MUJOCO_DEFAULT_SOLIMP = (0.9, 0.95, 0.001, 0.5, 2.0)

#: Named presets; each is a separate engine variant ``mujoco[<preset>]`` in results.
PRESETS: dict[str, dict] = {
    # What a user gets with an MJCF file that sets nothing: pyramidal cone, no noslip,
    # solref (0.02, 1), solimp (0.9, 0.95, 0.001), Euler, Newton, 100 iterations.
    "default": {},
    # docs/engines/mujoco.md: elliptic cone + 10 noslip iterations (creep 0.06 um instead of
    # 636 um on the 10 degree incline), stiff contacts solref (2 dt, 1), solimp
    # (0.99, 0.999, 1e-5) (a 0.1 mm clearance held within 1.5-2.8 um at dt 1e-4), stiff
    # equalities solref (2 dt, 1) (loop-closure drift 0.034 mm instead of 0.77 mm), convex
    # collision tolerance 1e-4 of the smallest feature (MuJoCo's 1e-6 m is 5 % of a C-60
    # clearance), and e = 0 mapped to dampratio 3 (e = 0.024) instead of 1 (e = 0.135).
    "tuned": {
        "cone": "elliptic",
        "noslip_iterations": 10,
        "timeconst_steps": 2.0,
        "solimp": (0.99, 0.999, 1e-5, 0.5, 2.0),
        "equality_timeconst_steps": 2.0,
        "equality_solimp": (0.99, 0.999, 1e-5, 0.5, 2.0),
        "ccd_tolerance_relative": 1e-4,
        "map_plastic": True,
    },
}


@dataclass(frozen=True)
class MujocoSettings(EngineSettings):
    """Every option of a MuJoCo run (lengths in the model's internal units, SI by default).

    Attributes
    ----------
    integrator : {'Euler', 'implicit', 'implicitfast', 'RK4'}
    cone : {'pyramidal', 'elliptic'}
    impratio : float
        Ratio of frictional to normal constraint impedance (MuJoCo ``impratio``).
    solver : {'Newton', 'CG', 'PGS'}
    iterations, tolerance : int, float
        Main solver iteration cap and tolerance.
    noslip_iterations, noslip_tolerance : int, float
        Post-processing to remove friction slip (only acts with the elliptic cone).
    solref, solimp : tuple
        Contact (timeconst [s], dampratio) and impedance of pairs with e = 0.
    timeconst_steps : float or None
        When set, the contact timeconst is this many time steps (overrides ``solref[0]``).
    equality_solref, equality_solimp, equality_timeconst_steps
        The same for loop-closure equality constraints.
    restitution_contact_steps : float
        Steps per half period of the spring of a pair with e > 0 (its timeconst is lengthened
        until the contact lasts at least that many steps; shorter contacts make e depend on the
        phase of impact within a step).
    plastic_damping_ratio : float
        Damping ratio used for e = 0 where a pair's restitution is mapped (e(3) = 0.024);
        a plastic impact needs an infinite ratio, so e = 0 is approximated.
    map_plastic : bool
        Map e = 0 pairs too (else they keep ``solref``).
    ring_pieces : int
        Pieces per full circle of a ring (circle or arc shape).
    ring_piece : {'sphere', 'capsule', 'box'}
        Spheres centred on the circle (every MuJoCo collision with a sphere is analytic, so
        the sphere radius is compensated exactly by a negative pair margin), or capsules /
        boxes along the circumscribed polygon with their inner surface on it (for partners
        inside the ring: bores; mujoco 4.0 counts a negative margin twice in its convex
        collisions, so they cannot be compensated the same way).
    ring_piece_radius : float
        Radius (sphere, capsule) or half thickness (box) of a ring piece, relative to the
        ring radius; capped at half the radial clearance for clearance-joint rings.
    bore_pieces : int
        Boxes per full circle lining a bore (a concave cylinder: MuJoCo geoms are convex);
        their inner faces form the circumscribed polygon of the bore.
    bore_wall : float
        Radial half thickness of a bore's boxes, relative to the bore radius.
    face_thickness : float
        Thickness of the box (rectangle) or cylinder (disc) standing in for a bounded plane face
        that gives no ``depth``, relative to its larger half extent (or radius).
    plane_box_size : float
        Half size of the box that stands in for a plane on a moving body (MuJoCo planes must be
        static), relative to the scene's largest length.
    closure_spacing : float or None
        Distance between the two connect points of a loop-closing revolute joint [L]; None:
        the larger radius of gyration of the two bodies.
    driver_armature_ratio : float
        Armature of a driven degree of freedom relative to its own inertia.
    internal_units : {'SI', 'scene'}
        Units of the MuJoCo model: MuJoCo's absolute defaults (solimp width 1 mm, margins,
        minimum masses) assume metres and seconds.
    energy_gain_tolerance, guard_interval
        The shared energy guard (:class:`~clearbench.adapters.engine_settings.EngineSettings`).
    refsafe : bool
        MuJoCo's own clamp of timeconst to >= 2 dt.
    ccd_tolerance_relative : float or None
        Tolerance of MuJoCo's convex collision (GJK/EPA) relative to the scene's smallest
        feature (clearance, offset, shape size); None keeps MuJoCo's absolute 1e-6.
    """

    integrator: str = "Euler"
    cone: str = "pyramidal"
    impratio: float = 1.0
    solver: str = "Newton"
    iterations: int = 100
    tolerance: float = 1e-8
    noslip_iterations: int = 0
    noslip_tolerance: float = 1e-6
    solref: tuple = MUJOCO_DEFAULT_SOLREF
    solimp: tuple = MUJOCO_DEFAULT_SOLIMP
    timeconst_steps: float | None = None
    equality_solref: tuple = MUJOCO_DEFAULT_SOLREF
    equality_solimp: tuple = MUJOCO_DEFAULT_SOLIMP
    equality_timeconst_steps: float | None = None
    restitution_contact_steps: float = 20.0
    plastic_damping_ratio: float = 3.0
    map_plastic: bool = False
    ring_pieces: int = 64
    ring_piece: str = "sphere"
    ring_piece_radius: float = 0.01
    bore_pieces: int = 64
    bore_wall: float = 0.05
    face_thickness: float = 0.1
    plane_box_size: float = 100.0
    closure_spacing: float | None = None
    driver_armature_ratio: float = 1e6
    internal_units: str = "SI"
    refsafe: bool = True
    ccd_tolerance_relative: float | None = None

    def __post_init__(self) -> None:
        super().__post_init__()
        for name in ("solref", "equality_solref", "solimp", "equality_solimp"):
            object.__setattr__(self, name, tuple(float(x) for x in getattr(self, name)))


    def contact_timeconst(self, time_step: float) -> float:
        """Timeconst of the base contact solref at ``time_step`` [s]."""
        if self.timeconst_steps is not None:
            return self.timeconst_steps * time_step
        return self.solref[0]

    def equality_timeconst(self, time_step: float) -> float:
        if self.equality_timeconst_steps is not None:
            return self.equality_timeconst_steps * time_step
        return self.equality_solref[0]


#: Type, range and allowed values of every field of :class:`MujocoSettings` (solref: a positive
#: (timeconst, dampratio) or MuJoCo's direct (-stiffness, -damping), so any sign; solimp: five
#: numbers MuJoCo clamps into its own ranges).
OPTIONS = OptionTable("mujoco", (
    choice("integrator", ("Euler", "implicit", "implicitfast", "RK4")),
    choice("cone", ("pyramidal", "elliptic")),
    number("impratio", above=0.0),
    choice("solver", ("Newton", "CG", "PGS")),
    integer("iterations", at_least=1),
    number("tolerance", above=0.0),
    integer("noslip_iterations", at_least=0),
    number("noslip_tolerance", above=0.0),
    numbers("solref", 2),
    numbers("solimp", 5),
    number("timeconst_steps", above=0.0, optional=True),
    numbers("equality_solref", 2),
    numbers("equality_solimp", 5),
    number("equality_timeconst_steps", above=0.0, optional=True),
    number("restitution_contact_steps", above=0.0),
    number("plastic_damping_ratio", above=0.0),
    boolean("map_plastic"),
    integer("ring_pieces", at_least=3),
    choice("ring_piece", ("sphere", "capsule", "box")),
    number("ring_piece_radius", above=0.0),
    integer("bore_pieces", at_least=3),
    number("bore_wall", above=0.0),
    number("face_thickness", above=0.0),
    number("plane_box_size", above=0.0),
    number("closure_spacing", above=0.0, optional=True),
    number("driver_armature_ratio", above=0.0),
    choice("internal_units", ("SI", "scene")),
    *GUARD_OPTIONS,
    boolean("refsafe"),
    number("ccd_tolerance_relative", above=0.0, optional=True),
))
MujocoSettings.OPTIONS = OPTIONS
OPTION_NAMES = OPTIONS.names


def resolve_settings(preset: str, options: dict | None = None) -> MujocoSettings:
    """Values of the preset (a key of :data:`PRESETS`) overridden by ``options`` (fields of
    :class:`MujocoSettings`; the engine checks their names, the dataclass their values).

    An explicit ``solref`` (or ``equality_solref``) in ``options`` switches off the preset's
    step-relative timeconst unless ``timeconst_steps`` is given as well.
    """
    options = dict(options or {})
    values = dict(PRESETS[preset])
    if "solref" in options and "timeconst_steps" not in options:
        values.pop("timeconst_steps", None)
    if "equality_solref" in options and "equality_timeconst_steps" not in options:
        values.pop("equality_timeconst_steps", None)
    values.update(options)
    return MujocoSettings(**values)


# ---------------------------------------------------------------------------- restitution
def restitution_for_damping_ratio(zeta: float) -> float:
    """Coefficient of restitution of a unilateral linear spring-damper.

    A body hits the spring-damper (stiffness k, damping c = 2 zeta sqrt(k m)) and leaves when
    the force k x + c x' falls to zero (a contact cannot pull). Closed form for every
    ``zeta`` >= 0; e(0) = 1, e(1) = exp(-2), e(0.0744) = 0.800.
    """
    if not zeta >= 0.0 or not math.isfinite(zeta):
        raise ValueError(f"damping ratio must be finite and >= 0, got {zeta!r}")
    if zeta == 0.0:
        return 1.0
    if abs(zeta - 1.0) < 1e-9:
        return math.exp(-2.0)  # x = t e^-t: force (2 - t) e^-t vanishes at t = 2
    if zeta < 1.0:
        # x = e^(-zeta t) sin(wd t) / wd (unit natural frequency, unit impact speed); the force
        # x + 2 zeta x' vanishes first at phase phi = pi - atan2(2 zeta wd, 1 - 2 zeta^2).
        wd = math.sqrt(1.0 - zeta * zeta)
        phi = math.pi - math.atan2(2.0 * zeta * wd, 1.0 - 2.0 * zeta * zeta)
        velocity = math.exp(-zeta * phi / wd) * (math.cos(phi) - zeta * math.sin(phi) / wd)
        return -velocity
    # Over-damped: x = (e^(s1 t) - e^(s2 t)) / (s1 - s2); (1 + 2 zeta s) e^(s t) balances.
    root = math.sqrt(zeta * zeta - 1.0)
    s1, s2 = -zeta + root, -zeta - root
    t = math.log((1.0 + 2.0 * zeta * s2) / (1.0 + 2.0 * zeta * s1)) / (s1 - s2)
    velocity = (s1 * math.exp(s1 * t) - s2 * math.exp(s2 * t)) / (s1 - s2)
    return -velocity


def damping_ratio_for_restitution(restitution: float, plastic_damping_ratio: float = 3.0) -> float:
    """Inverse of :func:`restitution_for_damping_ratio` (bisection to 1e-12 relative).

    e below e(``plastic_damping_ratio``) (0.024 for 3) returns ``plastic_damping_ratio``: a
    spring-damper never gives e = 0 exactly.
    """
    if not 0.0 <= restitution <= 1.0:
        raise ValueError(f"restitution must be in [0, 1], got {restitution!r}")
    if restitution == 1.0:
        return 0.0
    if restitution <= restitution_for_damping_ratio(plastic_damping_ratio):
        return plastic_damping_ratio
    low, high = 0.0, plastic_damping_ratio  # e decreases monotonically with zeta
    for _ in range(200):
        middle = 0.5 * (low + high)
        if restitution_for_damping_ratio(middle) > restitution:
            low = middle
        else:
            high = middle
        if high - low <= 1e-12 * high:
            break
    return 0.5 * (low + high)


@dataclass(frozen=True)
class ContactParameters:
    """solref / solimp of one contact pair and how they were chosen."""

    solref: tuple
    solimp: tuple
    damping_ratio: float
    mapped: bool


def contact_parameters(restitution: float, settings: MujocoSettings,
                       time_step: float) -> ContactParameters:
    """solref and solimp of a pair with Newton coefficient ``restitution``.

    Pairs with e > 0 (and e = 0 when ``map_plastic``) get dampratio = zeta(e) with a constant
    impedance (solimp d0 = dmax, so the spring is linear and the mapping exact) and a timeconst
    of at least the base one and long enough that the contact lasts
    ``restitution_contact_steps`` steps: with k = 1/(timeconst zeta)^2 the half period is
    pi timeconst zeta (for small zeta). Other pairs keep the base solref / solimp.
    """
    base_timeconst = settings.contact_timeconst(time_step)
    if restitution <= 0.0 and not settings.map_plastic:
        return ContactParameters((base_timeconst, settings.solref[1]), settings.solimp,
                                 settings.solref[1], False)
    zeta = damping_ratio_for_restitution(restitution, settings.plastic_damping_ratio)
    # natural frequency w = 1/(timeconst zeta); steps per half period = pi / (w dt).
    omega_max = math.pi / (settings.restitution_contact_steps * time_step)
    timeconst = base_timeconst
    if zeta > 0:
        timeconst = max(base_timeconst, 1.0 / (omega_max * zeta))
    else:  # e = 1: undamped; MuJoCo needs a positive dampratio
        zeta = 1e-6
        timeconst = max(base_timeconst, 1.0 / (omega_max * zeta))
    dmax = settings.solimp[1]
    solimp = (dmax, dmax) + tuple(settings.solimp[2:])
    return ContactParameters((timeconst, zeta), solimp, zeta, True)


# ---------------------------------------------------------------------------- guards
def effective_stiffness_damping(solref: tuple, time_step: float,
                                refsafe: bool = True) -> tuple[float, float]:
    """Stiffness [1/T^2] and damping [1/T] per unit mass of a saturated soft constraint.

    solref > 0: (timeconst, dampratio) with MuJoCo's refsafe clamp timeconst >= 2 dt;
    solref <= 0: (-stiffness, -damping) given directly.
    """
    first, second = float(solref[0]), float(solref[1])
    if first > 0:
        timeconst = max(first, 2.0 * time_step) if refsafe else first
        return 1.0 / (timeconst * second) ** 2, 2.0 / timeconst
    return -first, -second


#: Bounds of stiffness*dt^2 and damping*dt above which MuJoCo contacts were measured to gain
#: energy (docs/engines/mujoco.md: 'keep ... at or below about 1').
STIFFNESS_DT2_LIMIT = 1.0
DAMPING_DT_LIMIT = 1.0


def time_step_warnings(label: str, solref: tuple, time_step: float,
                       refsafe: bool = True) -> list[str]:
    """Warnings when a soft constraint is too stiff or too damped for ``time_step``."""
    stiffness, damping = effective_stiffness_damping(solref, time_step, refsafe)
    out = []
    if stiffness * time_step**2 > STIFFNESS_DT2_LIMIT:
        out.append(f"{label}: stiffness*dt^2 = {stiffness * time_step**2:.3g} > "
                   f"{STIFFNESS_DT2_LIMIT:g} (solref {tuple(solref)}, dt {time_step:g}): "
                   "explicit contact spring, energy may grow")
    if damping * time_step > DAMPING_DT_LIMIT:
        out.append(f"{label}: damping*dt = {damping * time_step:.3g} > {DAMPING_DT_LIMIT:g} "
                   f"(solref {tuple(solref)}, dt {time_step:g}): explicit damping overshoots")
    return out


def ring_chord_error(radius: float, pieces_per_circle: int, piece: str = "sphere") -> float:
    """Largest distance between a circle of ``radius`` and the surface its ring of
    ``pieces_per_circle`` pieces presents to a large partner [L]: spheres sit on the circle
    and a partner spanning two of them meets their chord, R (1 - cos(pi/N)) inside;
    capsules/boxes form the circumscribed polygon, whose corners are R (1/cos(pi/N) - 1)
    outside."""
    step = 2.0 * math.pi / pieces_per_circle
    if piece == "sphere":
        return primitive_pieces.ring_chord_error(radius, step)
    return primitive_pieces.polygon_corner_error(radius, step)


def ring_clearance_error(bore_radius: float, radial_clearance: float, pieces_per_circle: int,
                         piece: str = "sphere") -> float:
    """Extra eccentricity a journal of radius R - c gains where it is held by two pieces
    instead of the circle [L].

    Polygon (capsules/boxes, apothem R): touching two adjacent flats, the journal centre is
    c / cos(pi/N) from the bore centre. Spheres on the circle at +-pi/N from the journal's
    direction: the centre can move to R cos(pi/N) - sqrt((R - c)^2 - R^2 sin^2(pi/N)).
    Both are about c (pi/N)^2 / 2: far below the chord error when c << R.
    """
    half_angle = math.pi / pieces_per_circle
    if piece == "sphere":
        journal = bore_radius - radial_clearance
        reach = bore_radius * math.cos(half_angle) - math.sqrt(
            journal**2 - (bore_radius * math.sin(half_angle)) ** 2)
        return reach - radial_clearance
    return radial_clearance * (1.0 / math.cos(half_angle) - 1.0)
