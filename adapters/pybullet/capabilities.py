"""What the PyBullet adapter does with each scene feature: native, approximated (how, how
large) or unsupported (why), one function per feature kind, asked by
:meth:`clearbench.adapters.base.Engine.capabilities`. Pure Python: stated without a physics
server.

PyBullet defaults kept in both presets, and why (measured in docs/engines/pybullet.md):
contactERP 0.08, erp 0.2 and frictionERP 0.2 (the Baumgarte factors: larger ones shrink the
closure drift but add energy to contacts), warm-starting 0.1, the relative breaking threshold
0.02 (a factor on each shape's bounding radius: 34.6 um for a 1 mm sphere, enough for every
library scene; it is process-global, so every run sets it), the cone-friction flag (it does
nothing in PyBullet's solver mode). ``tuned`` changes the rest (:mod:`.settings`).
"""

from __future__ import annotations

from dataclasses import dataclass

from clearbench.adapters.base import BORE_DEPTH_NOTE, Capability, Support
from clearbench.adapters.pybullet.geometry import (
    collision_groups,
    collision_margin,
    margin_feature_length,
    pair_clearance_growth,
    side_geometry,
)
from clearbench.adapters.pybullet.settings import PybulletSettings
from clearbench.adapters.pybullet.topology import plan_topology
from clearbench.ref_solver.scene_system import law_load_problems
from clearbench.scenarios.scales import largest_length
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.shapes import Arc, Bore, Circle


def _approx(detail: str) -> Capability:
    return Capability(Support.APPROXIMATED, detail)


def _native(detail: str) -> Capability:
    return Capability(Support.NATIVE, detail)


def plan(scene: Scene, settings: PybulletSettings):
    """(topology, per-pair side geometries) of ``scene``; geometry errors become problems."""
    length_scale = largest_length(scene)
    sides, counts, problems = [], {}, []
    for index in range(len(scene.expanded.contacts)):
        try:
            pair = [side_geometry(scene, index, side, settings, length_scale)
                    for side in ("a", "b")]
        except ValueError as error:
            problems.append(("contacts", str(error)))
            sides.append(None)
            continue
        sides.append(pair)
        for geometry in pair:
            counts[geometry.body] = counts.get(geometry.body, 0) + len(
                collision_groups(geometry))
    topology = plan_topology(scene, settings.body_model, counts)
    return topology, sides, problems


def ring_summary(scene: Scene, settings: PybulletSettings) -> list[str]:
    """Per ring or bore pair side: pieces, and against a coaxial journal the clearance it
    gains between two pieces next to the radial clearance."""
    out = []
    unit = scene.units.length
    _, sides, _ = plan(scene, settings)
    contacts = scene.expanded.contacts
    for index, pair in enumerate(sides):
        for geometry in pair or ():
            shape = scene.expanded.body(geometry.body).shape(geometry.shape)
            if not isinstance(shape, Circle | Arc | Bore):
                continue
            line = f"{contacts[index].name} ({geometry.body}/{geometry.shape}): {geometry.note}"
            growth = pair_clearance_growth(scene, index, settings)
            if growth is not None:
                clearance, extra = growth
                line += (f"; radial clearance {clearance:.4g} {unit}, the journal gains at most "
                         f"{extra:.3g} {unit} ({100 * extra / clearance:.3g} %) between two "
                         "pieces")
            elif geometry.shape_error > 0:
                line += f" {unit}"
            out.append(line)
    return out


@dataclass(frozen=True)
class FeatureContext:
    """What the capability hooks need, derived once per scene: the scene in the model's
    internal units, the settings, the body plan and the reasons it cannot be built."""

    scene: Scene
    settings: PybulletSettings
    topology: object
    problems: dict


def feature_context(scene: Scene, settings: PybulletSettings) -> FeatureContext:
    """The context of ``scene`` (internal units) with ``settings``."""
    topology, _, geometry_problems = plan(scene, settings)
    problems: dict[str, list[str]] = {}
    for feature, reason in (*topology.problems, *law_load_problems(scene),
                            *geometry_problems):
        problems.setdefault(feature, []).append(reason)
    return FeatureContext(scene, settings, topology, problems)


