"""What the Exudyn adapter does with each scene feature: native, approximated (how, how large)
or unsupported (why), one function per feature kind, asked by
:meth:`clearbench.adapters.base.Engine.capabilities`. Pure Python: stated without building a
system (the pairs are planned by :mod:`.geometry`, which needs no ``exudyn``)."""

from __future__ import annotations

import math
from dataclasses import dataclass

from clearbench.adapters.base import BORE_DEPTH_NOTE, Capability, Support
from clearbench.adapters.exudyn.geometry import (
    UnsupportedPair,
    facet_error,
    pair_problem,
    plan_pair,
    ring_chord_error,
    ring_sphere_radius,
)
from clearbench.adapters.exudyn.settings import ExudynSettings, incline_creep
from clearbench.ref_solver.scene_system import law_load_problems
from clearbench.scenarios.features import pair_feature
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.shapes import SHAPE_TYPES, Arc, Bore, Circle, Cylinder

#: The shape kinds of the scene format (a pair of other kinds is an unknown feature).
SHAPE_KINDS = frozenset(SHAPE_TYPES)


def _approx(detail: str) -> Capability:
    return Capability(Support.APPROXIMATED, detail)


def _native(detail: str) -> Capability:
    return Capability(Support.NATIVE, detail)


def _unsupported(detail: str) -> Capability:
    return Capability(Support.UNSUPPORTED, detail)


def pair_problems(scene: Scene, settings: ExudynSettings,
                  rebuilt: dict | None = None) -> dict[str, list[str]]:
    """``pair:<a>-<b>`` feature -> reasons its pairs cannot be rebuilt; ``rebuilt`` (if
    given) receives feature -> [(pair name, how, connectors, shape error [L])] of the others."""
    expanded = scene.expanded
    out: dict[str, list[str]] = {}
    for contact in expanded.contacts:
        kind_a = expanded.body(contact.body_a).shape(contact.shape_a).kind
        kind_b = expanded.body(contact.body_b).shape(contact.shape_b).kind
        feature = pair_feature(kind_a, kind_b)
        reason = pair_problem(kind_a, kind_b)
        if reason is None:
            try:
                plan = plan_pair(scene, contact, settings)
            except UnsupportedPair as error:
                reason = str(error)
            else:
                if rebuilt is not None:
                    rebuilt.setdefault(feature, []).append(
                        (contact.name, plan.how, len(plan.connectors), plan.shape_error))
        if reason is not None:
            out.setdefault(feature, []).append(f"{contact.name}: {reason}")
    return out


def clearance_summary(scene: Scene, settings: ExudynSettings) -> list[str]:
    """Per clearance joint: how its rings are rebuilt and the error next to the clearance."""
    out = []
    unit = scene.units.length
    for joint in scene.clearance_joints:
        c = joint.radial_clearance
        if settings.ring_journal == "hollow_sphere":
            dz = 0.5 * joint.axial_clearance
            extra = dz**2 / (2.0 * c)
            out.append(f"{joint.name}: each bearing ring is one sphere-in-hollow-sphere "
                       f"connector (exact in the ring's plane); at the full axial play "
                       f"dz = {dz:.3g} {unit} the gap closes {extra:.3g} {unit} early "
                       f"({100 * extra / c:.3g} % of the radial clearance {c:.3g} {unit})")
        else:
            rho = min(settings.ring_sphere_radius * joint.bore_radius,
                      0.9 * joint.journal_radius)
            facets = facet_error(joint.journal_radius, settings.journal_facets)
            chord = ring_chord_error(joint.bore_radius, settings.ring_spheres)
            out.append(f"{joint.name}: {settings.ring_spheres} ring spheres (radius "
                       f"{rho:.3g} {unit}) per ring against {settings.journal_facets} journal "
                       f"facets: facet error {facets:.3g} {unit} "
                       f"({100 * facets / c:.3g} % of the clearance {c:.3g} {unit}), chord "
                       f"error {chord:.3g} {unit} ({100 * chord / c:.3g} %)")
    return out


