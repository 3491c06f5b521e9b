"""The Schneider Electric C-60 circuit-breaker mechanism as a scene, in mm, g, ms (forces in N).

Built from the data sheet ``data/c60/model.toml`` (bodies, contacts, offsets, friction, loads,
driver, measurement pairs, all transcribed from the public Siconos example "Trip_Magnetic") and
from the exact primitives of its CAD surfaces ``data/c60/primitives.json`` (see PRIMITIVES.md).

Bodies. The frame (case and cover, fixed, at the identity: its surfaces are in world
coordinates) and 8 moving bodies: handle, rod, hook, plate, moving contact, tripping bar, plunger
(the magnetic plunger, driven along world x) and needle. Body frames are the CAD frames, placed
by the data sheet's initial ON pose (``origin`` + rotation ``rotation_angle`` about
``rotation_axis``); centres of mass and inertias from the sheet, except the needle, which takes
the paper's mass and inertia (0.39 g, diag(8.5112, 0.19729, 8.5611) g mm^2; the source's 0.1 g
and identity inertia are placeholders).

Contacts. Each of the 39 contact pairs of the sheet, body1 = A (the offset is taken on A's side,
as the source does; friction the sheet's or as :mod:`.variants` says), each CAD surface
reduced to a shape:

* bearing ring (a band 0.005-0.02 mm wide) -> :class:`~.shapes.Circle` at the middle of the band;
* convex cylinder or cylinder patch (journals, the C5, C7 and FC_X patches, the C4 fillet) ->
  :class:`~.shapes.Cylinder` (its angular extent is not bounded: the contact tests check that
  every contact that carries force stays on its CAD patch);
* concave cylinder patch (the C4 hollow) and the plunger's sleeve -> :class:`~.shapes.Bore`
  (angles and length bounded);
* plane face -> :class:`~.shapes.Rectangle` (its bounding rectangle in the face's (u, v) axes),
  or :class:`~.shapes.Disc` for the round plunger face; the normal points out of the material
  as the part's ``outward`` flag says, or toward the partner surface in the ON pose for the
  frame's faces (no material data); a single face must face its partner (checked);
* arc (a half ring standing for a rounded edge) -> :class:`~.shapes.Arc`; stray points dropped.

The latch's edge (``latch_edge``, :mod:`.variants`). The tripping bar's latch corner, where the
hook's latch face rests (C4_3, C4_4), is a half ring of 0.5 mm in the source's arc files, a
sharp corner in the bar's solid, and rounded by a convex r 0.05 mm fillet in the source's wedge
file (C4_1, C4_2). By default (``fillet``) the half ring's centre line is moved onto that
fillet's axis and the fillet's radius is added to the pair's offset: the pair's gap is then the
gap of the torus of that radius about the moved half ring, whose section at the contact is the
fillet's. Against the face's solid (its free edge sharp, as in the hook's solid) the gap and
normal stay continuous while the bar's corner slides off the face's edge. ``face-normal`` keeps
the source's bare half rings and continues the hook's face past its free edge by
:data:`FACE_NORMAL_EXTENSION` (the face's normal and plane gap there, as the source's CAD
distance takes them). docs/c60.md states the CAD evidence.

A surface made of several faces (the C4 wedge of the tripping bar: side plane, top plane,
concave hollow, convex fillet) gives one contact pair per face, named ``<pair>_<face>``: the
source takes one minimum distance over the composite surface, the union of per-face pairs
has that minimum among its candidates and keeps a second point where two faces meet.

Radial clearances. Joint Jj's rings get the offset ``CAD gap - clearance`` (CAD gap = ring radius
- journal radius, 0.5 mm except J1's top ring, 0.52 mm); by default the sheet's offsets stand
(0.021 mm, and 0.041 mm at J1 top), ``clearances={"J3": 0.06, ...}`` overrides joints one by
one (both rings of a joint get the given clearance).

Loads (see :mod:`.loads`, law loads; the signs below are the physical actions, the source's
plugin functions being registered as internal forces that Siconos subtracts):

* ``handle_spring``: torsion law C = 3.82 (1.99 + |theta_0| - theta_handle) N mm, applied as a
  force C / 5.65 along the handle's body x axis. theta is the absolute rotation about world z;
  the source's initial angle is unsigned (2 acos(q0_w), +0.3316 rad for the -0.3316 rad pose),
  reproduced here. The force acts at the point that gives the source's moment: the source takes
  the moment about the centre of mass with the arm R (P0 - z0), where P0 = (0, -5.65, -0.9) and
  the plugin parameter z0 is the body's INITIAL CENTRE-OF-MASS POSITION IN WORLD (Siconos passes
  q0 as the plugin's z), not the centre of mass in the body frame: the force therefore acts at
  body point G + P0 - z0 (``handle_spring_arm="source"``, default). ``"design"`` applies it at P0
  (a moment of C about the pivot, the evident intent).
* ``plate_spring_A2``: distance law s = 1.16 (18.44 - L), L from frame point (11.8, 9, 1.95) to
  plate point (0.19, 9, -7.6), applied as a force s along the plate's body -x axis at that point.
* ``contact_pressure_spring``: angle law M = 244.46 (theta_mc - theta_plate + (54.54 + 22) deg +
  0.49 rad) N mm, applied as a force M / 5.48 along plate body (-1.1, 0.9, 0) at its centre of
  mass, a moment 0.2513 M about world z on the plate, and a force M / 6.06 along moving-contact
  body (0.6, -1.1, -0.01) at its centre of mass. The source's comments document other
  preloads, offsets and levers: :mod:`.variants` makes each a named, validated parameter
  (``contact_spring_preload``, ``contact_spring_angle_offset``, ``moving_contact_force_lever``,
  ``plate_force_lever``) and ``clearbench c60 identify`` measures what each does to the paper's
  figures.
* ``tripping_bar_moment``: a moment on the tripping bar about world z for t < 1 ms. The source's
  function returns +15 N mm, registered as an internal moment, i.e. the physical moment is
  -15 N mm (it presses the bar toward its stop, away from tripping).

Driver: the plunger's world x velocity, 0 before ``plunger_start`` (0.7 ms in the source) and
``plunger_speed`` (0.2 mm/ms) after; the other 5 components are free (held by the sleeve).

Outputs: ``FC1_contact_force`` (normal force of C7, moving on fixed contact) and the 7
measurement pairs of the sheet as point distances (see :data:`FUNCTIONAL_CONDITIONS`).
"""

