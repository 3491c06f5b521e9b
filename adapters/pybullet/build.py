"""Scene -> PyBullet world (a DIRECT client), with the maps the run loop needs.

The scene is expected in the model's internal units (SI by default, see :mod:`.engine`).

- Bodies: mass and full inertia with the principal axes as the inertial frame (eigenvectors of
  the scene's tensor) at the centre of mass; ``changeDynamics`` gets ``mass`` and
  ``localInertiaDiagonal`` in the same call (alone, the inertia makes the mass of a rigid body
  -1/0 and the first step non-finite). A rigid body's new inertia acts only after its world
  inertia is refreshed, which happens in a step: the world is built at rest without gravity or
  contacts, stepped once (the warm-up step), and only then given gravity, contact pairs,
  velocities and motors.
- Collision objects: one per group of pieces of each side of each contact pair
  (:mod:`.geometry`); every default collision is switched off (group and mask 0) and each
  pair's objects are enabled against each other with ``setCollisionFilterPair``; a multibody
  is created with self-collision on, so that the pairs between two of its links collide (a
  clearance joint inside a linkage, whose journal and bearing are links of one tree). Side A carries
  the pair's mu and e, side B 1 and 1 (PyBullet multiplies them).
- Joints and drivers (:mod:`.topology`): multibody links whose link frame sits at the joint
  anchor with the body's orientation; collision objects are extra links welded with
  JOINT_FIXED (exact in reduced coordinates), whose frame is the piece's frame when alone.
- ``contactBreakingThreshold`` is process-global and survives ``disconnect``: it is set at the
  start of every build.
"""

from __future__ import annotations

import math

import numpy as np

from clearbench.adapters.force_elements import scene_force_elements
from clearbench.adapters.primitive_pieces import pair_overlap
from clearbench.adapters.pybullet.dynamics import (
    body_dynamics,
    check_mass_properties,
    motor_off,
    object_dynamics,
)
from clearbench.adapters.pybullet.frames import (
    IDENTITY,
    compose,
    principal_frame,
    relative,
    to_pb,
    unit_quaternion,
)
from clearbench.adapters.pybullet.geometry import (
    collision_groups,
    collision_margin,
    side_geometry,
)
from clearbench.adapters.pybullet.library import pb
from clearbench.adapters.pybullet.settings import PybulletSettings
from clearbench.adapters.pybullet.shapes import create_shape, object_frame
from clearbench.adapters.pybullet.topology import LinkPlan, TreePlan, plan_topology
from clearbench.adapters.pybullet.velocities import initial_velocities
from clearbench.adapters.pybullet.world import (
    BodyHandle,
    BuiltWorld,
    CollisionObject,
    DrivenJoint,
)
from clearbench.kernels.quaternion import quat_to_matrix
from clearbench.scenarios.bodies import Motion
from clearbench.scenarios.scales import largest_length
from clearbench.scenarios.scene import Scene


# ---------------------------------------------------------------------------- build
def build_world(scene: Scene, settings: PybulletSettings, time_step: float) -> BuiltWorld:
    """Build ``scene`` (internal units) in a new DIRECT client at ``time_step`` [T]."""
    length_scale = largest_length(scene)
    expanded = scene.expanded
    sides: list[tuple] = []
    notes = {}
    objects_per_body: dict[str, int] = {}
    for index, contact in enumerate(expanded.contacts):
        pair_sides = []
        for side in ("a", "b"):
            geometry = side_geometry(scene, index, side, settings, length_scale)
            groups = collision_groups(geometry)
            pair_sides.append((geometry, groups))
            notes[(contact.name, side)] = geometry.note
            objects_per_body[geometry.body] = objects_per_body.get(geometry.body, 0) + len(groups)
        sides.append(pair_sides)
    overlap = {contact.name: pair_overlap(geometry for geometry, _ in pair_sides)
               for contact, pair_sides in zip(expanded.contacts, sides, strict=True)}
    topology = plan_topology(scene, settings.body_model, objects_per_body)
    if topology.problems:
        reasons = "; ".join(f"{feature}: {why}" for feature, why in topology.problems)
        raise ValueError(f"scene {scene.name!r} cannot be built in PyBullet: {reasons}")

    client = pb.connect(pb.DIRECT)
    try:
        built = _build(client, scene, settings, time_step, topology, sides, notes)
    except Exception:
        pb.disconnect(client)
        raise
    built.rebuild_overlap = overlap
    return built


def disconnect(built: BuiltWorld) -> None:
    """Close the world's physics client (the process-global breaking threshold stays: the
    next build sets it again)."""
    pb.disconnect(built.client)