def shape_summary(scene: Scene, settings: ExudynSettings, kinds: tuple) -> list[str]:
    """One line per ring, arc, bore or cylinder shape in a pair: samples and their errors."""
    out = []
    unit = scene.units.length
    for body in scene.expanded.bodies:
        for shape in body.shapes:
            if not isinstance(shape, kinds):
                continue
            if isinstance(shape, Circle | Arc):
                rho = ring_sphere_radius(shape, 0.0, settings)
                chord = ring_chord_error(shape.radius, settings.ring_spheres)
                out.append(f"{body.name}/{shape.name}: R {shape.radius:.4g} {unit}, spheres "
                           f"of radius {rho:.3g} {unit} every "
                           f"{360 / settings.ring_spheres:.3g} deg, chord error {chord:.3g} "
                           f"{unit}")
            elif isinstance(shape, Bore | Cylinder):
                error = facet_error(shape.radius, settings.journal_facets)
                out.append(f"{body.name}/{shape.name}: R {shape.radius:.4g} {unit}, "
                           f"{settings.journal_facets} facets per circle, facet error "
                           f"{error:.3g} {unit}")
    return out


@dataclass(frozen=True)
class FeatureContext:
    """What the capability hooks need of one scene, derived once.

    Attributes
    ----------
    scene : Scene
    settings : ExudynSettings
    problems : dict
        Feature -> reasons it cannot be rebuilt (pairs without a connector, law loads the
        shared evaluation cannot take).
    rebuilt : dict
        ``pair:<a>-<b>`` -> [(pair name, how, connector count, shape error [L])].
    """

    scene: Scene
    settings: ExudynSettings
    problems: dict
    rebuilt: dict


def feature_context(scene: Scene, settings: ExudynSettings) -> FeatureContext:
    """Plan every pair once (pure Python) and collect what cannot be rebuilt."""
    rebuilt: dict[str, list] = {}
    problems = pair_problems(scene, settings, rebuilt)
    for feature, reason in law_load_problems(scene):
        problems.setdefault(feature, []).append(reason)
    return FeatureContext(scene, settings, problems, rebuilt)


def feature_problems(context: FeatureContext) -> dict[str, list[str]]:
    """Features that cannot be rebuilt here, with the reasons."""
    return context.problems


def pair_capability(context: FeatureContext, kind_a: str, kind_b: str) -> Capability | None:
    """How the pairs of one ``pair:`` feature are rebuilt: the first pair's description, the
    connector count and the largest surface error of the rebuild; None for unknown kinds."""
    pairs = context.rebuilt.get(pair_feature(kind_a, kind_b))
    if not pairs:
        if {kind_a, kind_b} <= SHAPE_KINDS:
            reason = pair_problem(kind_a, kind_b)
            return _unsupported(reason) if reason else _approx("no pair of the scene uses it")
        return None
    name, how, _, _ = pairs[0]
    count = sum(p[2] for p in pairs)
    error = max(p[3] for p in pairs)
    unit = context.scene.units.length
    detail = (f"{len(pairs)} pair(s), {count} connectors; e.g. {name}: {how}; largest surface "
              f"error of the rebuild {error:.3g} {unit}")
    return _native(detail) if how.startswith("sphere-sphere connector") else _approx(detail)


def joint_capability(context: FeatureContext, kind: str) -> Capability | None:
    """Ideal joints: Exudyn's index-3 joint objects; None for an unknown kind."""
    objects = {"revolute": "ObjectJointRevoluteZ", "prismatic": "ObjectJointPrismaticX",
               "spherical": "ObjectJointSpherical", "fixed": "ObjectJointGeneric, all axes"}
    return _native(objects[kind]) if kind in objects else None


def shape_capability(context: FeatureContext, kind: str) -> Capability | None:
    """How a shape kind is rebuilt from spheres and triangles; None for an unknown kind."""
    scene, s = context.scene, context.settings
    if kind == "sphere":
        return _native("sphere side of a sphere-sphere / sphere-triangle connector")
    if kind == "plane":
        return _approx(f"one triangle covering a square of half size {s.plane_size:g} x "
                       "the scene's largest length (a bounded plane)")
    if kind == "box":
        return _approx("8 corner spheres against faces (corner sphere radius "
                       f"{s.corner_sphere_radius:g} x the smallest half extent, the face "
                       "moved back by it: exact corner gaps, but friction acts that far "
                       "below the corner; a corner deeper than that passes through); "
                       "against a sphere: its 12 face triangles")
    if kind == "rectangle":
        return _approx("two triangles without edge contact (bounded face); the face's "
                       "depth is not modelled: a partner deeper than its sphere radius "
                       "is pushed through")
    if kind == "disc":
        return _approx(f"fan of {s.disc_segments} triangles (inscribed polygon, radius "
                       f"error R (1 - cos(pi/{s.disc_segments})))")
    if kind in ("circle", "arc"):
        return _approx(f"{s.ring_spheres} spheres per circle on the curve: "
                       + "; ".join(shape_summary(scene, s, (Circle, Arc))))
    if kind == "cylinder":
        return _approx("journal in a full ring: sphere of its radius on its axis "
                       "(sphere-in-hollow-sphere); against faces: spheres at its axis ends; "
                       "otherwise a prism of facets: "
                       + "; ".join(shape_summary(scene, s, (Bore, Cylinder))))
    if kind == "bore":
        return _approx(f"lining of facets (circumscribed polygon; {BORE_DEPTH_NOTE}): "
                       + "; ".join(shape_summary(scene, s, (Bore, Cylinder))))
    if kind == "capsule":
        return _unsupported("Exudyn has no capsule connector")
    return None


