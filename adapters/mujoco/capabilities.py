"""What the MuJoCo adapter does with each scene feature: native, approximated (how, how
large) or unsupported (why), one function per feature kind, asked by
:meth:`clearbench.adapters.base.Engine.capabilities`. Pure Python: stated without compiling a
model."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from clearbench.adapters.base import BORE_DEPTH_NOTE, Capability, Support
from clearbench.adapters.mujoco.geometry import (
    bore_piece_count,
    bore_radius_error,
    face_thickness,
    ring_piece_radius,
)
from clearbench.adapters.mujoco.settings import (
    MujocoSettings,
    damping_ratio_for_restitution,
    restitution_for_damping_ratio,
    ring_chord_error,
    ring_clearance_error,
)
from clearbench.adapters.mujoco.topology import Topology, plan_topology
from clearbench.kernels.quaternion import quat_multiply, quat_normalize, quat_to_matrix
from clearbench.ref_solver.scene_system import law_load_problems
from clearbench.scenarios.bodies import Motion
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.shapes import Arc, Bore, Circle, Cylinder, Disc, Plane, Rectangle

NATIVE_SHAPES = {"sphere": "sphere", "box": "box", "capsule": "capsule"}


def _approx(detail: str) -> Capability:
    return Capability(Support.APPROXIMATED, detail)


def _native(detail: str) -> Capability:
    return Capability(Support.NATIVE, detail)


def describe_solref(solref: tuple, timeconst_steps: float | None) -> str:
    """``(0.02, 1)`` or ``(2 dt, 1)`` when the timeconst follows the time step."""
    if timeconst_steps is None:
        return f"({solref[0]:g}, {solref[1]:g})"
    return f"({timeconst_steps:g} dt, {solref[1]:g})"


def describe_plastic(settings: MujocoSettings) -> str:
    """What e = 0 pairs become."""
    if settings.map_plastic:
        zeta = settings.plastic_damping_ratio
        return f"e = 0 get zeta = {zeta:g} (e = {restitution_for_damping_ratio(zeta):.3f})"
    zeta = settings.solref[1]
    return (f"e = 0 keep dampratio {zeta:g}, i.e. they rebound with "
            f"e = {restitution_for_damping_ratio(zeta):.3f}")


def ring_summary(scene: Scene, settings: MujocoSettings) -> list[str]:
    """One line per circle/arc shape: pieces, piece radius and chord error [scene L], and for
    every pair with a journal inside, the chord error next to its radial clearance."""
    out = []
    unit = scene.units.length
    for body in scene.expanded.bodies:
        for shape in body.shapes:
            if isinstance(shape, Circle | Arc):
                rho = ring_piece_radius(scene, body.name, shape, settings)
                chord = ring_chord_error(shape.radius, settings.ring_pieces, settings.ring_piece)
                line = (f"{body.name}/{shape.name}: R {shape.radius:.6g} {unit}, "
                        f"{settings.ring_piece}s of radius {rho:.3g} {unit}, chord error "
                        f"{chord:.3g} {unit}")
                for name, clearance in journal_clearances(scene, body.name, shape):
                    if clearance is not None and clearance > 0:
                        extra = ring_clearance_error(shape.radius, clearance,
                                                     settings.ring_pieces, settings.ring_piece)
                        line += f"; pair {name}: " + _clearance_words(chord, extra, clearance,
                                                                       unit)
                out.append(line)
    return out


def clearance_summary(scene: Scene, settings: MujocoSettings) -> list[str]:
    """Per clearance joint: chord error of its bore next to the clearance it distorts."""
    out = []
    unit = scene.units.length
    for joint in scene.clearance_joints:
        chord = ring_chord_error(joint.bore_radius, settings.ring_pieces, settings.ring_piece)
        extra = ring_clearance_error(joint.bore_radius, joint.radial_clearance,
                                     settings.ring_pieces, settings.ring_piece)
        out.append(
            f"{joint.name}: bore R {joint.bore_radius:.6g} {unit} as {settings.ring_pieces} "
            f"{settings.ring_piece}s, chord error {chord:.3g} {unit} "
            f"({100 * chord / joint.radial_clearance:.3g} % of the radial clearance "
            f"{joint.radial_clearance:.3g} {unit}); the journal sees the clearance grow by "
            f"at most {extra:.3g} {unit} between two pieces")
    return out


def _axis_world(scene: Scene, body_name: str, shape) -> np.ndarray:
    """World direction of a shape's z axis in the initial pose."""
    body = scene.expanded.body(body_name)
    q = quat_multiply(np.asarray(body.orientation, dtype=float),
                      np.asarray(shape.orientation, dtype=float))
    return quat_to_matrix(quat_normalize(q))[:, 2]


