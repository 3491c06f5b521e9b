"""Scene -> compiled MuJoCo model (MjSpec), with the maps the run loop needs.

The scene is expected in the model's internal units (see :mod:`.engine`). Clearance
joints are expanded into their shapes and contact pairs (Scene.expanded). Every MuJoCo body
frame is the scene's body frame; its inertial frame (centre of mass, principal axes) is set
from the scene's centre of mass and inertia tensor, and MuJoCo diagonalises it. Geoms have
contype = conaffinity = 0: only the scene's explicit pairs collide.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import mujoco
import numpy as np

from clearbench.adapters.mujoco.geometry import (
    GeomSpec,
    PairSpec,
    RingInfo,
    pair_overlaps,
    shape_geoms,
)
from clearbench.adapters.mujoco.laws import LawForces, law_forces
from clearbench.adapters.mujoco.settings import (
    ContactParameters,
    MujocoSettings,
    contact_parameters,
    time_step_warnings,
)
from clearbench.adapters.mujoco.topology import Topology, plan_topology
from clearbench.kernels.quaternion import (
    quat_conjugate,
    quat_multiply,
    quat_normalize,
    quat_to_matrix,
)
from clearbench.scenarios.bodies import Motion
from clearbench.scenarios.loads import (
    AngleLawLoad,
    DistanceLawLoad,
    LinearSpringDamper,
    Moment,
    PointForce,
    TorsionalSpringDamper,
)
from clearbench.scenarios.scales import largest_length, smallest_feature_length
from clearbench.scenarios.scene import Scene

INTEGRATORS = {"Euler": mujoco.mjtIntegrator.mjINT_EULER,
               "implicit": mujoco.mjtIntegrator.mjINT_IMPLICIT,
               "implicitfast": mujoco.mjtIntegrator.mjINT_IMPLICITFAST,
               "RK4": mujoco.mjtIntegrator.mjINT_RK4}
CONES = {"pyramidal": mujoco.mjtCone.mjCONE_PYRAMIDAL, "elliptic": mujoco.mjtCone.mjCONE_ELLIPTIC}
SOLVERS = {"PGS": mujoco.mjtSolver.mjSOL_PGS, "CG": mujoco.mjtSolver.mjSOL_CG,
           "Newton": mujoco.mjtSolver.mjSOL_NEWTON}
JOINT_TYPES = {"hinge": mujoco.mjtJoint.mjJNT_HINGE, "slide": mujoco.mjtJoint.mjJNT_SLIDE,
               "ball": mujoco.mjtJoint.mjJNT_BALL}


@dataclass
class DrivenDofState:
    """A driven degree of freedom of the compiled model."""

    qpos_address: int
    dof_address: int
    initial: float
    sign: float
    driver: object


@dataclass
class PythonLoad:
    """A load applied through ``xfrc_applied`` before every step (body ids in the model)."""

    load: object
    body_id: int
    other_id: int = -1
    # Torsional springs: axis fixed in body A (its axes) and the unwrapped angle so far.
    axis_in_a: np.ndarray | None = None
    reference_a: np.ndarray | None = None
    reference_b: np.ndarray | None = None
    angle: float = 0.0


@dataclass
class BuiltModel:
    """A compiled model and what the run loop needs to drive and read it."""

    model: mujoco.MjModel
    data: mujoco.MjData
    topology: Topology
    body_ids: np.ndarray                       # (nb,) MuJoCo body id of each scene body
    pair_lookup: dict                          # (geom1, geom2) sorted -> scene contact index
    contact_body_b: np.ndarray                 # (npair,) MuJoCo body id of each pair's B
    driven: list[DrivenDofState]
    python_loads: list[PythonLoad]
    rings: list[RingInfo]
    contact_parameters: list[ContactParameters]
    hinge_springs: list = field(default_factory=list)  # (load, qpos address, sign)
    warnings: list[str] = field(default_factory=list)
    initial_velocity_residual: float = 0.0
    law_forces: LawForces | None = None  # angle / distance law loads, applied every step
    rebuild_overlap: dict = field(default_factory=dict)  # contact name -> [L] (pair_overlaps)

    @property
    def time_step(self) -> float:
        """The model's step [T, internal units]."""
        return self.model.opt.timestep


def _relative_pose(parent_pose, child_pose) -> tuple[np.ndarray, np.ndarray]:
    """Pose of the child frame in the parent frame."""
    (xp, qp), (xc, qc) = parent_pose, child_pose
    rotation = quat_to_matrix(qp)
    return rotation.T @ (xc - xp), quat_multiply(quat_conjugate(qp), qc)


