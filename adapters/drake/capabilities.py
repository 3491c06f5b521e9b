"""What the Drake adapter does with each scene feature: native, approximated (how, how large) or
unsupported (why), one function per feature kind, asked by
:meth:`clearbench.adapters.base.Engine.capabilities`. Pure Python: stated without a plant.
"""

from __future__ import annotations

from dataclasses import dataclass

from clearbench.adapters.base import BORE_DEPTH_NOTE, Capability, Support
from clearbench.adapters.drake.settings import DrakeSettings
from clearbench.adapters.drake.topology import Topology, plan_topology
from clearbench.adapters.primitive_pieces import pair_clearance_growth, side_geometry
from clearbench.ref_solver.scene_system import law_load_problems
from clearbench.scenarios.scales import largest_length
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.shapes import Arc, Bore, Circle


def _approx(detail: str) -> Capability:
    return Capability(Support.APPROXIMATED, detail)


def _native(detail: str) -> Capability:
    return Capability(Support.NATIVE, detail)


@dataclass(frozen=True)
class FeatureContext:
    """What the capability hooks need, derived once per scene."""

    scene: Scene
    settings: DrakeSettings
    topology: Topology
    problems: dict


def feature_context(scene: Scene, settings: DrakeSettings) -> FeatureContext:
    """The context of ``scene`` with ``settings``: the plant plan and what cannot be built."""
    topology = plan_topology(scene, settings.discrete_contact_approximation)
    problems: dict[str, list[str]] = {}
    length_scale = largest_length(scene)
    for index in range(len(scene.all_contacts)):
        for side in ("a", "b"):
            try:
                side_geometry(scene, index, side, settings, length_scale)
            except ValueError as error:
                problems.setdefault("contacts", []).append(str(error))
    for feature, reason in (*topology.problems, *law_load_problems(scene)):
        problems.setdefault(feature, []).append(reason)
    return FeatureContext(scene, settings, topology, problems)


def feature_problems(context: FeatureContext) -> dict[str, list[str]]:
    """Features the scene uses that Drake cannot build here, with the reasons."""
    return context.problems


def ring_summary(scene: Scene, settings: DrakeSettings) -> list[str]:
    """Per ring or bore pair side: its pieces and, against a coaxial journal, the clearance
    the journal gains between two pieces."""
    out = []
    length_scale = largest_length(scene)
    unit = scene.units.length
    for index, contact in enumerate(scene.all_contacts):
        for side in ("a", "b"):
            body = contact.body_a if side == "a" else contact.body_b
            shape = scene.expanded.body(body).shape(contact.shape_a if side == "a"
                                                    else contact.shape_b)
            if not isinstance(shape, Circle | Arc | Bore):
                continue
            try:
                geometry = side_geometry(scene, index, side, settings, length_scale)
            except ValueError:
                continue
            line = f"{contact.name} ({body}/{shape.name}): {geometry.note}"
            growth = pair_clearance_growth(scene, index, settings)
            if growth is not None:
                clearance, extra = growth
                line += (f"; radial clearance {clearance:.4g} {unit}, the journal gains at most "
                         f"{extra:.3g} {unit} ({100 * extra / clearance:.3g} %) between two "
                         "pieces")
            out.append(line)
    return out


def _contact_words(settings: DrakeSettings) -> str:
    approximation = settings.discrete_contact_approximation
    if settings.stiffness_steps is not None:
        stiffness = (f"stiffness m (pi / ({settings.stiffness_steps:g} dt))^2 per pair (m: the "
                     "lighter moving body)")
    elif settings.point_stiffness is not None:
        stiffness = f"stiffness {settings.point_stiffness:g} N/m per pair"
    else:
        stiffness = ("stiffness and dissipation estimated by Drake from penetration_allowance "
                     f"{settings.penetration_allowance:g} m")
    if settings.uses_sap_dissipation:
        tau = (f"{settings.relaxation_steps:g} dt" if settings.relaxation_steps is not None
               else f"{settings.relaxation_time:g} s" if settings.relaxation_time is not None
               else "Drake's 0.1 s")
        dissipation = f"SAP linear dissipation, time constant {tau}"
    else:
        d = settings.hunt_crossley_dissipation
        dissipation = ("Hunt-Crossley dissipation " + (f"{d:g} s/m" if d is not None
                                                        else "estimated by Drake"))
    return (f"compliant point contact, discrete approximation {approximation!r} (contact model "
            f"{settings.contact_model!r}: the primitives carry no hydroelastic properties, so "
            f"point contact), {stiffness}, {dissipation}; explicit pairs only: one geometry "
            "set per pair side with the pair's material, every other pair filtered out")


SHAPES = {
    "sphere": (Support.NATIVE, "Sphere"),
    "box": (Support.NATIVE, "Box (an offset on side A grows the half extents: sharp corners "
                            "where the offset surface would be rounded)"),
    "capsule": (Support.NATIVE, "Capsule, length 2 half_length between the centres"),
    "cylinder": (Support.APPROXIMATED, "Cylinder of the full length; its end caps collide "
                                       "too (the scene's cylinder touches on its lateral "
                                       "surface only)"),
    "disc": (Support.APPROXIMATED, "Cylinder whose +z cap is the disc (its rim collides too)"),
}