def journal_clearances(scene: Scene, body_name: str, shape) -> list[tuple[str, float | None]]:
    """(pair name, nominal radial clearance R - r - offset [L]) of every pair of a circle, arc
    or bore with a coaxial cylinder of smaller radius inside it (a journal); None for the
    pairs of other partners (no clearance to speak of)."""
    expanded = scene.expanded
    axis = _axis_world(scene, body_name, shape)
    out = []
    for contact in expanded.contacts:
        sides = [(contact.body_a, contact.shape_a), (contact.body_b, contact.shape_b)]
        if (body_name, shape.name) not in sides:
            continue
        other_body, other_name = next(side for side in sides if side != (body_name, shape.name))
        partner = expanded.body(other_body).shape(other_name)
        coaxial = isinstance(partner, Cylinder) and partner.radius < shape.radius and abs(
            abs(float(axis @ _axis_world(scene, other_body, partner))) - 1.0) < 1e-6
        out.append((contact.name, shape.radius - partner.radius - contact.offset
                    if coaxial else None))
    return out


def _clearance_words(error: float, extra: float, clearance: float, unit: str) -> str:
    words = (f"radial clearance {clearance:.4g} {unit}: the journal gains at most "
             f"{extra:.3g} {unit} ({100 * extra / clearance:.3g} % of it) between two pieces")
    if error > clearance:
        return words + (f"; THE POLYGON ERROR {error:.3g} {unit} EXCEEDS THIS CLEARANCE "
                        f"{clearance:.4g} {unit}")
    return words + f", the shape error is {100 * error / clearance:.3g} % of it"


def bore_summary(scene: Scene, settings: MujocoSettings) -> list[str]:
    """One line per bore: boxes, radius error of their polygon [scene L], and for every pair
    with a journal inside the nominal radial clearance c, the clearance error
    c (1/cos(step/2) - 1) and, plainly, whether the polygon's radius error exceeds c."""
    out = []
    unit = scene.units.length
    for body in scene.expanded.bodies:
        for shape in body.shapes:
            if not isinstance(shape, Bore):
                continue
            pieces = bore_piece_count(shape, settings)
            error = bore_radius_error(shape, settings)
            step = (shape.end_angle - shape.start_angle) / pieces
            span = math.degrees(shape.end_angle - shape.start_angle)
            line = (f"{body.name}/{shape.name}: R {shape.radius:.6g} {unit} over {span:.4g} deg "
                    f"as {pieces} boxes (half thickness {settings.bore_wall * shape.radius:.3g} "
                    f"{unit}), radius error up to {error:.3g} {unit} at the polygon's corners")
            for name, clearance in journal_clearances(scene, body.name, shape):
                if clearance is None:
                    line += f"; pair {name}: no journal inside, no clearance"
                    continue
                extra = clearance * (1.0 / math.cos(0.5 * step) - 1.0)
                line += f"; pair {name}: " + _clearance_words(error, extra, clearance, unit)
            out.append(line)
    return out


def face_summary(scene: Scene, settings: MujocoSettings, kind: type) -> list[str]:
    """One line per rectangle / disc: the thickness of the solid standing in for it."""
    out = []
    unit = scene.units.length
    for body in scene.expanded.bodies:
        for shape in body.shapes:
            if isinstance(shape, kind):
                source = "its depth" if shape.depth is not None else \
                    f"{settings.face_thickness:g} x its size"
                out.append(f"{body.name}/{shape.name}: {face_thickness(shape, settings):.3g} "
                           f"{unit} ({source})")
    return out


@dataclass(frozen=True)
class FeatureContext:
    """What the MuJoCo capabilities of one scene are derived from (computed once per scene)."""

    scene: Scene
    settings: MujocoSettings
    topology: Topology
    closures: frozenset       # names of the loop-closing joints (soft equalities)
    joint_kind: dict          # joint name -> kind
    moving_planes: tuple      # "body/shape" of the planes on moving bodies