def _world_poses(scene: Scene) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    out = {}
    for body in scene.bodies:
        out[body.name] = (np.asarray(body.position, dtype=float),
                          quat_normalize(np.asarray(body.orientation, dtype=float)))
    return out


def build_model(scene: Scene, settings: MujocoSettings, time_step: float) -> BuiltModel:
    """Compile ``scene`` (internal units) into a MuJoCo model at ``time_step`` [T]."""
    expanded = scene.expanded
    topology = plan_topology(scene)
    if topology.problems:
        reasons = "; ".join(f"{feature}: {why}" for feature, why in topology.problems)
        raise ValueError(f"scene {scene.name!r} cannot be built in MuJoCo: {reasons}")
    poses = _world_poses(scene)
    length_scale = largest_length(scene)
    spec = mujoco.MjSpec()
    spec.modelname = scene.name
    spec.compiler.inertiafromgeom = mujoco.mjtInertiaFromGeom.mjINERTIAFROMGEOM_FALSE
    spec.compiler.autolimits = True
    spec.compiler.degree = False  # springref and other angles in radians
    _set_options(spec, scene, settings, time_step)

    warnings: list[str] = []
    spec_bodies = {}
    for link in topology.links:
        body = expanded.body(link.body)
        parent_spec = spec.worldbody if link.parent is None else spec_bodies[link.parent]
        parent_pose = (np.zeros(3), np.array([1.0, 0, 0, 0])) if link.parent is None \
            else poses[link.parent]
        position, orientation = _relative_pose(parent_pose, poses[link.body])
        child = parent_spec.add_body(name=link.body, pos=position, quat=orientation)
        inertia = np.asarray(body.inertia, dtype=float)
        child.mass = body.mass
        child.ipos = np.asarray(body.center_of_mass, dtype=float)
        child.fullinertia = [inertia[0, 0], inertia[1, 1], inertia[2, 2], inertia[0, 1],
                             inertia[0, 2], inertia[1, 2]]
        child.explicitinertial = True
        spec_bodies[link.body] = child
        _add_tree_joints(child, link, scene, poses)

    # geoms
    geoms_of: dict[tuple[str, str], list[GeomSpec]] = {}
    rings: list[RingInfo] = []
    for body in expanded.bodies:
        for shape in body.shapes:
            geoms, ring = shape_geoms(scene, body.name, shape, settings, length_scale)
            geoms_of[(body.name, shape.name)] = geoms
            if ring is not None:
                rings.append(ring)
            for g in geoms:
                spec_bodies[body.name].add_geom(
                    name=g.name, type=getattr(mujoco.mjtGeom, f"mjGEOM_{g.kind.upper()}"),
                    size=list(g.size), pos=list(g.position), quat=list(g.orientation),
                    contype=0, conaffinity=0)

    # pairs
    pairs: list[PairSpec] = []
    parameters: list[ContactParameters] = []
    users: dict[tuple, list[str]] = {}  # solref -> contact names, to warn once per solref
    for index, contact in enumerate(expanded.contacts):
        chosen = contact_parameters(contact.restitution, settings, time_step)
        parameters.append(chosen)
        users.setdefault(tuple(chosen.solref), []).append(contact.name)
        kind_a = expanded.body(contact.body_a).shape(contact.shape_a).kind
        kind_b = expanded.body(contact.body_b).shape(contact.shape_b).kind
        for ga in geoms_of[(contact.body_a, contact.shape_a)]:
            for gb in geoms_of[(contact.body_b, contact.shape_b)]:
                pair = PairSpec(ga.name, gb.name, index, contact.offset
                                - ga.offset_against(kind_b) - gb.offset_against(kind_a))
                pairs.append(pair)
                spec.add_pair(
                    name=f"{contact.name}|{ga.name}|{gb.name}", geomname1=ga.name,
                    geomname2=gb.name, condim=3 if contact.friction > 0 else 1,
                    friction=[contact.friction, contact.friction, 0.0, 0.0, 0.0],
                    solref=list(chosen.solref), solreffriction=list(chosen.solref),
                    solimp=list(chosen.solimp), margin=pair.margin)

    for solref, names in users.items():
        label = f"contact {names[0]!r}" if len(names) == 1 else \
            f"{len(names)} contacts ({names[0]!r}, ...)"
        warnings += time_step_warnings(label, solref, time_step, settings.refsafe)

    # loop closures
    equality_solref = (settings.equality_timeconst(time_step), settings.equality_solref[1])
    for name in topology.closures:
        joint = next(j for j in scene.joints if j.name == name)
        warnings += time_step_warnings(f"loop closure {name!r}", equality_solref, time_step,
                                       settings.refsafe)
        _add_closure(spec, scene, joint, poses, settings, equality_solref)

    # springs and loads
    python_loads, controls, hinge_springs = _add_loads(spec, scene, topology, poses,
                                                       spec_bodies, warnings, time_step)

    model = spec.compile()
    data = mujoco.MjData(model)
    body_ids = np.array([model.body(b.name).id for b in scene.bodies], dtype=np.int64)
    geom_id = {model.geom(i).name: i for i in range(model.ngeom)}
    pair_lookup = {}
    for pair in pairs:
        key = tuple(sorted((geom_id[pair.geom_a], geom_id[pair.geom_b])))
        pair_lookup[key] = pair.contact
    contact_body_b = np.array([model.body(c.body_b).id for c in expanded.contacts],
                              dtype=np.int64)
    for load in python_loads:
        load.body_id = model.body(load.load.body_a if hasattr(load.load, "body_a")
                                  else load.load.body).id
        if isinstance(load.load, TorsionalSpringDamper):
            load.other_id = model.body(load.load.body_b).id

    driven = _driven_dofs(model, scene, topology, settings)
    hinge_springs = [(load, int(model.joint(f"{body}:hinge").qposadr[0]), sign)
                     for load, body, sign in hinge_springs]
    built = BuiltModel(model, data, topology, body_ids, pair_lookup, contact_body_b, driven,
                       python_loads, rings, parameters, hinge_springs, warnings,
                       law_forces=law_forces(scene, model),
                       rebuild_overlap=pair_overlaps(scene, rings))
    if built.law_forces is not None:
        built.law_forces.wrenches(data)  # compile / load the numba function outside stepping
    # Preloads are constant motor controls: set after the reset of the initial state.
    controls = [(model.actuator(name).id, value) for name, value in controls]
    _set_initial_state(built, scene, controls)
    return built