def plain_capability(context: FeatureContext, feature: str) -> Capability | None:
    """Support of a plain feature; None for one the adapter does not know."""
    s = context.settings
    v_reg = s.friction_regularisation_velocity
    if feature in ("gravity", "fixed_bodies"):
        return _native("body gravity loads" if feature == "gravity" else "ObjectGround")
    if feature == "contacts":
        step = "the run's step" if s.stiffness_time_step == "run" else \
            "the scene's comfortable step"
        k = ("the rule k = m (2 pi / (n dt))^2 per connector, n = "
             f"{s.contact_period_steps:g} steps of {step} per period on the pair's reduced "
             "mass"
             if s.contact_stiffness is None else f"k = {s.contact_stiffness:g}")
        return _approx(f"penalty connectors (sphere-sphere, sphere-triangle) per scene pair, "
                       f"{k}; the gap goes below zero by about the weight over k; offsets move "
                       "the partner surface")
    if feature == "friction":
        creep = incline_creep(s, math.radians(10.0), 0.3)
        return _approx(f"regularised Coulomb friction, linear below v_reg = {v_reg:g} m/s: a "
                       f"body that should stick creeps at v_reg tan(theta) / mu "
                       f"({1e6 * creep:.3g} um/s on a 10 deg incline with mu 0.3)")
    if feature == "restitution":
        model = {0: "linear", 1: "Hunt-Crossley", 2: "Gonthier/Carvalho-Martins"}
        return _approx(
            f"impact model {s.impact_model} ({model[s.impact_model]}): "
            "damping lambda = k f(e) / v_impact reproduces Newton's e (first apex -1.7 ... "
            "+4.1 % for e 0.2-0.9, NOTES.md); the normal force is not clipped at zero (the "
            "damping can pull while separating); e = 0 pairs get e = "
            f"{s.plastic_restitution:g} (Exudyn requires e > 0); impacts slower than "
            f"{s.minimum_impact_velocity:g} m/s are damped as at that speed")
    if feature in ("rings", "arcs"):
        return _approx(f"{s.ring_spheres} spheres per full circle (see shape:circle/arc)")
    if feature == "ideal_joints":
        return _native("index-3 constraints in maximal coordinates (exact at the solver "
                       "tolerance)")
    if feature == "closed_loop":
        return _native("constraints in maximal coordinates close loops exactly (redundant "
                       "planar loops need ignore_singular_jacobian)")
    if feature == "clearance_joints":
        return _approx("bearing rings against the journal, thrust arcs as spheres against "
                       "the flange planes: "
                       + "; ".join(clearance_summary(context.scene, s)))
    if feature == "springs":
        return _native("ObjectConnectorSpringDamper (implicit), preload as its force")
    if feature == "torsional_springs":
        return _approx("ObjectConnectorTorsionalSpringDamper about the axis at body B's "
                       "origin (implicit); its angle is Exudyn's relative rotation about the "
                       "axis (exact when a revolute joint holds the two bodies)")
    if feature in ("angle_law_loads", "distance_law_loads"):
        if s.law_loads == "explicit":
            return _approx("the reference's law evaluation at each step start applied as "
                           "force/torque loads during the step (explicit, one step lag)")
        return _approx("Python load user functions evaluated at every Newton iterate "
                       "(implicit; no Jacobian): the symbolic user functions cannot read "
                       "the configuration")
    if feature in ("point_forces", "moments"):
        return _native("LoadForceVector / LoadTorqueVector (world or body axes)")
    if feature == "time_switched_loads":
        return _native("compiled symbolic load user function of t (switched inside the step "
                       "at the Newton iterate's time)")
    if feature == "drivers":
        return _native("ObjectJointGeneric from a ground at the centre of mass, world axes, "
                       "the driven components constrained to a Python offset user function "
                       "(index 3: exact positions; several rotations as Tait-Bryan angles)")
    return None