from __future__ import annotations

import dataclasses
import math
import re
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np

from clearbench.scenarios.bodies import Body, Motion
from clearbench.scenarios.c60 import primitives as prim
from clearbench.scenarios.c60.variants import ModelParameters, contact_friction
from clearbench.scenarios.contacts import ContactPair
from clearbench.scenarios.drivers import Driver
from clearbench.scenarios.expectations import Expectation
from clearbench.scenarios.loads import AngleLawLoad, DistanceLawLoad, LoadApplication, Moment
from clearbench.scenarios.outputs import ContactForce, Output, PointDistance
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.shapes import Arc, Bore, Circle, Cylinder, Disc, Rectangle, Shape
from clearbench.scenarios.units import MM_G_MS
from clearbench.scenarios.validation import SceneError

MODEL_PATH = prim.PRIMITIVES_PATH.parent / "model.toml"
FRAME = "frame"
PLUNGER = "plunger"
JOINTS = ("J1", "J2", "J3", "J4", "J5", "J6", "J7")
#: The moving/fixed contact pair whose normal force is FC-1.
C7 = "Mcontact_Fcontact_bot_1_C7"
#: Face labels of the C4 wedge file (in its primitive order): the side plane (x = 0.25 in the
#: bar frame), the top plane (y = 7, on which the hook's half rings rest in the ON pose), the
#: concave hollow below the side plane (r 5.9) and the convex fillet (r 0.05) between the planes.
WEDGE_FACES = ("side", "top", "hollow", "fillet")
Z_AXIS = (0.0, 0.0, 1.0)
#: How far the solid behind a plane contact face or a partial bore reaches [mm]
#: (``Rectangle.depth``, ``Bore.depth``): a partner
#: deeper than this has gone round behind the part, it is not in it. Without it the handle,
#: which turns freely after a trip (the source has no OFF stop), brings its ON-stop face back
#: round behind the case's stop pins 8.5 mm "deep" at 15.2 ms of c60-trip, and the projection
#: tears the handle out of its bearing. 0.5 mm is 250x the deepest motion of a contact in one
#: step (about 2 mm/ms x 1e-3 ms) and below the thickness of the C-60's plates and walls
#: (about 1 mm; an estimate, not measured on the CAD). Likewise, after the trip the tripping
#: bar's C4 partners leave the hook's concave hollow (a partial bore) round behind it, 13.4 mm
#: "deep" at 19.62 ms of c60-trip, and the projection moved the parts 6.4 mm in one step.
FACE_DEPTH = 0.5
#: The latch pairs whose tripping-bar arc (a half ring of 0.5 mm about the bar's latch corner,
#: ``REVISED_CAD3/C4/Tbar_half_ring_C4_*``) meets the hook's latch face
#: (``REVISED_CAD1/C4/Hook_Tbar_C4_surface``), and the file of the source that rounds that corner
#: (the wedge surface of C4_1/C4_2: its ``fillet`` face, r 0.05 mm about the corner).
LATCH_CORNER_CONTACTS = ("Hook_Tbar_C4_3", "Hook_Tbar_C4_4")
LATCH_FILLET_FILE = "C60/C4/Tbar_hook_wedge_surface_C4.stp"
#: How far ``latch_edge="face-normal"`` continues the hook's latch face past its free edge [mm]:
#: 20 times the face's width, beyond any motion of the bar's arc over it before the latch has
#: let go (the source's CAD distance continues the face's normal without end).
FACE_NORMAL_EXTENSION = 10.0


@lru_cache(maxsize=1)
def load_model(path: Path = MODEL_PATH) -> dict[str, Any]:
    """The data sheet as a dict (read once)."""
    with Path(path).open("rb") as stream:
        return tomllib.load(stream)