def _engine_parameters(client: int, settings: PybulletSettings, time_step: float) -> None:
    """Every solver parameter, the process-global breaking threshold included."""
    pb.setPhysicsEngineParameter(
        fixedTimeStep=time_step, numSubSteps=0,
        numSolverIterations=settings.num_solver_iterations,
        solverResidualThreshold=settings.solver_residual_threshold,
        warmStartingFactor=settings.warm_starting_factor,
        contactERP=settings.contact_erp, erp=settings.erp, frictionERP=settings.friction_erp,
        globalCFM=settings.global_cfm, useSplitImpulse=int(settings.use_split_impulse),
        splitImpulsePenetrationThreshold=settings.split_impulse_penetration_threshold,
        contactBreakingThreshold=settings.contact_breaking_threshold,
        contactSlop=settings.contact_slop,
        restitutionVelocityThreshold=settings.restitution_velocity_threshold,
        enableConeFriction=int(settings.enable_cone_friction),
        deterministicOverlappingPairs=int(settings.deterministic_overlapping_pairs),
        reportSolverAnalytics=1, physicsClientId=client)


def _build(client, scene, settings, time_step, topology, sides, notes) -> BuiltWorld:
    _engine_parameters(client, settings, time_step)
    pb.setGravity(0.0, 0.0, 0.0, physicsClientId=client)  # gravity after the warm-up step
    expanded = scene.expanded
    maximal_statics = settings.body_model == "rigid"
    body_poses = {b.name: (np.asarray(b.position, float), unit_quaternion(b.orientation))
                  for b in expanded.bodies}
    groups_of: dict[str, list] = {b.name: [] for b in expanded.bodies}
    for index, pair_sides in enumerate(sides):
        for side, (geometry, groups) in zip("ab", pair_sides, strict=True):
            for group in groups:
                groups_of[geometry.body].append((index, side, group))

    handles: dict[str, BodyHandle] = {}
    objects: list[CollisionObject] = []

    def inertial_of(body) -> tuple[tuple, np.ndarray]:
        if body.motion is Motion.FIXED:
            return (np.zeros(3), IDENTITY.copy()), np.zeros(3)
        moments, rotation = principal_frame(body.inertia)
        return (np.asarray(body.center_of_mass, float), rotation), moments

    # Static bodies: every collision object a body of its own.
    for name in topology.static:
        body = expanded.body(name)
        handles[name] = BodyHandle(name, "static", -1, -1, (np.zeros(3), IDENTITY.copy()),
                                   0.0, np.zeros(3))
        for index, side, group in groups_of[name]:
            shape = create_shape(client, group)
            world = compose(body_poses[name], object_frame(group))
            uid = pb.createMultiBody(0.0, shape, basePosition=list(world[0]),
                                     baseOrientation=to_pb(world[1]),
                                     useMaximalCoordinates=maximal_statics,
                                     physicsClientId=client)
            objects.append(CollisionObject(index, side, name, uid, -1, group, shape))

    # Rigid bodies (maximal coordinates): one collision object at most.
    for name in topology.rigid:
        body = expanded.body(name)
        inertial, moments = inertial_of(body)
        mine = groups_of[name]
        shape, frame = -1, (np.zeros(3), IDENTITY.copy())
        if mine:
            group = mine[0][2]
            shape = create_shape(client, group)
            frame = object_frame(group)
        link_world = compose(body_poses[name], frame)
        inertial_in_link = relative(frame, inertial)
        uid = pb.createMultiBody(body.mass, shape, basePosition=list(link_world[0]),
                                 baseOrientation=to_pb(link_world[1]),
                                 baseInertialFramePosition=list(inertial_in_link[0]),
                                 baseInertialFrameOrientation=to_pb(inertial_in_link[1]),
                                 useMaximalCoordinates=True, physicsClientId=client)
        pb.changeDynamics(uid, -1, mass=body.mass, localInertiaDiagonal=list(moments),
                          physicsClientId=client)
        handles[name] = BodyHandle(name, "rigid", uid, -1, inertial, body.mass, moments)
        if mine:
            index, side, group = mine[0]
            objects.append(CollisionObject(index, side, name, uid, -1, group, shape))

    # Multibodies.
    driven: list[DrivenJoint] = []
    free_joints: list[tuple] = []
    for tree in topology.trees:
        _build_tree(client, scene, settings, tree, topology, body_poses, groups_of, handles,
                    objects, driven, free_joints, inertial_of)

    built = BuiltWorld(client, scene, settings, time_step, topology,
                       [handles[b.name] for b in scene.bodies], objects, [], driven,
                       free_joints, side_notes=notes)
    built.margin = collision_margin(scene, settings)
    check_mass_properties(built)
    object_dynamics(built)
    body_dynamics(built)
    # Again: a changeDynamics call on a link with a field whose C setter writes link index -1
    # moves every field of the call to the base (docs: traps); nothing may have landed there.
    check_mass_properties(built)
    # Warm-up step at rest: no gravity, no contact enabled, no velocity, no motor.
    for obj in objects:
        pb.setCollisionFilterGroupMask(obj.pb_body, obj.link, 0, 0, physicsClientId=client)
    for pb_body, joint, kind in free_joints:
        motor_off(client, pb_body, joint, kind)
    for item in driven:
        motor_off(client, item.pb_body, item.joint, "1dof")
    pb.stepSimulation(physicsClientId=client)
    # Now the physics.
    pb.setGravity(*[float(g) for g in scene.gravity], physicsClientId=client)
    pair_objects = [([], []) for _ in expanded.contacts]
    for obj in objects:
        pair_objects[obj.pair][0 if obj.side == "a" else 1].append(obj)
    for a_objects, b_objects in pair_objects:
        for a in a_objects:
            for b in b_objects:
                pb.setCollisionFilterPair(a.pb_body, b.pb_body, a.link, b.link, 1,
                                          physicsClientId=client)
    built.pair_objects = pair_objects
    if not settings.switch_off_joint_motors:
        for pb_body, joint, kind in free_joints:  # PyBullet's default: velocity 0, force 1
            if kind == "1dof":
                pb.setJointMotorControl2(pb_body, joint, pb.VELOCITY_CONTROL, targetVelocity=0.0,
                                         force=1.0, physicsClientId=client)
    built.closures = _closures(client, scene, settings, handles, body_poses, topology.closures)
    initial_velocities(built, body_poses)
    built.loads = scene_force_elements(scene)
    if built.loads is not None:  # compile / load the numba function outside stepping
        nb = len(scene.bodies)
        built.loads.wrenches(0.0, np.zeros((nb, 3)), np.tile(np.eye(3), (nb, 1, 1)),
                             np.zeros((nb, 3)), np.zeros((nb, 3)))
        built.loads.angle_memory[:] = np.nan
    return built