def feature_context(scene: Scene, settings: MujocoSettings) -> FeatureContext:
    """The tree plan and the facts the capabilities of ``scene`` need."""
    topology = plan_topology(scene)
    moving_planes = tuple(f"{b.name}/{s.name}" for b in scene.expanded.bodies for s in b.shapes
                          if isinstance(s, Plane) and b.motion is not Motion.FIXED)
    return FeatureContext(scene, settings, topology, frozenset(topology.closures),
                          {j.name: j.kind for j in scene.joints}, moving_planes)


def feature_problems(context: FeatureContext) -> dict[str, list[str]]:
    """Features MuJoCo cannot represent for this scene (the tree plan's and the law loads'
    problems), with the reasons."""
    problems: dict[str, list[str]] = {}
    for feature, reason in (*context.topology.problems, *law_load_problems(context.scene)):
        problems.setdefault(feature, []).append(reason)
    return problems


def plain_capability(context: FeatureContext, name: str) -> Capability | None:
    """Support of a plain feature; None for one the adapter does not know."""
    settings = context.settings
    if name in ("gravity", "fixed_bodies"):
        return _native("gravity option" if name == "gravity" else "static bodies")
    if name == "contacts":
        return _approx(
            "one <pair> per scene pair and geom piece (contype = conaffinity = 0, so nothing "
            "else collides); MuJoCo contacts are soft constraints that let the gap go below "
            f"zero (solref {describe_solref(settings.solref, settings.timeconst_steps)}, "
            f"solimp {settings.solimp[:3]}); a pair's offset is its MuJoCo pair margin")
    if name == "friction":
        if settings.cone == "pyramidal":
            return _approx("pyramidal cone, soft: a body below the friction angle creeps "
                           "(docs/engines/mujoco.md: 636 um in 1 s, 10 deg incline, mu 0.3); "
                           "noslip has no effect with this cone")
        if settings.noslip_iterations > 0:
            return _approx(f"elliptic cone with {settings.noslip_iterations} noslip "
                           "iterations (docs/engines/mujoco.md: creep 0.06 um in 1 s)")
        return _approx("elliptic cone, soft: creeps (docs/engines/mujoco.md: 444 um in 1 s)")
    if name == "restitution":
        zeta_08 = damping_ratio_for_restitution(0.8, settings.plastic_damping_ratio)
        return _approx(
            "MuJoCo has no restitution parameter: e becomes the dampratio of a unilateral "
            f"spring-damper (zeta(0.8) = {zeta_08:.4f}), constant impedance, timeconst long "
            f"enough for {settings.restitution_contact_steps:g} steps per contact (softer "
            "contacts, deeper penetration); pairs with " + describe_plastic(settings))
    if name in ("rings", "arcs"):
        return _approx(f"{settings.ring_pieces} {settings.ring_piece}s per full circle "
                       "(see shape:circle / shape:arc)")
    if name == "ideal_joints":
        if context.closures:
            return _approx("tree joints (exact) on a spanning tree; loops closed by soft "
                           f"equalities: {', '.join(sorted(context.closures))}")
        return _native("tree joints (hinge / slide / ball / welded child): exact")
    if name == "closed_loop":
        solref = describe_solref(settings.equality_solref, settings.equality_timeconst_steps)
        return _approx(f"loop-closing joints are soft equalities (solref {solref}): they drift")
    if name == "clearance_joints":
        return _approx("journal cylinder against bearing rings and flange planes against "
                       "thrust rings, rings as convex pieces: " +
                       "; ".join(clearance_summary(context.scene, settings)))
    if name == "springs":
        return _native("spatial tendon between two sites (stiffness, damping, springlength); "
                       "preload as a constant motor force on the tendon")
    if name == "torsional_springs":
        return _approx("joint stiffness/damping where a tree hinge joins the two bodies about "
                       "the spring axis (exact); otherwise an explicit moment from the "
                       "relative rotation, applied before every step")
    if name in ("angle_law_loads", "distance_law_loads"):
        return _approx("explicit, one step lag: the reference solver's own force function "
                       "(ref_solver.forces.element_forces) evaluated at the configuration of "
                       "each step start, applied as xfrc_applied during the step")
    if name in ("point_forces", "moments"):
        return _native("xfrc_applied at the centre of mass (with the moment of the offset), "
                       "set before every step")
    if name == "time_switched_loads":
        return _approx("switched at the first step that starts inside the window "
                       "(resolution one time step)")
    if name == "drivers":
        return _approx(
            "each driven component is a joint of the body (hinge / slide to a fixed body, or "
            "world slides; a body whose three rotations are held at zero has no rotational "
            "freedom at all, exact) with armature "
            f"{settings.driver_armature_ratio:g} x its inertia, position and velocity reset to "
            "the profile before every step (exact at step starts; reactions from the "
            "dynamics). Not mocap bodies: MuJoCo gives them no velocity, so contacts and "
            "joined bodies would not see the motion")
    return None