@lru_cache(maxsize=1)
def primitives() -> prim.PrimitiveSet:
    """The extracted primitives (read once)."""
    return prim.load_primitives()


def prototype_clearances() -> dict[str, float]:
    """Radial clearances of the Section 5 prototype (paper, Table 7) [mm]."""
    return dict(load_model()["paper"]["prototype_radial_clearance_mm"])


# ------------------------------------------------------------------------------------------------
# Poses
# ------------------------------------------------------------------------------------------------


def _quaternions():
    """:mod:`clearbench.kernels.quaternion`, imported at the first build: it imports numba
    (about a second), which registering and listing the C-60 scenes do not need."""
    from clearbench.kernels import quaternion

    return quaternion


@dataclass(frozen=True)
class Pose:
    """World pose of a body frame: position (3,) [mm], unit quaternion (4,) (w, x, y, z)."""

    position: np.ndarray
    quaternion: np.ndarray

    @property
    def rotation(self) -> np.ndarray:
        return _quaternions().quat_to_matrix(self.quaternion)

    def point(self, local) -> np.ndarray:
        return self.position + self.rotation @ np.asarray(local, dtype=float)

    def direction(self, local) -> np.ndarray:
        return self.rotation @ np.asarray(local, dtype=float)


def on_pose(body: Mapping[str, Any]) -> Pose:
    """The data sheet's initial (ON) pose of a body entry."""
    quaternion = _quaternions().quat_from_axis_angle(np.asarray(body["rotation_axis"], dtype=float),
                                      float(body["rotation_angle"]))
    return Pose(np.asarray(body["origin"], dtype=float), quaternion)


def on_poses() -> dict[str, Pose]:
    """ON pose of every body of the sheet, and of the frame (identity)."""
    poses = {b["name"]: on_pose(b) for b in load_model()["bodies"]}
    poses[FRAME] = Pose(np.zeros(3), np.array([1.0, 0.0, 0.0, 0.0]))
    return poses


def _frame_quaternion(x_axis, z_axis) -> tuple[float, float, float, float]:
    """Quaternion of the frame whose x and z axes are ``x_axis`` and ``z_axis`` (made
    orthonormal: x is projected off z)."""
    z = np.asarray(z_axis, dtype=float)
    z = z / np.linalg.norm(z)
    x = np.asarray(x_axis, dtype=float)
    x = x - (x @ z) * z
    x = x / np.linalg.norm(x)
    matrix = np.column_stack((x, np.cross(z, x), z))
    return tuple(float(c) for c in _quaternions().quat_from_matrix(matrix))  # type: ignore[return-value]


# ------------------------------------------------------------------------------------------------
# CAD primitives -> shapes
# ------------------------------------------------------------------------------------------------


def _file_stem(cad_path: str) -> str:
    return Path(cad_path).stem


def _representative_points(primitive: prim.Primitive) -> list[np.ndarray]:
    """A few points of a primitive (file frame) used to tell which side of a plane it is on."""
    if isinstance(primitive, prim.Arc):
        middle = 0.5 * (primitive.start_angle + primitive.end_angle)
        return [np.asarray(primitive.point_at(middle)), np.asarray(primitive.centre)]
    if isinstance(primitive, prim.Cylinder):
        return [np.asarray(primitive.axis_point)
                + 0.5 * primitive.length * np.asarray(primitive.axis)]
    if isinstance(primitive, prim.Plane):
        return [np.asarray(primitive.point)]
    if isinstance(primitive, prim.Point):
        return [np.asarray(primitive.position)]
    raise TypeError(f"no representative point for {primitive!r}")


def _plane_shape(name: str, plane: prim.Plane, toward_world: np.ndarray, pose: Pose,
                 round_face: bool, single_face: bool) -> Shape:
    """A plane face as a Rectangle (or Disc), +z out of the material: along the face's normal
    as ``outward`` says, or toward ``toward_world`` (the partner) where it is unknown (frame
    faces). A single face with a known ``outward`` must also face its partner."""
    normal = np.asarray(plane.normal, dtype=float)
    point_world = pose.point(plane.point)
    side = float((toward_world - point_world) @ pose.direction(normal))
    sign = float(plane.outward) if plane.outward is not None else (1.0 if side > 0 else -1.0)
    if single_face and sign * side <= 0.0:
        raise ValueError(f"plane {name}: its partner lies on the material side "
                         f"(outward {plane.outward}, partner side {side:+.4g} mm)")
    u_axis = np.asarray(plane.u_axis, dtype=float)
    orientation = _frame_quaternion(u_axis, sign * normal)
    half_u = 0.5 * (plane.u_range[1] - plane.u_range[0])
    half_v = 0.5 * (plane.v_range[1] - plane.v_range[0])
    centre = tuple(float(c) for c in plane.point)
    if round_face:
        if abs(half_u - half_v) > 1e-9:
            raise ValueError(f"plane {name}: a round face needs a square bounding box")
        return Disc(name, position=centre, orientation=orientation, radius=half_u,
                    depth=FACE_DEPTH)
    return Rectangle(name, position=centre, orientation=orientation,
                     half_extents=(half_u, half_v), depth=FACE_DEPTH)