def _joint_anchor_frame(scene: Scene, link: LinkPlan, body_poses) -> tuple:
    """World pose of a link's frame: at the joint anchor (the centre of mass for translation
    links and floating bases use the body frame), with the body's orientation."""
    position, orientation = body_poses[link.body]
    body = scene.expanded.body(link.body)
    if link.kind == "base":
        return position, orientation
    if link.kind in ("translation", "translation_held"):
        com = position + quat_to_matrix(orientation) @ np.asarray(body.center_of_mass, float)
        return com, orientation
    joint = next(j for j in scene.joints if j.name == link.joint)
    return np.asarray(joint.anchor, float), orientation


def _build_tree(client, scene, settings, tree: TreePlan, topology, body_poses, groups_of,
                handles, objects, driven, free_joints, inertial_of) -> None:
    """One multibody: mass links for the scene bodies, welded links for their collision
    objects."""
    expanded = scene.expanded
    masses, shapes, positions, orientations = [], [], [], []
    inertial_positions, inertial_orientations, parents, types, axes = [], [], [], [], []
    frames: dict[int, tuple] = {0: (np.zeros(3), IDENTITY.copy())}  # pb parent index -> pose
    link_of: dict[str, int] = {}   # scene body -> pb parent index of its mass link (0: base)
    pending = []                    # (body name, link index, kind, joint, moments, inertial)
    registered_joints = []          # (creation link index, kind, link plan, slide axis)

    base_mass, base_inertial, base_frame = 0.0, (np.zeros(3), IDENTITY.copy()), frames[0]
    links = list(tree.links)
    if not tree.fixed_base:
        first = links.pop(0)
        body = expanded.body(first.body)
        inertial, moments = inertial_of(body)
        base_mass, base_inertial = body.mass, inertial
        base_frame = body_poses[first.body]
        frames[0] = base_frame
        link_of[first.body] = 0
        pending.append((first.body, -1, moments, inertial))

    def add_link(mass, shape, frame_world, parent_index, joint_type, axis_local,
                 inertial_in_link=None) -> int:
        if inertial_in_link is None:
            inertial_in_link = (np.zeros(3), IDENTITY)
        rel = relative(frames[parent_index], frame_world)
        masses.append(mass)
        shapes.append(shape)
        positions.append([float(c) for c in rel[0]])
        orientations.append(to_pb(rel[1]))
        inertial_positions.append([float(c) for c in inertial_in_link[0]])
        inertial_orientations.append(to_pb(inertial_in_link[1]))
        parents.append(parent_index)
        types.append(joint_type)
        axes.append([float(c) for c in axis_local])
        index = len(masses)  # pb parent index of this link (link index + 1)
        frames[index] = frame_world
        return index

    for link in links:
        body = expanded.body(link.body)
        inertial, moments = inertial_of(body)
        parent_index = 0 if link.parent is None else link_of[link.parent]
        frame = _joint_anchor_frame(scene, link, body_poses)
        rotation = quat_to_matrix(frame[1])
        body_frame_in_link = relative(frame, body_poses[link.body])
        inertial_in_link = compose(body_frame_in_link, inertial)
        if link.kind in ("translation", "translation_held"):
            index = parent_index
            for k, axis in enumerate(np.eye(3)):
                last = link.kind == "translation_held" and k == 2
                index = add_link(body.mass if last else 0.0, -1, frame, index,
                                 pb.JOINT_PRISMATIC, rotation.T @ axis,
                                 inertial_in_link if last else (np.zeros(3), IDENTITY))
                registered_joints.append((index - 1, "slide", link, "xyz"[k]))
            if link.kind == "translation":
                index = add_link(body.mass, -1, frame, index, pb.JOINT_SPHERICAL, [0, 0, 1],
                                 inertial_in_link)
                registered_joints.append((index - 1, "spherical", link, None))
        else:
            joint = next(j for j in scene.joints if j.name == link.joint)
            kind = {"revolute": pb.JOINT_REVOLUTE, "prismatic": pb.JOINT_PRISMATIC,
                    "spherical": pb.JOINT_SPHERICAL, "fixed": pb.JOINT_FIXED}[link.kind]
            axis = rotation.T @ np.asarray(getattr(joint, "axis", (0.0, 0.0, 1.0)), float)
            index = add_link(body.mass, -1, frame, parent_index, kind, axis, inertial_in_link)
            if link.kind != "fixed":
                registered_joints.append((index - 1, link.kind, link, None))
        link_of[link.body] = index
        pending.append((link.body, index - 1, moments, inertial))

    # Collision objects welded to their body's mass link.
    collision_links = []
    for name, mass_index in link_of.items():
        for pair, side, group in groups_of[name]:
            shape = create_shape(client, group)
            world = compose(body_poses[name], object_frame(group))
            index = add_link(0.0, shape, world, mass_index, pb.JOINT_FIXED, [0, 0, 1])
            collision_links.append((pair, side, name, index - 1, group, shape))

    base_inertial_in_link = base_inertial  # the base's link frame is the body frame
    uid = pb.createMultiBody(
        base_mass, -1, basePosition=list(base_frame[0]), baseOrientation=to_pb(base_frame[1]),
        baseInertialFramePosition=list(base_inertial_in_link[0]),
        baseInertialFrameOrientation=to_pb(base_inertial_in_link[1]),
        linkMasses=masses, linkCollisionShapeIndices=shapes,
        linkVisualShapeIndices=[-1] * len(masses), linkPositions=positions,
        linkOrientations=orientations, linkInertialFramePositions=inertial_positions,
        linkInertialFrameOrientations=inertial_orientations, linkParentIndices=parents,
        linkJointTypes=types, linkJointAxis=axes, useMaximalCoordinates=False,
        # Links of one multibody never collide without it, whatever setCollisionFilterPair
        # enables (btMultiBodyLinkCollider::checkCollideWithOverride): the journal and the
        # bearing of a clearance joint between two links of one tree carried 0 N and the
        # journal left its bore. Only the pairs enabled below collide (every mask is 0).
        flags=pb.URDF_USE_SELF_COLLISION, physicsClientId=client)
    # PyBullet renumbers the links depth-first: every index planned above is a creation index.
    index_of = _link_indices(client, uid)
    pending = [(name, index_of[k], moments, inertial) for name, k, moments, inertial in pending]
    collision_links = [(pair, side, name, index_of[k], group, shape)
                       for pair, side, name, k, group, shape in collision_links]
    registered_joints = [(index_of[k], kind, link, axis)
                         for k, kind, link, axis in registered_joints]
    for name, link_index, moments, inertial in pending:
        body = expanded.body(name)
        pb.changeDynamics(uid, link_index, mass=body.mass, localInertiaDiagonal=list(moments),
                          physicsClientId=client)
        handles[name] = BodyHandle(name, "base" if link_index < 0 else "link", uid, link_index,
                                   inertial, body.mass, moments)
    for pair, side, name, link_index, group, shape in collision_links:
        objects.append(CollisionObject(pair, side, name, uid, link_index, group, shape))
    # Joints: driven ones get a motor, the others are switched off.
    gravity = float(np.linalg.norm(scene.gravity))
    for joint_index, kind, link, axis_name in registered_joints:
        dofs = topology.driven.get(link.body, ())
        dof = None
        for candidate in dofs:
            if (kind in ("revolute", "prismatic") and candidate.joint == "tree") or (
                    kind == "slide" and candidate.joint == f"slide_{axis_name}"):
                dof = candidate
        if dof is None:
            free_joints.append((uid, joint_index, "spherical" if kind == "spherical"
                                else "1dof"))
            continue
        body = expanded.body(link.body)
        size = max(largest_length(scene), 1e-300)
        weight = body.mass * (gravity if gravity > 0 else 1.0)
        scale = weight * (size if dof.driver.is_rotation else 1.0)
        driven.append(DrivenJoint(uid, joint_index, dof.sign, dof.driver,
                                  settings.driver_max_force * scale))