def feature_problems(context: FeatureContext) -> dict[str, list[str]]:
    """Features the scene uses that PyBullet cannot build here, with the reasons."""
    return context.problems


def _rigid_words(settings: PybulletSettings, topology) -> str:
    if settings.body_model == "multibody":
        return ("every moving body is a Featherstone multibody (PyBullet's default): no split "
                "impulse, penetration corrected by contactERP "
                f"{settings.contact_erp:g} x depth / dt added to the velocity (energy)")
    multi = sorted({link.body for tree in topology.trees for link in tree.links})
    words = (f"rigid bodies in maximal coordinates ({', '.join(topology.rigid) or 'none'}) use "
             "split impulse")
    if settings.split_impulse_penetration_threshold < 0:
        words += (f" only below {settings.split_impulse_penetration_threshold:g} L of "
                  "penetration")
    if multi:
        words += (f"; multibodies ({', '.join(multi)}: joints, drivers or several contact "
                  "objects) never do")
    return words


SHAPES = {
    "sphere": (Support.NATIVE, "GEOM_SPHERE"),
    "box": (Support.NATIVE, "GEOM_BOX (an offset on side A grows the half extents: sharp "
                            "corners where the offset surface would be rounded)"),
    "capsule": (Support.NATIVE, "GEOM_CAPSULE, height = 2 half_length (between the centres)"),
    "cylinder": (Support.APPROXIMATED, "GEOM_CYLINDER, height = full length; its end caps "
                                       "collide too (the scene's cylinder touches on its "
                                       "lateral surface only)"),
    "disc": (Support.APPROXIMATED, "cylinder whose +z cap is the disc (its rim collides too)"),
}


def plain_capability(context: FeatureContext, name: str) -> Capability | None:
    """Support of a plain feature (``contacts``, ``friction``, ``drivers``, ...)."""
    scene, settings, topology = context.scene, context.settings, context.topology
    if name in ("gravity", "fixed_bodies"):
        return _native("setGravity" if name == "gravity" else
                       "static bodies (mass 0), one per collision object")
    if name == "contacts":
        margin = collision_margin(scene, settings)
        margin_words = ("PyBullet's 0.001 m margins on boxes, cylinders and planes (they "
                        "round edges by that much and a box or cylinder thinner than twice it "
                        "is malformed)") if margin is None else (
            f"margins {margin:.3g} L ({margin / margin_feature_length(scene):.3g} of the "
            "smallest feature) on boxes, cylinders and planes")
        return _approx(
            "explicit pairs only: every collision object's group and mask are 0 and each pair's "
            "objects are enabled with setCollisionFilterPair; one collision object per side of "
            "each pair (side A grown by the pair's offset). Velocity-level sequential impulses "
            f"({settings.num_solver_iterations} sweeps, residual threshold "
            f"{settings.solver_residual_threshold:g} on squared velocity changes); resting "
            f"contacts sink by the slop {settings.contact_slop:g} L; "
            + _rigid_words(settings, topology) + "; " + margin_words)
    if name == "friction":
        anchor = "with friction anchors" if settings.friction_anchor else "no friction anchors"
        return _approx(
            "Coulomb, one friction row per contact point along the sliding direction (PyBullet's "
            "solver mode has no second direction, so enableConeFriction does nothing), "
            f"{anchor}; the pair's mu on side A x 1 on side B (PyBullet multiplies them); "
            "products above 10 are clamped")
    if name == "restitution":
        return _approx(
            "Newton restitution e (side A) x 1 (side B), applied when the approach speed "
            f"exceeds {settings.restitution_velocity_threshold:g} L/T; Baumgarte position "
            "correction (contactERP) adds to the rebound where split impulse is not used")
    if name in ("rings", "arcs"):
        return _approx(f"{settings.ring_pieces} spheres per full circle (see shape:circle, "
                       "shape:arc)")
    if name == "ideal_joints":
        if topology.closures:
            return _approx("tree joints of a Featherstone multibody (exact), default motors "
                           "switched off; loops closed by constraints (soft): "
                           + ", ".join(topology.closures))
        return _native("tree joints of a Featherstone multibody (exact), default velocity "
                       "motors switched off")
    if name == "closed_loop":
        return _approx("loop-closing joints are createConstraint constraints (point-to-point, "
                       f"fixed, prismatic) with Baumgarte erp {settings.erp:g}: they drift "
                       "(0.29 mm in 2 s for a rigid-body pendulum at dt 1e-3, O(dt^2))")
    if name == "clearance_joints":
        return _approx("journal cylinder against bearing rings (rings of spheres) and flange "
                       "planes against thrust arcs: " + "; ".join(
                           line for line in ring_summary(scene, settings)
                           if any(line.startswith(f"{j.name}.") for j in
                                  scene.clearance_joints)))
    return _load_capability(name)