def _round_face(plane: prim.Plane) -> bool:
    """True when every boundary edge of the face is an arc of one circle (a disc)."""
    edges = plane.boundary
    return bool(edges) and all(isinstance(e, prim.Arc) for e in edges) and len(
        {round(e.radius, 9) for e in edges}) == 1


def _is_bore(cylinder: prim.Cylinder, pose: Pose, partners: list[prim.Primitive],
             partner_pose: Pose) -> bool:
    """Material outside? As extracted; for the frame's surfaces (no solid in the data set):
    a bore when its partner is a parallel cylinder or ring of smaller radius whose axis lies
    inside it (the plunger in its sleeve), a convex surface otherwise (journals, fillets)."""
    if cylinder.material is not None:
        return cylinder.material == "outside"
    axis = pose.direction(cylinder.axis)
    origin = pose.point(cylinder.axis_point)
    for partner in partners:
        if not isinstance(partner, prim.Cylinder):
            continue
        partner_axis = partner_pose.direction(partner.axis)
        offset = partner_pose.point(partner.axis_point) - origin
        off_axis = np.linalg.norm(offset - (offset @ axis) * axis)
        if (abs(abs(partner_axis @ axis) - 1.0) < 1e-9 and off_axis < cylinder.radius
                and partner.radius < cylinder.radius):
            return True
    return False


def _shape(name: str, primitive: prim.Primitive, toward_world: np.ndarray, pose: Pose,
           single_face: bool = True, bore: bool = False) -> Shape:
    """Our shape for one primitive of a body's contact surface (file frame = body frame);
    ``bore``: a cylinder with its material outside."""
    if isinstance(primitive, prim.Ring):
        circle = primitive.mid_circle
        return Circle(name, position=tuple(circle.centre),
                      orientation=_frame_quaternion(circle.x_axis, circle.normal),
                      radius=circle.radius)
    if isinstance(primitive, prim.Cylinder):
        axis = np.asarray(primitive.axis, dtype=float)
        centre = np.asarray(primitive.axis_point) + 0.5 * primitive.length * axis
        orientation = _frame_quaternion(primitive.x_axis, axis)
        if bore:
            # A full bore keeps the exact default range (the document rounds 2 pi to 12 digits).
            # A partial bore (the C4 hollow, a concave patch) can be left round behind its
            # solid as a face can (FACE_DEPTH); a full bore cannot be left that way.
            angles = {} if primitive.is_full else dict(start_angle=primitive.start_angle,
                                                       end_angle=primitive.end_angle,
                                                       depth=FACE_DEPTH)
            return Bore(name, position=tuple(centre), orientation=orientation,
                        radius=primitive.radius, half_length=0.5 * primitive.length, **angles)
        return Cylinder(name, position=tuple(centre), orientation=orientation,
                        radius=primitive.radius, half_length=0.5 * primitive.length)
    if isinstance(primitive, prim.Arc):
        return Arc(name, position=tuple(primitive.centre),
                   orientation=_frame_quaternion(primitive.x_axis, primitive.normal),
                   radius=primitive.radius, start_angle=primitive.start_angle,
                   end_angle=primitive.end_angle)
    if isinstance(primitive, prim.Plane):
        return _plane_shape(name, primitive, toward_world, pose, _round_face(primitive),
                            single_face)
    raise TypeError(f"no shape for primitive {primitive!r}")


def _contact_primitives(cad_path: str) -> list[prim.Primitive]:
    """The primitives of a contact surface file that are surfaces (stray points dropped)."""
    return [p for p in primitives()[cad_path].primitives if not isinstance(p, prim.Point)]


def face_labels(cad_path: str, count: int) -> list[str]:
    """Labels of the faces of a contact surface file (empty for a single face)."""
    if count == 1:
        return [""]
    if Path(cad_path).stem == "Tbar_hook_wedge_surface_C4" and count == len(WEDGE_FACES):
        return list(WEDGE_FACES)
    return [f"face{k + 1}" for k in range(count)]


def sheet_contact_name(pair_name: str) -> str:
    """The data sheet's contact a scene pair comes from (``Hook_Tbar_C4_1_top`` ->
    ``Hook_Tbar_C4_1``)."""
    names = {c["name"] for c in load_model()["contacts"]}
    if pair_name in names:
        return pair_name
    base = pair_name.rsplit("_", 1)[0]
    if base in names:
        return base
    raise KeyError(f"{pair_name!r} comes from no contact of the data sheet")


def joint_of(contact_name: str) -> str | None:
    """``J1`` .. ``J7`` for the bearing-ring contacts of a revolute joint, else None."""
    match = re.search(r"_(J[1-7])_", contact_name)
    return match.group(1) if match else None


def cad_radial_gap(contact: Mapping[str, Any]) -> float:
    """Ring radius minus journal radius of a joint contact in the CAD [mm]."""
    ring = next(p for p in _contact_primitives(contact["cad1"]) if isinstance(p, prim.Ring))
    journal = next(p for p in _contact_primitives(contact["cad2"])
                   if isinstance(p, prim.Cylinder) and not isinstance(p, prim.Ring))
    return ring.radius - journal.radius