def _link_indices(client: int, uid: int) -> dict[int, int]:
    """Creation index (0-based position in ``createMultiBody``'s link lists; -1 the base) ->
    PyBullet's link index.

    ``createMultiBody`` renumbers the links depth-first (a branched tree listed breadth-first
    comes back in another order) and names link k of the creation lists ``link{k + 1}``
    (``getJointInfo`` field 12), which gives the map back.
    """
    index_of = {-1: -1}
    for index in range(pb.getNumJoints(uid, physicsClientId=client)):
        name = pb.getJointInfo(uid, index, physicsClientId=client)[12].decode()
        if not name.startswith("link") or not name[4:].isdigit():
            raise RuntimeError(f"PyBullet link {index} has an unexpected name {name!r}: cannot "
                               "map it back to the link it was created as")
        index_of[int(name[4:]) - 1] = index
    return index_of


def _com_frame(handle: BodyHandle, body_pose: tuple) -> tuple:
    """World pose of a body's inertial frame."""
    return compose(body_pose, handle.inertial)


def _closures(client, scene: Scene, settings, handles, body_poses, names) -> list[int]:
    """Loop-closing joints as constraints; PyBullet takes the frames in each body's inertial
    (centre-of-mass) frame, the world's in world coordinates. Their limit is raised from
    PyBullet's 500 to 1e30 (it acts on multibody constraints only)."""
    out = []
    for joint in [j for j in scene.joints if j.name in set(names)]:
        a, b = handles[joint.body_a], handles[joint.body_b]
        if a.kind == "static":  # the world can only be the child
            a, b = b, a
        frame_a = _com_frame(a, body_poses[a.name])
        parent_body, parent_link = a.pb_body, a.link
        if b.kind == "static":
            if a.kind == "rigid":
                child_body = pb.createMultiBody(0.0, -1, useMaximalCoordinates=True,
                                                physicsClientId=client)
            else:
                child_body = -1
            child_link, frame_b = -1, (np.zeros(3), IDENTITY.copy())
        else:
            child_body, child_link = b.pb_body, b.link
            frame_b = _com_frame(b, body_poses[b.name])
        anchor = np.asarray(joint.anchor, float)
        axis = np.asarray(getattr(joint, "axis", (0.0, 0.0, 1.0)), float)
        points = [anchor]
        kind = pb.JOINT_POINT2POINT
        if joint.kind == "revolute":
            spacing = settings.closure_spacing or max(
                _gyration(scene, joint.body_a), _gyration(scene, joint.body_b))
            points = [anchor - 0.5 * spacing * axis, anchor + 0.5 * spacing * axis]
        elif joint.kind in ("fixed", "prismatic"):
            kind = pb.JOINT_FIXED if joint.kind == "fixed" else pb.JOINT_PRISMATIC
        for point in points:
            in_a = relative(frame_a, (point, IDENTITY))
            in_b = relative(frame_b, (point, IDENTITY))
            axis_a = quat_to_matrix(frame_a[1]).T @ axis
            uid = pb.createConstraint(
                parent_body, parent_link, child_body, child_link, kind,
                [float(c) for c in axis_a], [float(c) for c in in_a[0]],
                [float(c) for c in in_b[0]], parentFrameOrientation=to_pb(in_a[1]),
                childFrameOrientation=to_pb(in_b[1]), physicsClientId=client)
            pb.changeConstraint(uid, maxForce=1e30, physicsClientId=client)
            out.append(uid)
    return out


def _gyration(scene: Scene, name: str) -> float:
    body = scene.body(name)
    if body.motion is Motion.FIXED:
        return 0.0
    return math.sqrt(np.trace(np.asarray(body.inertia, dtype=float)) / body.mass)