def _set_options(spec, scene: Scene, settings: MujocoSettings, time_step: float) -> None:
    option = spec.option
    option.timestep = time_step
    option.gravity = np.asarray(scene.gravity, dtype=float)
    option.integrator = INTEGRATORS[settings.integrator]
    option.cone = CONES[settings.cone]
    option.impratio = settings.impratio
    option.solver = SOLVERS[settings.solver]
    option.iterations = settings.iterations
    option.tolerance = settings.tolerance
    option.noslip_iterations = settings.noslip_iterations
    option.noslip_tolerance = settings.noslip_tolerance
    # A blow-up must stay visible: MuJoCo would otherwise reset the state silently.
    option.disableflags = int(option.disableflags) | int(mujoco.mjtDisableBit.mjDSBL_AUTORESET)
    if not settings.refsafe:
        option.disableflags = int(option.disableflags) | int(mujoco.mjtDisableBit.mjDSBL_REFSAFE)
    if settings.ccd_tolerance_relative is not None:
        option.ccd_tolerance = settings.ccd_tolerance_relative * smallest_feature_length(scene)


def _add_tree_joints(body_spec, link, scene: Scene, poses) -> None:
    """Joints of ``link.body`` relative to its parent (or the world)."""
    position, quaternion = poses[link.body]
    rotation = quat_to_matrix(quaternion)
    if link.kind == "free":
        body_spec.add_freejoint(name=f"{link.body}:free")
        return
    if link.kind in ("translation_driven", "translation_driven_held"):
        for k, axis in enumerate("xyz"):
            body_spec.add_joint(name=f"{link.body}:slide_{axis}", type=JOINT_TYPES["slide"],
                                axis=rotation.T @ np.eye(3)[k])
        if link.kind == "translation_driven_held":
            return
        com = np.asarray(scene.body(link.body).center_of_mass, dtype=float)
        body_spec.add_joint(name=f"{link.body}:ball", type=JOINT_TYPES["ball"], pos=com)
        return
    if link.kind in ("static", "weld"):
        return
    joint = next(j for j in scene.joints if j.name == link.joint)
    anchor = rotation.T @ (np.asarray(joint.anchor, dtype=float) - position)
    axis = rotation.T @ np.asarray(getattr(joint, "axis", (0.0, 0.0, 1.0)), dtype=float)
    body_spec.add_joint(name=f"{link.body}:{link.kind}", type=JOINT_TYPES[link.kind],
                        pos=anchor, axis=axis)


