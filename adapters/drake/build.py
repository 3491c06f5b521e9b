"""A scene (in SI) rebuilt as a discrete Drake ``MultibodyPlant`` in a diagram with its
``SceneGraph``, the way a Drake user writes it.

- ``AddMultibodyPlant(MultibodyPlantConfig(time_step=dt, ...))``: the discrete plant, with the
  settings' contact approximation, contact model, penetration allowance and stiction tolerance.
- Bodies: ``AddRigidBody`` with ``SpatialInertia.MakeFromCentralInertia`` (mass, centre of mass
  in the body frame, the scene's central inertia tensor in body axes); fixed bodies are the
  world (their shapes are registered on the world body).
- Joints (:mod:`.topology`): tree joints between ``FixedOffsetFrame`` s placed at the joint's
  world frame at t = 0 (coordinates 0 at the scene's pose); closures as SAP constraints.
- Collision geometry: each side of each scene pair gets its own pieces
  (:func:`~clearbench.adapters.primitive_pieces.side_geometry`: spheres, boxes, capsules,
  cylinders, half-spaces; rings and bores of spheres and capsules) with the pair's material
  (:func:`side_material`), and collisions are filtered to exactly the scene's pairs: every
  geometry excluded from every other, then each pair's two sides allowed.
- Drivers: a driven joint gets a ``JointActuator`` with a reflected inertia
  ``driver_armature_ratio`` times the body's inertia about (mass along) the joint axis; the run
  resets the coordinate to its profile at each step start.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from pydrake.common.eigen_geometry import Quaternion
from pydrake.geometry import (
    AddCompliantHydroelasticProperties,
    AddContactMaterial,
    AddRigidHydroelasticProperties,
    Box,
    Capsule,
    CollisionFilterDeclaration,
    Cylinder,
    GeometrySet,
    HalfSpace,
    ProximityProperties,
    Sphere,
)
from pydrake.math import RigidTransform
from pydrake.multibody.math import SpatialVelocity
from pydrake.multibody.plant import (
    AddMultibodyPlant,
    CoulombFriction,
    MultibodyPlantConfig,
)
from pydrake.multibody.tree import (
    BallRpyJoint,
    FixedOffsetFrame,
    PrismaticJoint,
    RevoluteJoint,
    RotationalInertia,
    SpatialInertia,
    WeldJoint,
)
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder

from clearbench.adapters.drake.settings import DrakeSettings
from clearbench.adapters.drake.topology import Topology, plan_topology
from clearbench.adapters.force_elements import ForceElements, scene_force_elements
from clearbench.adapters.primitive_pieces import Piece, pair_overlap, side_geometry
from clearbench.kernels.quaternion import quat_normalize, quat_to_matrix
from clearbench.scenarios.bodies import Motion
from clearbench.scenarios.scales import largest_length
from clearbench.scenarios.scene import Scene

__all__ = ["BuiltPlant", "build_plant", "pair_materials", "side_material"]


@dataclass(frozen=True)
class PairMaterial:
    """Contact parameters of one scene pair (None: Drake's estimate)."""

    friction: float
    stiffness: float | None
    hunt_crossley: float | None
    relaxation_time: float | None
    note: str = ""


@dataclass
class BuiltPlant:
    """A Drake model of a scene and the handles the run needs."""

    scene: Scene
    settings: DrakeSettings
    time_step: float
    diagram: object
    plant: object
    simulator: object
    context: object
    plant_context: object
    bodies: dict
    topology: Topology
    geometry_pair: dict
    loads: ForceElements | None
    driven: list
    materials: list
    notes: dict = field(default_factory=dict)
    rebuild_overlap: dict = field(default_factory=dict)  # contact name -> [L] (pair_overlap)


def _unit(q) -> np.ndarray:
    return quat_normalize(np.asarray(q, dtype=float))


def _transform(position, quaternion) -> RigidTransform:
    q = _unit(quaternion)
    return RigidTransform(Quaternion(q[0], q[1], q[2], q[3]), np.asarray(position, float))


def body_transform(scene: Scene, name: str) -> RigidTransform:
    """X_WB of scene body ``name`` at t = 0."""
    body = scene.expanded.body(name)
    return _transform(body.position, body.orientation)


def _lightest_mass(scene: Scene, contact) -> float:
    masses = [scene.body(name).mass for name in (contact.body_a, contact.body_b)
              if scene.body(name).motion is not Motion.FIXED]
    return min(masses) if masses else 1.0


def _damping_ratio(restitution: float) -> float:
    """Damping ratio of a linear spring-damper whose free oscillation loses the energy of a
    Newton impact with ``restitution`` over a half period (the textbook relation
    zeta = -ln e / sqrt(pi^2 + ln^2 e); a contact that can only push leaves earlier, so the
    rebound is a little higher than e: measured in docs/engines/drake.md)."""
    if restitution <= 0.0:
        return math.inf
    log_e = math.log(restitution)
    return -log_e / math.sqrt(math.pi**2 + log_e**2)


def pair_materials(scene: Scene, settings: DrakeSettings, dt: float) -> list[PairMaterial]:
    """Contact parameters of every pair of ``scene.all_contacts`` (SI)."""
    out = []
    for contact in scene.all_contacts:
        stiffness = settings.point_stiffness
        omega = None
        if settings.stiffness_steps is not None:
            omega = math.pi / (settings.stiffness_steps * dt)
            stiffness = _lightest_mass(scene, contact) * omega**2
        relaxation = settings.relaxation_time
        if relaxation is None and settings.relaxation_steps is not None:
            relaxation = settings.relaxation_steps * dt
        note = ""
        if (contact.restitution > 0 and settings.uses_sap_dissipation and omega is not None):
            # SAP's linear model: f = k (x + tau v), i.e. c / k = tau = 2 zeta / omega.
            relaxation = 2.0 * _damping_ratio(contact.restitution) / omega
            note = (f"e = {contact.restitution:g} as SAP relaxation time {relaxation:.3g} s "
                    "(damping ratio of e)")
        out.append(PairMaterial(contact.friction, stiffness, settings.hunt_crossley_dissipation,
                                relaxation, note))
    return out


def hydroelastic_pair(geometries, material: PairMaterial, settings: DrakeSettings) -> bool:
    """True when a pair is built hydroelastic: ``hydroelastic_boxes`` on, a stiffness to derive
    the modulus from, and both sides boxes or planes (at least one box)."""
    kinds = {piece.kind for geometry in geometries for piece in geometry.pieces}
    return (settings.hydroelastic_boxes and material.stiffness is not None
            and kinds <= {"box", "plane"} and "box" in kinds)


def hydroelastic_modulus(stiffness: float, half_extents) -> float:
    """Modulus [F/L^2] giving a box pressed on a face about ``stiffness`` [F/L]: Drake's
    compliant box has its pressure field over the smallest half extent h, so a face of area A
    pressed by x carries about E A x / h."""
    half = sorted(float(h) for h in half_extents)
    return stiffness * half[0] / (4.0 * half[1] * half[2])


def side_material(material: PairMaterial, piece=None, hydroelastic: bool = False,
                  compliant_sides: int = 1) -> ProximityProperties:
    """Proximity properties of one side's geometry, so that Drake's combination of two equal
    sides gives the pair's values: stiffness 2k (series), SAP time constant tau / 2 (sum),
    Hunt–Crossley d (stiffness-weighted mean), friction mu (2 mu^2 / 2 mu). A hydroelastic
    pair's boxes are compliant (modulus :func:`hydroelastic_modulus` of the pair stiffness,
    times ``compliant_sides``: Drake combines two compliant moduli in series), planes rigid."""
    properties = ProximityProperties()
    if hydroelastic and piece is not None:
        if piece.kind == "box":
            AddCompliantHydroelasticProperties(
                min(piece.size),
                compliant_sides * hydroelastic_modulus(material.stiffness, piece.size),
                properties)
        else:
            AddRigidHydroelasticProperties(properties)
    AddContactMaterial(
        dissipation=material.hunt_crossley,
        point_stiffness=None if material.stiffness is None else 2.0 * material.stiffness,
        friction=CoulombFriction(material.friction, material.friction),
        properties=properties)
    if material.relaxation_time is not None:
        properties.AddProperty("material", "relaxation_time", 0.5 * material.relaxation_time)
    return properties


#: Half-spaces a plant holds safely: pydrake 1.51.1 segfaults registering the 15th HalfSpace
#: on the world body (tests/test_drake_engine.py); beyond this count planes become boxes.
MAX_HALF_SPACES = 8


def plane_as_box(piece, half_size: float):
    """A box of half size ``half_size`` [L] whose +z face is the plane ``piece``."""
    rotation = quat_to_matrix(_unit(piece.orientation))
    centre = np.asarray(piece.position, float) - half_size * rotation[:, 2]
    return Piece("box", (half_size,) * 3, tuple(centre), piece.orientation)


def _drake_shape(piece):
    if piece.kind == "sphere":
        return Sphere(piece.size[0])
    if piece.kind == "box":
        return Box(*(2.0 * np.asarray(piece.size)))
    if piece.kind == "capsule":
        return Capsule(piece.size[0], 2.0 * piece.size[1])
    if piece.kind == "cylinder":
        return Cylinder(piece.size[0], 2.0 * piece.size[1])
    if piece.kind == "plane":
        return HalfSpace()
    raise ValueError(f"no Drake shape for piece kind {piece.kind!r}")  # pragma: no cover


def _joint_frames(plant, bodies, scene, edge):
    """Frames on the parent (world when None) and the child at the joint's world frame."""
    joint = edge.joint
    x_wj = RigidTransform(np.asarray(joint.anchor, float))
    frames = []
    for name in (edge.parent, edge.child):
        if name is None:
            frames.append(plant.AddFrame(FixedOffsetFrame(f"{joint.name}@world",
                                                          plant.world_frame(), x_wj)))
            continue
        x_bj = body_transform(scene, name).inverse() @ x_wj
        frames.append(plant.AddFrame(FixedOffsetFrame(f"{joint.name}@{name}",
                                                      bodies[name].body_frame(), x_bj)))
    return frames


def _add_tree_joint(plant, bodies, scene, edge, scene_parent_sign: float):
    joint = edge.joint
    parent_frame, child_frame = _joint_frames(plant, bodies, scene, edge)
    # The scene states the joint as body_a -> body_b; the child's coordinate is measured
    # from the parent, so the axis flips when the child is the scene's body_a.
    if joint.kind == "revolute":
        axis = scene_parent_sign * np.asarray(joint.axis, float)
        return plant.AddJoint(RevoluteJoint(joint.name, parent_frame, child_frame, axis, 0.0))
    if joint.kind == "prismatic":
        axis = scene_parent_sign * np.asarray(joint.axis, float)
        return plant.AddJoint(PrismaticJoint(joint.name, parent_frame, child_frame, axis,
                                             -math.inf, math.inf, 0.0))
    if joint.kind == "spherical":
        return plant.AddJoint(BallRpyJoint(joint.name, parent_frame, child_frame, 0.0))
    return plant.AddJoint(WeldJoint(joint.name, parent_frame, child_frame, RigidTransform()))


def _add_slides(plant, bodies, scene, name: str, held: bool) -> dict:
    """Slides x, y, z from the world to the body's centre of mass (massless intermediate
    bodies), then a ball joint (a weld when ``held``): joints by name ``BODY/slide_x`` ..."""
    body = scene.body(name)
    x_wb = body_transform(scene, name)
    com = x_wb @ np.asarray(body.center_of_mass, float)
    parent = plant.AddFrame(FixedOffsetFrame(f"{name}/slides@world", plant.world_frame(),
                                             RigidTransform(com)))
    joints = {}
    for k, axis in enumerate("xyz"):
        last = axis == "z" and held
        child_body = bodies[name] if last else plant.AddRigidBody(
            f"{name}/carriage_{axis}", SpatialInertia.Zero())
        child = (plant.AddFrame(FixedOffsetFrame(f"{name}/slides@body", bodies[name].body_frame(),
                                                 x_wb.inverse() @ RigidTransform(com)))
                 if last else child_body.body_frame())
        joint = plant.AddJoint(PrismaticJoint(f"{name}/slide_{axis}", parent, child,
                                              np.eye(3)[k], -math.inf, math.inf, 0.0))
        joints[joint.name()] = joint
        parent = child
    if not held:
        child = plant.AddFrame(FixedOffsetFrame(f"{name}/ball@body", bodies[name].body_frame(),
                                                x_wb.inverse() @ RigidTransform(com)))
        plant.AddJoint(BallRpyJoint(f"{name}/ball", parent, child, 0.0))
    return joints


def _add_closure(plant, bodies, scene, joint, spacing: float) -> None:
    """A loop-closing joint as SAP constraints between its two bodies (world for fixed)."""
    anchor = np.asarray(joint.anchor, float)

    def body_and_point(name, point):
        body = bodies.get(name)
        if body is None:
            return plant.world_body(), point
        return body, body_transform(scene, name).inverse() @ point

    if joint.kind == "fixed":
        a, _ = body_and_point(joint.body_a, anchor)
        b, _ = body_and_point(joint.body_b, anchor)
        x_wj = RigidTransform(anchor)
        x_aj = x_wj if a.index() == plant.world_body().index() else \
            body_transform(scene, joint.body_a).inverse() @ x_wj
        x_bj = x_wj if b.index() == plant.world_body().index() else \
            body_transform(scene, joint.body_b).inverse() @ x_wj
        plant.AddWeldConstraint(a, x_aj, b, x_bj)
        return
    points = [anchor]
    if joint.kind == "revolute":
        axis = np.asarray(joint.axis, float)
        points = [anchor - 0.5 * spacing * axis, anchor + 0.5 * spacing * axis]
    for point in points:
        a, p_a = body_and_point(joint.body_a, point)
        b, p_b = body_and_point(joint.body_b, point)
        plant.AddBallConstraint(a, p_a, b, p_b)


def _axis_inertia(scene: Scene, name: str, joint) -> float:
    body = scene.body(name)
    if joint.kind == "prismatic":
        return body.mass
    rotation = quat_to_matrix(_unit(body.orientation))
    axis_body = rotation.T @ np.asarray(joint.axis, float)
    return float(axis_body @ np.asarray(body.inertia, float) @ axis_body)


def build_plant(scene: Scene, settings: DrakeSettings, dt: float) -> BuiltPlant:
    """The Drake model of ``scene`` (SI) stepped at ``dt`` [s]."""
    topology = plan_topology(scene, settings.discrete_contact_approximation)
    config = MultibodyPlantConfig(
        time_step=dt,
        discrete_contact_approximation=settings.discrete_contact_approximation,
        contact_model=settings.contact_model,
        penetration_allowance=settings.penetration_allowance,
        stiction_tolerance=settings.stiction_tolerance,
        sap_near_rigid_threshold=settings.sap_near_rigid_threshold,
        adjacent_bodies_collision_filters=settings.adjacent_bodies_collision_filters)
    builder = DiagramBuilder()
    plant, _ = AddMultibodyPlant(config, builder)
    plant.mutable_gravity_field().set_gravity_vector(np.asarray(scene.gravity, float))

    bodies = {}
    for body in scene.bodies:
        if body.motion is Motion.FIXED:
            continue
        inertia = np.asarray(body.inertia, float)
        rotational = RotationalInertia(inertia[0, 0], inertia[1, 1], inertia[2, 2],
                                       inertia[0, 1], inertia[0, 2], inertia[1, 2])
        bodies[body.name] = plant.AddRigidBody(
            body.name, SpatialInertia.MakeFromCentralInertia(
                body.mass, np.asarray(body.center_of_mass, float), rotational))

    joints = {}
    for edge in topology.edges:
        sign = 1.0 if edge.child == edge.joint.body_b else -1.0
        joints[edge.joint.name] = _add_tree_joint(plant, bodies, scene, edge, sign)

    for body_name, held in topology.slides.items():
        joints.update(_add_slides(plant, bodies, scene, body_name, held))

    driven = []
    for body_name, dofs in topology.driven.items():
        for dof in dofs:
            if dof.joint == "tree":
                edge = next(e for e in topology.edges if e.child == body_name)
                joint = joints[edge.joint.name]
                inertia = _axis_inertia(scene, body_name, edge.joint)
            else:
                joint = joints[f"{body_name}/{dof.joint}"]
                inertia = scene.body(body_name).mass
            actuator = plant.AddJointActuator(f"{joint.name()}_driver", joint)
            actuator.set_default_gear_ratio(1.0)
            actuator.set_default_rotor_inertia(settings.driver_armature_ratio * inertia)
            driven.append((joint, dof))

    materials = pair_materials(scene, settings, dt)
    length_scale = largest_length(scene)
    geometry_pair: dict = {}
    sides_of_pair = []
    notes = {}
    pair_geometries = [[side_geometry(scene, index, side, settings, length_scale)
                        for side in ("a", "b")] for index in range(len(scene.all_contacts))]
    planes = sum(piece.kind == "plane" for pair in pair_geometries for geometry in pair
                 for piece in geometry.pieces)
    for index, contact in enumerate(scene.all_contacts):
        sides = []
        geometries = pair_geometries[index]
        hydroelastic = hydroelastic_pair(geometries, materials[index], settings)
        compliant_sides = sum(all(p.kind == "box" for p in g.pieces) for g in geometries)
        for side, geometry in zip(("a", "b"), geometries, strict=True):
            notes[(contact.name, side)] = geometry.note + (" (hydroelastic)" if hydroelastic
                                                           else "")
            body_name = geometry.body
            fixed = body_name not in bodies
            frame_body = plant.world_body() if fixed else bodies[body_name]
            x_pre = body_transform(scene, body_name) if fixed else RigidTransform()
            ids = []
            for k, piece in enumerate(geometry.pieces):
                # The material follows the scene's piece (a plane stays rigid as a box).
                shape_piece = piece
                if piece.kind == "plane" and planes > MAX_HALF_SPACES:
                    shape_piece = plane_as_box(piece, settings.plane_box_size * length_scale)
                x_bp = _transform(shape_piece.position, shape_piece.orientation)
                ids.append(plant.RegisterCollisionGeometry(
                    frame_body, x_pre @ x_bp, _drake_shape(shape_piece),
                    f"{contact.name}/{side}/{k}",
                    side_material(materials[index], piece, hydroelastic, compliant_sides)))
            for gid in ids:
                geometry_pair[gid] = (index, side)
            sides.append(ids)
        sides_of_pair.append(sides)

    spacing = 0.1 * length_scale
    for joint in topology.closures:
        _add_closure(plant, bodies, scene, joint, spacing)
    plant.Finalize()

    if geometry_pair:
        _filter_to_pairs(plant, builder, sides_of_pair, list(geometry_pair))
    diagram = builder.Build()
    simulator = Simulator(diagram)
    context = simulator.get_mutable_context()
    plant_context = plant.GetMyMutableContextFromRoot(context)
    _set_initial_state(scene, plant, plant_context, bodies, topology, joints)
    loads = scene_force_elements(scene)
    return BuiltPlant(scene, settings, dt, diagram, plant, simulator, context, plant_context,
                      bodies, topology, geometry_pair, loads, driven, materials, notes,
                      {contact.name: pair_overlap(geometries) for contact, geometries
                       in zip(scene.all_contacts, pair_geometries, strict=True)})


def _filter_to_pairs(plant, builder, sides_of_pair, all_ids) -> None:
    """Only the scene's pairs collide: every geometry excluded from every other, then each
    pair's two sides allowed (also between bodies joined by a joint, which Drake would
    otherwise filter when ``adjacent_bodies_collision_filters`` is on)."""
    scene_graph = builder.GetSubsystemByName("scene_graph")
    manager = scene_graph.collision_filter_manager()
    declaration = CollisionFilterDeclaration().ExcludeWithin(GeometrySet(all_ids))
    for side_a, side_b in sides_of_pair:
        declaration.AllowBetween(GeometrySet(side_a), GeometrySet(side_b))
    manager.Apply(declaration)


def _set_initial_state(scene, plant, context, bodies, topology, joints) -> None:
    """Free bodies at their poses and twists; tree coordinates 0 (the frames are the scene's
    initial pose) with rates from the bodies' initial relative velocities."""
    for name in topology.free:
        if name not in bodies:
            continue
        plant.SetFreeBodyPose(context, bodies[name], body_transform(scene, name))
        plant.SetFreeBodySpatialVelocity(context, bodies[name], _spatial_velocity(scene, name))
    for edge in topology.edges:
        joint = edge.joint
        if joint.kind not in ("revolute", "prismatic"):
            continue
        child = _world_twist(scene, edge.child)
        parent = _world_twist(scene, edge.parent) if edge.parent else (np.zeros(3), np.zeros(3),
                                                                      np.zeros(3))
        axis = np.asarray(joint.axis, float) * (1.0 if edge.child == joint.body_b else -1.0)
        anchor = np.asarray(joint.anchor, float)
        if joint.kind == "revolute":
            rate = float((child[1] - parent[1]) @ axis)
            joints[joint.name].set_angular_rate(context, rate)
        else:
            v_child = child[0] + np.cross(child[1], anchor - child[2])
            v_parent = parent[0] + np.cross(parent[1], anchor - parent[2])
            joints[joint.name].set_translation_rate(context, float((v_child - v_parent) @ axis))


def _world_twist(scene: Scene, name: str):
    """(centre-of-mass velocity, angular velocity, centre of mass), world, at t = 0."""
    body = scene.body(name)
    rotation = quat_to_matrix(_unit(body.orientation))
    com = np.asarray(body.position, float) + rotation @ np.asarray(body.center_of_mass, float)
    return (np.asarray(body.velocity, float),
            rotation @ np.asarray(body.angular_velocity, float), com)


def _spatial_velocity(scene: Scene, name: str) -> SpatialVelocity:
    velocity, omega, com = _world_twist(scene, name)
    origin = np.asarray(scene.body(name).position, float)
    return SpatialVelocity(omega, velocity + np.cross(omega, origin - com))