def contact_offsets(clearances: Mapping[str, float] | None = None) -> dict[str, float]:
    """Offset of every contact of the sheet [mm]; joint rings from ``clearances`` if given."""
    clearances = dict(clearances or {})
    unknown = sorted(set(clearances) - set(JOINTS))
    if unknown:
        raise SceneError("clearances", clearances, f"unknown joints {unknown}; joints: {JOINTS}")
    offsets = {}
    for contact in load_model()["contacts"]:
        joint = joint_of(contact["name"])
        if joint in clearances:
            clearance = clearances[joint]
            if not isinstance(clearance, int | float) or not 0.0 < clearance < 0.5:
                raise SceneError(f"clearances.{joint}", clearance,
                                 "must be a radial clearance in (0, 0.5) mm")
            offsets[contact["name"]] = cad_radial_gap(contact) - float(clearance)
        else:
            offsets[contact["name"]] = float(contact["offset"])
    return offsets


def radial_clearances(scene: Scene) -> dict[str, float]:
    """Radial clearance of each ring contact of a C-60 scene (CAD gap - offset) [mm]."""
    by_name = {c["name"]: c for c in load_model()["contacts"]}
    return {c.name: cad_radial_gap(by_name[c.name]) - c.offset for c in scene.contacts
            if joint_of(c.name)}


# ------------------------------------------------------------------------------------------------
# Bodies, shapes, contacts
# ------------------------------------------------------------------------------------------------


def _contact_geometry(offsets: Mapping[str, float], poses: Mapping[str, Pose],
                      parameters: ModelParameters):
    """Shapes per body and the contact pairs, from the sheet's contacts (friction per
    ``parameters``)."""
    shapes: dict[str, dict[str, Shape]] = {name: {} for name in poses}
    pairs: list[ContactPair] = []
    for contact in load_model()["contacts"]:
        friction = contact_friction(contact, parameters, _file_stem)
        side_shapes = []
        for side, other in (("1", "2"), ("2", "1")):
            body = contact[f"body{side}"]
            cad = contact[f"cad{side}"]
            partner = _contact_primitives(contact[f"cad{other}"])
            partner_pose = poses[contact[f"body{other}"]]
            toward = np.mean([partner_pose.point(p) for q in partner
                              for p in _representative_points(q)], axis=0)
            names = []
            items = _contact_primitives(cad)
            for label, primitive in zip(face_labels(cad, len(items)), items, strict=True):
                name = _file_stem(cad) + (f"_{label}" if label else "")
                bore = isinstance(primitive, prim.Cylinder) and _is_bore(
                    primitive, poses[body], partner, partner_pose)
                shape = _shape(name, primitive, toward, poses[body], len(items) == 1, bore)
                if contact["name"] in LATCH_CORNER_CONTACTS:
                    shape = _latch_edge_shape(shape, parameters.latch_edge)
                known = shapes[body].get(name)
                if known is not None and known != shape:
                    raise ValueError(f"shape {name} of {body} differs between two contacts")
                shapes[body][name] = shape
                names.append((label, name))
            side_shapes.append(names)
        for label_a, shape_a in side_shapes[0]:
            for label_b, shape_b in side_shapes[1]:
                label = "_".join(x for x in (label_a, label_b) if x)
                pairs.append(ContactPair(
                    contact["name"] + (f"_{label}" if label else ""),
                    body_a=contact["body1"], shape_a=shape_a, body_b=contact["body2"],
                    shape_b=shape_b, friction=friction,
                    restitution=float(contact["restitution"]),
                    offset=offsets[contact["name"]] + _latch_offset(contact["name"],
                                                                    parameters.latch_edge)))
    return shapes, pairs


def latch_fillet() -> prim.Cylinder:
    """The fillet face of the tripping bar's wedge surface (:data:`LATCH_FILLET_FILE`): the
    convex r 0.05 mm cylinder about the bar's latch corner (bar frame)."""
    faces = dict(zip(WEDGE_FACES, _contact_primitives(LATCH_FILLET_FILE), strict=True))
    fillet = faces["fillet"]
    if not isinstance(fillet, prim.Cylinder) or fillet.radius > 0.1:
        raise ValueError(f"{LATCH_FILLET_FILE}: its fourth face is not the corner's fillet")
    return fillet


def _latch_offset(contact_name: str, latch_edge: str) -> float:
    """What ``latch_edge`` adds to a latch pair's offset [mm]: the fillet's radius (the
    tube's) for ``fillet``, nothing otherwise."""
    if contact_name in LATCH_CORNER_CONTACTS and latch_edge == "fillet":
        return latch_fillet().radius
    return 0.0