def shape_capability(context: FeatureContext, kind: str) -> Capability | None:
    """Support of a shape kind; None for one the adapter does not know."""
    scene, settings = context.scene, context.settings
    if kind in NATIVE_SHAPES:
        return _native(f"MuJoCo {NATIVE_SHAPES[kind]}")
    if kind == "cylinder":
        return _native("MuJoCo cylinder (its flat end caps collide too; the scene's "
                       "cylinder touches on its lateral surface only)")
    if kind == "plane":
        if context.moving_planes:
            return _approx(
                "MuJoCo plane on fixed bodies; on moving bodies (MuJoCo planes must be "
                f"static) a cube of half size {settings.plane_box_size:g} x the scene "
                f"size whose face is the plane: {', '.join(context.moving_planes)}")
        return _native("MuJoCo plane")
    if kind == "rectangle":
        return _approx("box whose +z face is the rectangle, as thick as the shape's depth "
                       f"(else {settings.face_thickness:g} x its larger half extent); its "
                       "edges and sides collide too (the scene's rectangle contacts on "
                       "its face only): " + "; ".join(face_summary(scene, settings,
                                                                    Rectangle)))
    if kind == "disc":
        return _approx("cylinder whose +z end cap is the disc, as thick as the shape's "
                       f"depth (else {settings.face_thickness:g} x its radius); its rim "
                       "and edge collide too: " + "; ".join(face_summary(scene, settings,
                                                                          Disc)))
    if kind == "bore":
        return _approx(
            f"MuJoCo geoms are convex: {settings.bore_pieces} boxes per full circle line "
            "the hole, their inner faces the circumscribed polygon (apothem R), so the "
            "hole is up to R (1/cos(pi/N) - 1) larger at the corners; the boxes' end faces "
            f"collide too (beyond the bore's angles and length); {BORE_DEPTH_NOTE}: "
            + "; ".join(bore_summary(scene, settings)))
    if kind in ("circle", "arc"):
        return _approx(f"ring of {settings.ring_pieces} {settings.ring_piece}s per full "
                       "circle: " + "; ".join(ring_summary(scene, settings)))
    return None


def pair_capability(context: FeatureContext, kind_a: str, kind_b: str) -> Capability | None:
    """Support of a pair of shape kinds: native between shapes the adapter knows (each a
    geom, or a ring of geom pieces); None otherwise."""
    if shape_capability(context, kind_a) is None or shape_capability(context, kind_b) is None:
        return None
    return _native("MuJoCo collision function for the two geom types (one pair per "
                   "piece of a ring)")


#: How a tree joint of each kind is built, and a loop-closing one approximated.
TREE_JOINTS = {"revolute": "hinge", "prismatic": "slide", "spherical": "ball",
               "fixed": "child welded to its parent"}
CLOSURES = {"revolute": "two connect equalities on the axis",
            "spherical": "one connect equality", "fixed": "one weld equality"}


def joint_capability(context: FeatureContext, kind: str) -> Capability | None:
    """Support of an ideal joint kind; None for one the adapter does not know."""
    if kind not in TREE_JOINTS:
        return None
    soft = sorted(name for name in context.closures if context.joint_kind[name] == kind)
    if soft:
        return _approx(f"tree {kind} joints exact; loop-closing ones ({', '.join(soft)}) "
                       f"as {CLOSURES[kind]} (soft, drift)")
    return _native(TREE_JOINTS[kind] + " in the tree: exact")