def plain_capability(context: FeatureContext, name: str) -> Capability | None:
    """Support of a plain feature (``contacts``, ``friction``, ``drivers``, ...)."""
    scene, settings, topology = context.scene, context.settings, context.topology
    if name == "gravity":
        return _native("the plant's uniform gravity field")
    if name == "fixed_bodies":
        return _native("the world body: their shapes registered on it at their poses")
    if name == "contacts":
        return _approx(_contact_words(settings))
    if name == "friction":
        return _approx(
            "Coulomb with the pair's mu as Drake's dynamic coefficient (the static one is "
            "ignored in discrete mode), regularised below stiction_tolerance "
            f"{settings.stiction_tolerance:g} m/s: a body that must stick creeps up to that "
            "speed")
    if name == "restitution":
        if settings.uses_sap_dissipation and settings.stiffness_steps is not None:
            return _approx("Drake has no restitution: e > 0 becomes the SAP dissipation time "
                           "constant 2 zeta(e) / omega of the pair's contact spring (zeta "
                           "from the textbook half-period relation); e = 0 keeps the preset's")
        return _approx("Drake has no restitution and this preset maps none: every impact "
                       "loses what the pair's dissipation takes (e is ignored)")
    if name in ("rings", "arcs"):
        return _approx(f"{settings.ring_pieces} spheres per full circle (see shape:circle, "
                       "shape:arc)")
    if name == "ideal_joints":
        if topology.closures:
            return _approx("tree joints in joint coordinates (exact); loops closed by SAP "
                           "constraints (compliant, near-rigid): "
                           + ", ".join(j.name for j in topology.closures))
        return _native("tree joints in joint coordinates (exact)")
    if name == "closed_loop":
        return _approx("loop-closing joints as SAP constraints: a revolute joint two "
                       "AddBallConstraint on its axis 0.1 scene size apart, a spherical one "
                       "AddBallConstraint, a fixed one AddWeldConstraint; SAP makes them "
                       "near-rigid compliant constraints (they drift by their compliance)")
    if name == "clearance_joints":
        return _approx("journal cylinder against bearing rings (rings of spheres) and flange "
                       "planes against thrust arcs: " + "; ".join(
                           line for line in ring_summary(scene, settings)
                           if any(line.startswith(f"{j.name}.") for j in
                                  scene.clearance_joints)))
    return _load_capability(name, settings)


def _load_capability(name: str, settings: DrakeSettings) -> Capability | None:
    explicit = ("explicit, one step lag: the reference solver's own force function "
                "(ref_solver.forces.element_forces) at each step start, applied as an "
                "ExternallyAppliedSpatialForce at the centre of mass")
    if name in ("springs", "torsional_springs"):
        return _approx(explicit + " (an explicit stiff spring diverges for stiffness dt^2 / m "
                                  "above about 4)")
    if name in ("angle_law_loads", "distance_law_loads"):
        return _approx(explicit)
    if name in ("point_forces", "moments"):
        return _native("ExternallyAppliedSpatialForce at the centre of mass with the moment of "
                       "the offset, world axes, set before every step")
    if name == "time_switched_loads":
        return _approx("switched at the first step that starts inside the window")
    if name == "drivers":
        return _approx("each driven component is the coordinate of a revolute / prismatic "
                       "joint to the world: reset to the profile at every step start and held "
                       "during the step by a JointActuator's reflected inertia "
                       f"{settings.driver_armature_ratio:g} times the body's own (exact at step "
                       "starts)")
    return None


def shape_capability(context: FeatureContext, kind: str) -> Capability | None:
    """Support of the shape kind ``kind``."""
    settings = context.settings
    if kind in SHAPES:
        return Capability(*SHAPES[kind])
    if kind == "plane":
        return _native("HalfSpace on fixed bodies; on moving bodies a box of half size "
                       f"{settings.plane_box_size:g} x the scene size")
    if kind == "rectangle":
        return _approx("Box whose +z face is the rectangle, as thick as its depth (else "
                       f"{settings.face_thickness:g} x its half extent): edges and sides "
                       "collide too")
    if kind in ("circle", "arc", "bore"):
        how = (f"{settings.bore_pieces} Capsules per full circle along the axis (a Mesh would "
               f"be its convex hull for point contact; {BORE_DEPTH_NOTE})" if kind == "bore"
               else f"{settings.ring_pieces} Spheres per full circle")
        return _approx(f"{how}: " + "; ".join(ring_summary(context.scene, settings)))
    return None


def pair_capability(context: FeatureContext, kind_a: str, kind_b: str) -> Capability | None:
    """Support of contacts between two known shape kinds."""
    known = set(SHAPES) | {"plane", "rectangle", "circle", "arc", "bore"}
    if kind_a in known and kind_b in known:
        return _native("Drake's point-pair penetration query between the two primitives")
    return None


def joint_capability(context: FeatureContext, kind: str) -> Capability | None:
    """Support of the ideal joint kind ``kind``: exact as a tree joint, compliant as a
    closure."""
    how = {"revolute": "RevoluteJoint", "spherical": "BallRpyJoint (roll-pitch-yaw: singular "
                                                    "at pitch +-90 degrees)",
           "prismatic": "PrismaticJoint", "fixed": "WeldJoint"}
    if kind not in how:
        return None
    names = {j.name for j in context.topology.closures if j.kind == kind}
    if names:
        return _approx(f"tree {kind} joints as {how[kind]} (exact); loop-closing ones "
                       f"({', '.join(sorted(names))}) as SAP constraints (near-rigid)")
    return _native(f"{how[kind]} in the plant's tree: exact")