def _latch_edge_shape(shape: Shape, latch_edge: str) -> Shape:
    """A latch pair's shape under ``latch_edge`` (module docstring): the bar's half ring
    moved onto the fillet's axis (``fillet``), or the hook's face continued past its free edge
    (``face-normal``); the other side as it is."""
    if isinstance(shape, Arc) and latch_edge == "fillet":
        fillet = latch_fillet()
        rotation = _quaternions().quat_to_matrix(np.asarray(shape.orientation, dtype=float))
        middle = 0.5 * (shape.start_angle + shape.end_angle)
        apex = np.asarray(shape.position) + shape.radius * (
            math.cos(middle) * rotation[:, 0] + math.sin(middle) * rotation[:, 1])
        axis = np.asarray(fillet.axis, dtype=float)
        offset = apex - np.asarray(fillet.axis_point, dtype=float)
        on_axis = apex - (offset - (offset @ axis) * axis)
        return dataclasses.replace(shape, position=tuple(
            float(c) for c in np.asarray(shape.position) + on_axis - apex))
    if isinstance(shape, Rectangle) and latch_edge == "face-normal":
        rotation = _quaternions().quat_to_matrix(np.asarray(shape.orientation, dtype=float))
        half_x, half_y = shape.half_extents
        # The face's free edge is its -x edge (the edge against the C5 surface, docs/c60.md).
        centre = np.asarray(shape.position) - 0.5 * FACE_NORMAL_EXTENSION * rotation[:, 0]
        return dataclasses.replace(shape, position=tuple(float(c) for c in centre),
                                   half_extents=(half_x + 0.5 * FACE_NORMAL_EXTENSION, half_y))
    return shape


def _bodies(shapes: Mapping[str, Mapping[str, Shape]]) -> list[Body]:
    bodies = [Body(FRAME, motion=Motion.FIXED, shapes=tuple(shapes[FRAME].values()))]
    for entry in load_model()["bodies"]:
        name = entry["name"]
        pose = on_pose(entry)
        mass = float(entry.get("paper_mass", entry["mass"]))
        inertia = np.asarray(entry.get("paper_inertia", entry["inertia"]), dtype=float)
        # The sheet's off-diagonal pairs differ in their 8th digit (6.015089 / 6.0150893 on
        # the handle): printed round-off of a symmetric tensor, symmetrised here.
        inertia = 0.5 * (inertia + inertia.T)
        bodies.append(Body(
            name, mass=mass, inertia=tuple(tuple(float(x) for x in row) for row in inertia),
            center_of_mass=tuple(float(x) for x in entry["center_of_mass"]),
            position=tuple(float(x) for x in pose.position),
            orientation=tuple(float(x) for x in pose.quaternion),
            velocity=tuple(float(x) for x in entry["velocity"][:3]),
            angular_velocity=tuple(float(x) for x in entry["velocity"][3:]),
            motion=Motion.DRIVEN if name == PLUNGER else Motion.FREE,
            shapes=tuple(shapes[name].values()),
        ))
    return bodies


# ------------------------------------------------------------------------------------------------
# Loads
# ------------------------------------------------------------------------------------------------


def _body_entry(name: str) -> Mapping[str, Any]:
    return next(b for b in load_model()["bodies"] if b["name"] == name)


def handle_spring_point(arm: str = "source") -> tuple[float, float, float]:
    """Body point where the handle spring's force acts (see the module docstring) [mm]."""
    load = next(item for item in load_model()["loads"] if item["name"] == "handle_spring")
    lever_point = np.asarray(load["force_point_body"], dtype=float)
    if arm == "design":
        return tuple(float(x) for x in lever_point)  # type: ignore[return-value]
    if arm != "source":
        raise SceneError("handle_spring_arm", arm, "must be 'source' or 'design'")
    entry = _body_entry("handle")
    pose = on_pose(entry)
    centre = np.asarray(entry["center_of_mass"], dtype=float)
    initial_centre_world = pose.point(centre)
    return tuple(float(x) for x in centre + lever_point - initial_centre_world)  # type: ignore


def _unsigned_initial_angle(body: str) -> float:
    """The source's 2 acos(q0_w): the initial rotation angle without its sign [rad]."""
    return abs(float(_body_entry(body)["rotation_angle"]))