def _radius_of_gyration(scene: Scene, name: str) -> float:
    body = scene.body(name)
    if body.motion is Motion.FIXED:
        return 0.0
    return math.sqrt(np.trace(np.asarray(body.inertia, dtype=float)) / body.mass)


def _add_closure(spec, scene: Scene, joint, poses, settings: MujocoSettings,
                 solref: tuple) -> None:
    """Loop-closing joint as soft equalities: connect(s) or weld."""
    position_a, quaternion_a = poses[joint.body_a]
    rotation_a = quat_to_matrix(quaternion_a)
    anchor = np.asarray(joint.anchor, dtype=float)
    common = dict(objtype=mujoco.mjtObj.mjOBJ_BODY, name1=joint.body_a, name2=joint.body_b,
                  solref=list(solref), solimp=list(settings.equality_solimp))
    if joint.kind == "fixed":
        data = np.zeros(12)
        data[10] = 1.0  # torquescale; zero relpose: MuJoCo takes the initial relative pose
        spec.add_equality(name=f"{joint.name}", type=mujoco.mjtEq.mjEQ_WELD, data=data,
                          **common)
        return
    points = [anchor]
    if joint.kind == "revolute":
        spacing = settings.closure_spacing or max(_radius_of_gyration(scene, joint.body_a),
                                                  _radius_of_gyration(scene, joint.body_b))
        axis = np.asarray(joint.axis, dtype=float)
        points = [anchor - 0.5 * spacing * axis, anchor + 0.5 * spacing * axis]
    for k, point in enumerate(points):
        data = np.zeros(12)
        data[0:3] = rotation_a.T @ (point - position_a)
        spec.add_equality(name=f"{joint.name}#{k}", type=mujoco.mjtEq.mjEQ_CONNECT, data=data,
                          **common)


def _add_loads(spec, scene: Scene, topology: Topology, poses, spec_bodies, warnings,
               time_step: float):
    """Springs as tendons / joint stiffness, preloads as motor actuators; point forces,
    moments and other torsional springs as Python loads applied every step (law loads are
    left to :func:`.laws.law_forces`)."""
    python_loads: list[PythonLoad] = []
    controls: list[tuple[str, float]] = []
    hinge_springs: list[tuple] = []
    for load in scene.loads:
        if isinstance(load, LinearSpringDamper):
            site_a = f"{load.name}:a"
            site_b = f"{load.name}:b"
            spec_bodies[load.body_a].add_site(name=site_a, pos=list(load.point_a))
            spec_bodies[load.body_b].add_site(name=site_b, pos=list(load.point_b))
            # mujoco 4 springs are polynomials (linear, quadratic, cubic coefficients).
            tendon = spec.add_tendon(name=load.name, stiffness=[load.stiffness, 0.0, 0.0],
                                     damping=[load.damping, 0.0, 0.0],
                                     springlength=[load.rest_length, load.rest_length])
            tendon.wrap_site(site_a)
            tendon.wrap_site(site_b)
            if load.preload != 0.0:
                actuator = spec.add_actuator(name=f"{load.name}:preload", target=load.name,
                                             trntype=mujoco.mjtTrn.mjTRN_TENDON)
                actuator.set_to_motor()  # force = ctrl along the tendon (gear 1)
                actuator.ctrllimited = False
                # Tension pulls the points together; a positive tendon force lengthens it.
                controls.append((actuator.name, -load.preload))
            lightest = min(scene.body(n).mass for n in (load.body_a, load.body_b)
                           if scene.body(n).motion is not Motion.FIXED)
            if load.stiffness * time_step**2 / lightest > 1.0:
                warnings.append(f"spring {load.name!r}: stiffness*dt^2/mass = "
                                f"{load.stiffness * time_step**2 / lightest:.3g} > 1 "
                                "(explicit spring)")
        elif isinstance(load, TorsionalSpringDamper):
            hinge = _matching_hinge(scene, topology, load)
            if hinge is None:
                python_loads.append(_torsional_python_load(load, poses))
                continue
            body, sign = hinge
            hinge_springs.append((load, body, sign))
            joint = next(j for j in spec_bodies[body].joints)
            joint.stiffness = [load.stiffness, 0.0, 0.0]
            joint.damping = [load.damping, 0.0, 0.0]
            joint.springref = sign * load.rest_angle
            if load.preload != 0.0:
                actuator = spec.add_actuator(name=f"{load.name}:preload", target=joint.name,
                                             trntype=mujoco.mjtTrn.mjTRN_JOINT)
                actuator.set_to_motor()
                actuator.ctrllimited = False
                controls.append((actuator.name, -sign * load.preload))
        elif isinstance(load, PointForce | Moment):
            python_loads.append(PythonLoad(load, -1))
        elif isinstance(load, AngleLawLoad | DistanceLawLoad):
            continue  # evaluated by the reference's force function (laws.py)
        else:  # pragma: no cover - every load kind is handled above
            raise TypeError(f"unhandled load kind {load.kind!r}")
    return python_loads, controls, hinge_springs