def _load_capability(name: str) -> Capability | None:
    if name == "springs":
        return _approx("explicit force from the reference's spring function at each step start "
                       "(diverges for stiffness x dt^2 / m above about 4)")
    if name == "torsional_springs":
        return _approx("explicit moment from the reference's spring function at each step start")
    if name in ("angle_law_loads", "distance_law_loads"):
        return _approx("explicit, one step lag: the reference solver's own force function "
                       "(ref_solver.forces.element_forces) at each step start, applied with "
                       "applyExternalForce / applyExternalTorque (WORLD_FRAME)")
    if name in ("point_forces", "moments"):
        return _native("applyExternalForce at the centre of mass with the moment of the offset, "
                       "WORLD_FRAME (a world point; LINK_FRAME would take the point from the "
                       "centre of mass), set before every step (PyBullet clears them after it)")
    if name == "time_switched_loads":
        return _approx("switched at the first step that starts inside the window")
    if name == "drivers":
        return _approx("each driven component is a joint coordinate (a revolute / prismatic "
                       "joint to a fixed body, or world slides + a spherical joint at the "
                       "centre of mass): reset to the profile before every step and held by a "
                       "velocity motor during it (exact at step starts)")
    return None


def shape_capability(context: FeatureContext, kind: str) -> Capability | None:
    """Support of the shape kind ``kind``."""
    settings = context.settings
    if kind in SHAPES:
        return Capability(*SHAPES[kind])
    if kind == "plane":
        return _native("GEOM_PLANE on fixed bodies; on moving bodies a box of half size "
                       f"{settings.plane_box_size:g} x the scene size")
    if kind == "rectangle":
        return _approx("box whose +z face is the rectangle, as thick as its depth (else "
                       f"{settings.face_thickness:g} x its half extent): edges and sides "
                       "collide too")
    if kind in ("circle", "arc", "bore"):
        how = (f"{settings.bore_pieces} capsules per full circle along the axis ("
               f"{BORE_DEPTH_NOTE})" if kind == "bore"
               else f"{settings.ring_pieces} spheres per full circle")
        return _approx(f"{how}, compounds of at most 16 children split across welded links "
                       "(PyBullet drops a compound's children beyond 16 silently; guarded): "
                       + "; ".join(ring_summary(context.scene, settings)))
    return None


def pair_capability(context: FeatureContext, kind_a: str, kind_b: str) -> Capability | None:
    """Support of contacts between two known shape kinds."""
    known = set(SHAPES) | {"plane", "rectangle", "circle", "arc", "bore"}
    if kind_a in known and kind_b in known:
        return _native("Bullet's collision algorithm for the two primitive types (GJK/EPA "
                       "for convex pairs without a special case)")
    return None


def joint_capability(context: FeatureContext, kind: str) -> Capability | None:
    """Support of the ideal joint kind ``kind``: exact as a tree joint, soft as a closure."""
    how = {"revolute": "two JOINT_POINT2POINT on the axis",
           "spherical": "one JOINT_POINT2POINT", "fixed": "a JOINT_FIXED constraint",
           "prismatic": "a JOINT_PRISMATIC constraint"}
    if kind not in how:
        return None
    names = {j.name for j in context.scene.joints if j.kind == kind}
    soft = sorted(names & set(context.topology.closures))
    if soft:
        return _approx(f"tree {kind} joints exact; loop-closing ones ({', '.join(soft)}) as "
                       f"{how[kind]}, soft: Baumgarte erp {context.settings.erp:g} (the global "
                       "erp; changeConstraint's erp does not act), drift O(dt^2)")
    return _native(f"JOINT_{kind.upper()} in a multibody tree: exact")