def c60_loads(parameters: ModelParameters | None = None, bar_moment_sign: float = -1.0) -> list:
    """The 4 loads of the sheet as scene loads (see the module docstring), with the
    contact-pressure law's preload, offset and levers and the handle spring's arm from
    ``parameters`` (the source's by default, see :mod:`.variants`)."""
    parameters = parameters or ModelParameters()
    sheet = {item["name"]: item for item in load_model()["loads"]}
    handle = sheet["handle_spring"]
    a2 = sheet["plate_spring_A2"]
    contact = sheet["contact_pressure_spring"]
    bar = sheet["tripping_bar_moment"]
    plate_centre = tuple(_body_entry("plate")["center_of_mass"])
    moving_centre = tuple(_body_entry("moving_contact")["center_of_mass"])
    lever = abs(float(handle["force_point_body"][1]))  # 5.65 mm
    return [
        AngleLawLoad(
            "handle_spring", axis=Z_AXIS, stiffness=float(handle["stiffness"]),
            offset=float(handle["preload_angle"]) + _unsigned_initial_angle("handle"),
            angle_bodies=("handle",), angle_coefficients=(-1.0,),
            applications=(LoadApplication(
                "handle", "force", tuple(handle["force_direction_body"]), "body",
                handle_spring_point(parameters.handle_spring_arm), lever=lever),),
        ),
        DistanceLawLoad(
            "plate_spring_A2", body_a=FRAME, point_a=tuple(a2["frame_point"]), body_b="plate",
            point_b=tuple(a2["body_point"]), stiffness=float(a2["stiffness"]),
            rest_length=float(a2["rest_length"]),
            applications=(LoadApplication("plate", "force", tuple(a2["force_direction_body"]),
                                          "body", tuple(a2["body_point"])),),
        ),
        AngleLawLoad(
            "contact_pressure_spring", axis=Z_AXIS, stiffness=float(contact["stiffness"]),
            offset=(math.radians(-parameters.contact_spring_angle_offset)
                    + parameters.contact_spring_preload),
            angle_bodies=("moving_contact", "plate"), angle_coefficients=(1.0, -1.0),
            applications=(
                LoadApplication("plate", "force", (-1.1, 0.9, 0.0), "body", plate_centre,
                                lever=parameters.plate_force_lever),
                LoadApplication("plate", "moment", Z_AXIS, "world", coefficient=0.2513),
                LoadApplication("moving_contact", "force", (0.6, -1.1, -0.01), "body",
                                moving_centre, lever=parameters.moving_contact_force_lever),
            ),
        ),
        Moment("tripping_bar_moment", body="tripping_bar",
               moment=tuple(bar_moment_sign * abs(float(m)) if m else 0.0
                            for m in bar["moment_world"]),
               frame="world", start_time=0.0, end_time=1.0),
    ]


# ------------------------------------------------------------------------------------------------
# Outputs: FC-1 and the measurement pairs
# ------------------------------------------------------------------------------------------------

#: Functional conditions of the paper (Table 1) -> (output name, description).
FUNCTIONAL_CONDITIONS = {
    "FC-1": ("FC1_contact_force", "normal force of C7, moving on fixed contact [N]"),
    "FC-2": ("Tbar_FC_X", "x of the tripping-bar pin axis (the needle axis is x = 0) [mm]"),
    "FC-3": ("Tbar_FC_Y", "-y of the tripping-bar pin axis (needle axis y = 0) [mm]"),
    "FC-4": ("Tbar_Lamage_FC_axis_X", "x of the lamage axis (segment middle) [mm]"),
    "FC-5": ("Tbar_Lamage_FC_axis_Y", "-y of the lamage axis (segment middle) [mm]"),
    "FC-6": ("Tbar_Magnetic_FC_X", "x distance of the tripping bar's magnetic face (its point "
             "nearest the case in the ON pose) from the case plane x = -5 [mm]"),
}


def _nearest_point(body_file: str, plane_file: str, pose: Pose) -> np.ndarray:
    """Point (body frame) [mm] of a body feature nearest a world plane in the ON pose, (3,).

    Every scene of a campaign asks the same few (7 measurements, one pose each), and a search
    goes over thousands of candidate points; so each is searched once per process.
    """
    position = np.asarray(pose.position, dtype=float).tobytes()
    quaternion = np.asarray(pose.quaternion, dtype=float).tobytes()
    return np.array(_nearest_point_searched(body_file, plane_file, position, quaternion))


@lru_cache(maxsize=256)
def _nearest_point_searched(body_file: str, plane_file: str, position: bytes,
                            quaternion: bytes) -> tuple[float, float, float]:
    """:func:`_nearest_point` for the pose whose position and quaternion (float64) are the
    bytes given: the candidates on the feature, the nearest by a search over all of them."""
    pose = Pose(np.frombuffer(position), np.frombuffer(quaternion))
    plane = primitives()[plane_file].primitives[0]
    normal = np.asarray(plane.normal, dtype=float)
    origin = np.asarray(plane.point, dtype=float)
    candidates = []
    for primitive in primitives()[body_file].primitives:
        if isinstance(primitive, prim.Segment):
            candidates.append(0.5 * (np.asarray(primitive.start) + np.asarray(primitive.end)))
        elif isinstance(primitive, prim.Cylinder):
            axis = np.asarray(primitive.axis, dtype=float)
            centre = np.asarray(primitive.axis_point) + 0.5 * primitive.length * axis
            angles = np.linspace(primitive.start_angle, primitive.end_angle, 2001)
            x_axis = np.asarray(primitive.x_axis, dtype=float)
            y_axis = np.cross(axis, x_axis)
            for angle in angles:
                candidates.append(centre + primitive.radius * (math.cos(angle) * x_axis
                                                               + math.sin(angle) * y_axis))
        elif isinstance(primitive, prim.Plane):
            for corner_u in primitive.u_range:
                for corner_v in primitive.v_range:
                    candidates.append(np.asarray(primitive.point)
                                      + corner_u * np.asarray(primitive.u_axis)
                                      + corner_v * np.asarray(primitive.v_axis))
    distances = [abs((pose.point(c) - origin) @ normal) for c in candidates]
    return tuple(float(x) for x in candidates[int(np.argmin(distances))])