def _matching_hinge(scene: Scene, topology: Topology, load) -> tuple[str, float] | None:
    """(tree child, sign) when a tree hinge joins the spring's bodies about its axis; sign
    +1 when the child is the spring's body B (hinge angle = rotation of B relative to A)."""
    for link in topology.links:
        if link.kind != "hinge" or {link.body, link.parent} != {load.body_a, load.body_b}:
            continue
        joint = next(j for j in scene.joints if j.name == link.joint)
        alignment = float(np.dot(joint.axis, load.axis))
        if abs(abs(alignment) - 1.0) > 1e-9:
            continue
        sign = math.copysign(1.0, alignment) * (1.0 if link.body == load.body_b else -1.0)
        return link.body, sign
    return None


def _torsional_python_load(load: TorsionalSpringDamper, poses) -> PythonLoad:
    """Axis and a perpendicular reference direction fixed in each body at t = 0."""
    axis = np.asarray(load.axis, dtype=float)
    helper = np.eye(3)[int(np.argmin(np.abs(axis)))]
    reference = np.cross(axis, helper)
    reference /= np.linalg.norm(reference)
    rotation_a = quat_to_matrix(poses[load.body_a][1])
    rotation_b = quat_to_matrix(poses[load.body_b][1])
    return PythonLoad(load, -1, -1, axis_in_a=rotation_a.T @ axis,
                      reference_a=rotation_a.T @ reference, reference_b=rotation_b.T @ reference)


def _driven_dofs(model, scene: Scene, topology: Topology,
                 settings: MujocoSettings) -> list[DrivenDofState]:
    """Driven joints: armature ``driver_armature_ratio`` times their own inertia."""
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    mass_matrix = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, data, mass_matrix)
    out = []
    for body, dofs in topology.driven.items():
        for dof in dofs:
            name = f"{body}:{topology.link(body).kind}" if dof.joint == "tree" \
                else f"{body}:{dof.joint}"
            joint = model.joint(name)
            qadr, vadr = int(joint.qposadr[0]), int(joint.dofadr[0])
            model.dof_armature[vadr] = settings.driver_armature_ratio * mass_matrix[vadr, vadr]
            out.append(DrivenDofState(qadr, vadr, float(model.qpos0[qadr]), dof.sign,
                                      dof.driver))
    return out


def _set_initial_state(built: BuiltModel, scene: Scene, controls: list) -> None:
    """qvel reproducing each body's initial centre-of-mass twist (least squares over the
    joint velocities that are not driven), and the constant controls of preloads; the
    residual of the twists is kept for the metadata."""
    model, data = built.model, built.data
    mujoco.mj_resetData(model, data)
    for actuator, value in controls:
        data.ctrl[actuator] = value
    for dof in built.driven:
        data.qvel[dof.dof_address] = dof.sign * float(dof.driver.velocity(0.0))
    mujoco.mj_forward(model, data)
    free = np.ones(model.nv, dtype=bool)
    free[[dof.dof_address for dof in built.driven]] = False
    rows, targets = [], []
    jacp = np.zeros((3, model.nv))
    jacr = np.zeros((3, model.nv))
    for index, body in enumerate(scene.bodies):
        if body.motion is Motion.FIXED or model.nv == 0:
            continue
        body_id = int(built.body_ids[index])
        mujoco.mj_jacBodyCom(model, data, jacp, jacr, body_id)
        rotation = data.xmat[body_id].reshape(3, 3)
        rows += [jacp.copy(), jacr.copy()]
        targets += [np.asarray(body.velocity, dtype=float),
                    rotation @ np.asarray(body.angular_velocity, dtype=float)]
    if not rows or model.nv == 0:
        return
    jacobian = np.vstack(rows)
    target = np.concatenate(targets) - jacobian @ data.qvel
    solution = np.linalg.lstsq(jacobian[:, free], target, rcond=None)[0]
    data.qvel[free] += solution
    built.initial_velocity_residual = float(np.linalg.norm(jacobian @ data.qvel
                                                           - np.concatenate(targets)))
    mujoco.mj_forward(model, data)