def c60_outputs(poses: Mapping[str, Pose]) -> list[Output]:
    """FC-1 and the 7 measurement pairs as point distances (signed to be positive at ON)."""
    outputs: list[Output] = [ContactForce("FC1_contact_force", contact=C7, component="normal")]
    for measurement in load_model()["measurements"]:
        body = measurement["body1"]
        plane = primitives()[measurement["cad2"]].primitives[0]
        normal = np.asarray(plane.normal, dtype=float)
        axis = int(np.argmax(np.abs(normal)))
        component = "xyz"[axis]
        local = _nearest_point(measurement["cad1"], measurement["cad2"], poses[body])
        on_plane = np.zeros(3)
        on_plane[axis] = plane.point[axis]
        value = poses[body].point(local)[axis] - on_plane[axis]
        point = tuple(float(x) for x in local)
        if value >= 0.0:
            outputs.append(PointDistance(measurement["name"], body_a=FRAME,
                                         point_a=tuple(on_plane), body_b=body, point_b=point,
                                         component=component))
        else:
            outputs.append(PointDistance(measurement["name"], body_a=body, point_a=point,
                                         body_b=FRAME, point_b=tuple(on_plane),
                                         component=component))
    return outputs


# ------------------------------------------------------------------------------------------------
# The scene
# ------------------------------------------------------------------------------------------------


def c60_scene(
    name: str = "c60-on",
    *,
    clearances: Mapping[str, float] | None = None,
    plunger_speed: float = 0.0,
    plunger_start: float = 0.7,
    horizon: float = 7.0,
    time_step: float = 1e-3,
    parameters: ModelParameters | None = None,
    bar_moment_sign: float = -1.0,
    extra_shapes: Mapping[str, tuple[Shape, ...]] | None = None,
    extra_bodies: tuple[Body, ...] = (),
    extra_contacts: tuple[ContactPair, ...] = (),
    extra_drivers: tuple[Driver, ...] = (),
    extra_outputs: tuple[Output, ...] = (),
    without_contacts: tuple[str, ...] = (),
    expectations: tuple[Expectation, ...] = (),
    description: str = "",
    tags: tuple[str, ...] = ("c60",),
) -> Scene:
    """The C-60 mechanism in its ON pose (mm, g, ms; forces N).

    Parameters
    ----------
    clearances : mapping joint -> radial clearance [mm], optional
        Overrides of J1..J7 (both rings of the joint); the sheet's offsets otherwise.
    plunger_speed : float
        World x velocity of the plunger after ``plunger_start`` [mm/ms] (0: it stays).
    plunger_start : float
        Time the plunger starts [ms].
    horizon, time_step : float
        Simulated time and suggested step [ms].
    parameters : ModelParameters, optional
        The documented alternatives (contact-pressure law, handle-spring arm, friction per
        contact class, see :mod:`.variants`); the source's model by default. Recorded in the
        scene's description (so in its content hash).
    bar_moment_sign : float
        Sign of the tripping bar's settling moment about world z (-1: the source's).
    extra_shapes : mapping body -> shapes, optional
        Shapes added to the sheet's bodies (e.g. the tripping-bar pin a probe pushes).
    extra_bodies, extra_contacts, extra_drivers, extra_outputs : tuples
        Added elements (the bench experiments' probes).
    without_contacts : tuple of str
        Names of sheet contacts to leave out (e.g. C7 when a probe replaces the fixed contact).
    """
    parameters = parameters or ModelParameters()
    poses = on_poses()
    offsets = contact_offsets(clearances)
    shapes, pairs = _contact_geometry(offsets, poses, parameters)
    for body, added in (extra_shapes or {}).items():
        if body not in shapes:
            raise SceneError("extra_shapes", body, "unknown body")
        for shape in added:
            shapes[body][shape.name] = shape
    unknown = sorted(set(without_contacts) - {p.name for p in pairs})
    if unknown:
        raise SceneError("without_contacts", without_contacts, f"unknown contacts {unknown}")
    pairs = [p for p in pairs if p.name not in without_contacts]
    drivers = [Driver("plunger_motion", body=PLUNGER, component="x", quantity="velocity",
                      times=(0.0, plunger_start, plunger_start),
                      values=(0.0, 0.0, plunger_speed))]
    outputs = [o for o in c60_outputs(poses)
               if not (isinstance(o, ContactForce) and o.contact in without_contacts)]
    return Scene(
        name=name,
        description=(description or "Schneider Electric C-60 circuit breaker mechanism, ON "
                     "pose.") + f" Model: {parameters.label()}.",
        units=MM_G_MS,
        gravity=(0.0, 0.0, 0.0),
        horizon=horizon,
        time_step=time_step,
        bodies=tuple(_bodies(shapes)) + tuple(extra_bodies),
        contacts=tuple(pairs) + tuple(extra_contacts),
        loads=tuple(c60_loads(parameters, bar_moment_sign)),
        drivers=tuple(drivers) + tuple(extra_drivers),
        outputs=tuple(outputs) + tuple(extra_outputs),
        expectations=tuple(expectations) or (Expectation("no_penetration",
                                                         kind="no_penetration"),),
        tags=tags,
    )
