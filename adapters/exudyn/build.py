"""Scene -> Exudyn system (``MainSystem``), with the maps the run loop needs.

The scene is expected in the model's units (see :mod:`.engine`); clearance joints are expanded
into their shapes and pairs. Every free or driven body is one ``NodeRigidBodyEP`` (Euler
parameters) + ``ObjectRigidBody`` whose node is the scene's body frame (reference point): the
inertia is given about the centre of mass (``RigidBodyInertia(..., inertiaTensorAtCOM=True)``;
without that flag Exudyn takes it about the reference point) and Exudyn stores it about the
reference point. ``CreateRigidBody`` takes the node's (body origin's) velocity and the angular
velocity in WORLD axes: the scene's centre-of-mass velocity and body-axis angular velocity are
converted. Fixed bodies are ``ObjectGround`` s at their pose.

Elements: ideal joints as ``ObjectJointRevoluteZ`` / ``ObjectJointPrismaticX`` /
``ObjectJointSpherical`` / ``ObjectJointGeneric`` (fixed), index-3 constraints, closed loops
included; linear and torsional spring-dampers as ``ObjectConnectorSpringDamper`` /
``ObjectConnectorTorsionalSpringDamper`` (implicit, with preload); point forces and moments as
``LoadForceVector`` / ``LoadTorqueVector``, time windows as compiled symbolic load user
functions; drivers as an ``ObjectJointGeneric`` between the ground and the body's centre of
mass (world axes) constraining the driven components, with a Python offset user function giving
the prescribed displacement; contacts as the connectors planned by :mod:`.geometry`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from clearbench.adapters.exudyn.geometry import PairPlan, plan_contacts, reduced_mass
from clearbench.adapters.exudyn.laws import law_forces
from clearbench.adapters.exudyn.settings import (
    ExudynSettings,
    contact_damping,
    contact_stiffness,
    exudyn_restitution,
)
from clearbench.adapters.force_elements import ForceElements
from clearbench.kernels.jit import njit
from clearbench.kernels.quaternion import quat_to_matrix, quat_to_matrix_batch
from clearbench.kernels.time_profiles import profile_integral, profile_value
from clearbench.scenarios.bodies import Motion
from clearbench.scenarios.joints import (
    FixedJoint,
    PrismaticJoint,
    RevoluteJoint,
    SphericalJoint,
)
from clearbench.scenarios.loads import (
    AngleLawLoad,
    DistanceLawLoad,
    LinearSpringDamper,
    Moment,
    PointForce,
    TorsionalSpringDamper,
)
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.units import SI
from clearbench.scenarios.validation import VELOCITY


def load_exudyn():
    """The ``exudyn`` package with the submodules the adapter uses (``itemInterface``,
    ``rigidBodyUtilities``, ``advancedUtilities``), imported on first use."""
    # Lazy import of the engine package: the adapter (capabilities, availability) imports
    # without it.
    import exudyn
    import exudyn.advancedUtilities
    import exudyn.itemInterface
    import exudyn.rigidBodyUtilities

    return exudyn


#: Option ``rotation_coordinates`` -> Exudyn's rigid-body node type.
NODE_TYPES = {"euler_parameters": "RotationEulerParameters",
              "rotation_vector": "RotationRotationVector",
              "tait_bryan": "RotationRxyz"}

#: Components of a driver -> index in an ObjectJointGeneric (translations 0-2, rotations 3-5).
DRIVER_AXES = {"x": 0, "y": 1, "z": 2, "rx": 3, "ry": 4, "rz": 5}


@dataclass
class ConnectorRef:
    """A contact connector of the built system and the pair it belongs to."""

    pair: int            # index in scene.all_contacts
    object: int          # Exudyn object index
    data_index: int      # index of its gap in the system's data coordinates
    sign: float          # +1: Exudyn's Force output (on the sphere) acts on the pair's B


@dataclass
class BodyMap:
    """Where each scene body lives in the Exudyn system (arrays over ``scene.bodies``).

    Attributes
    ----------
    movable : (nb,) bool
    coordinate_index : (nb, 7) int or None
        ODE2 indices of each movable body's node (x, y, z, e0, e1, e2, e3); -1 for fixed.
        None for nodes of other rotation coordinates (read through :meth:`node_state`).
    reference : (nb, 7) float or None
        Reference coordinates of the nodes (the ODE2 coordinates are displacements from them).
    fixed_pose : (nb, 7) float
        Position and quaternion of fixed bodies.
    com : (nb, 3) float
        Centre of mass in the body frame [L].
    """

    movable: np.ndarray
    coordinate_index: np.ndarray
    reference: np.ndarray
    fixed_pose: np.ndarray
    com: np.ndarray
    nodes: np.ndarray | None = None  # (nb,) Exudyn node numbers, -1 for fixed bodies

    @property
    def euler_parameters(self) -> bool:
        """True when the nodes' coordinates are Euler parameters (read from the coordinate
        vectors directly)."""
        return self.coordinate_index is not None

    def node_state(self, mbs) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Origins (nb, 3), rotations (nb, 3, 3), centre-of-mass velocities (nb, 3, world) and
        body-axis angular velocities (nb, 3) of the current configuration, through Exudyn's
        node outputs (any rotation coordinates)."""
        output = load_exudyn().OutputVariableType
        nb = self.movable.shape[0]
        position = self.fixed_pose[:, :3].copy()
        rotation = quat_to_matrix_batch(self.fixed_pose[:, 3:])
        velocity = np.zeros((nb, 3))
        omega = np.zeros((nb, 3))
        for b in np.flatnonzero(self.movable):
            node = int(self.nodes[b])
            position[b] = mbs.GetNodeOutput(node, output.Position)
            rotation[b] = np.reshape(mbs.GetNodeOutput(node, output.RotationMatrix), (3, 3))
            omega[b] = mbs.GetNodeOutput(node, output.AngularVelocityLocal)
            velocity[b] = (np.asarray(mbs.GetNodeOutput(node, output.Velocity))
                           + rotation[b] @ np.cross(omega[b], self.com[b]))
        return position, rotation, velocity, omega

    def euler_parameter_state(self, q: np.ndarray, q_t: np.ndarray) -> tuple[np.ndarray, ...]:
        """Body-frame origins (nb, 3), unit quaternions (nb, 4), rotations (nb, 3, 3),
        centre-of-mass velocities (nb, 3, world) and angular velocities (nb, 3, body axes)
        from the ODE2 coordinates ``q`` and their rates ``q_t`` of Euler-parameter nodes
        (compiled: :func:`euler_parameter_state`)."""
        return euler_parameter_state(np.asarray(q, dtype=float), np.asarray(q_t, dtype=float),
                                     self.coordinate_index, self.reference, self.fixed_pose,
                                     self.movable, self.com)


@njit(cache=True)
def euler_parameter_state(q, q_t, coordinate_index, reference, fixed_pose, movable, com):
    """:meth:`BodyMap.euler_parameter_state` (its arrays as arguments). A node's Euler
    parameters p are normalised; omega_body = 2 vec(conj(p) * dp/dt); the centre of mass moves
    at the node's velocity plus R (omega x com). Called before and after every Exudyn step."""
    nb = movable.shape[0]
    position = np.empty((nb, 3))
    quaternion = np.empty((nb, 4))
    rotation = np.empty((nb, 3, 3))
    velocity = np.zeros((nb, 3))
    omega = np.zeros((nb, 3))
    for b in range(nb):
        if not movable[b]:
            position[b] = fixed_pose[b, :3]
            quaternion[b] = fixed_pose[b, 3:7] / np.sqrt(np.sum(fixed_pose[b, 3:7] ** 2))
            rotation[b] = quat_to_matrix(quaternion[b])
            continue
        index = coordinate_index[b]
        for i in range(3):
            position[b, i] = reference[b, i] + q[index[i]]
        for i in range(4):
            quaternion[b, i] = reference[b, 3 + i] + q[index[3 + i]]
        quaternion[b] /= np.sqrt(np.sum(quaternion[b] ** 2))
        rotation[b] = quat_to_matrix(quaternion[b])
        w, x, y, z = quaternion[b, 0], quaternion[b, 1], quaternion[b, 2], quaternion[b, 3]
        dw, dx, dy, dz = q_t[index[3]], q_t[index[4]], q_t[index[5]], q_t[index[6]]
        omega[b, 0] = 2.0 * (w * dx - x * dw - y * dz + z * dy)
        omega[b, 1] = 2.0 * (w * dy + x * dz - y * dw - z * dx)
        omega[b, 2] = 2.0 * (w * dz - x * dy + y * dx - z * dw)
        lever = np.cross(omega[b], com[b])
        for i in range(3):
            velocity[b, i] = q_t[index[i]] + (rotation[b, i, 0] * lever[0]
                                              + rotation[b, i, 1] * lever[1]
                                              + rotation[b, i, 2] * lever[2])
    return position, quaternion, rotation, velocity, omega


@dataclass
class BuiltSystem:
    """An assembled Exudyn system and what the run loop needs to drive and read it."""

    container: object                     # exu.SystemContainer (keeps mbs alive)
    mbs: object                           # exu.MainSystem
    bodies: BodyMap
    items: dict                           # scene body name -> Exudyn object index
    connectors: list[ConnectorRef]
    pair_plans: list[PairPlan]
    time_step: float
    law_forces: ForceElements | None = None  # the C-60 law loads (angle, distance laws)
    law_loads: list = field(default_factory=list)   # (body index, force load, torque load)
    keep_alive: list = field(default_factory=list)  # user functions Exudyn must not lose
    warnings: list[str] = field(default_factory=list)
    stiffness: dict = field(default_factory=dict)   # pair name -> connector stiffness

    @property
    def connector_count(self) -> int:
        return len(self.connectors)


def _rotation(q) -> np.ndarray:
    q = np.asarray(q, dtype=float)
    return quat_to_matrix(q / np.linalg.norm(q))


def build_system(scene: Scene, settings: ExudynSettings, time_step: float) -> BuiltSystem:
    """Build ``scene`` (model units) into an assembled Exudyn system at ``time_step`` [T]."""
    exu = load_exudyn()
    eii = exu.itemInterface
    container = exu.SystemContainer()
    mbs = container.AddSystem()
    gravity = [float(g) for g in scene.gravity]
    items: dict[str, int] = {}
    nodes: dict[str, int] = {}
    for body in scene.bodies:
        rotation = _rotation(body.orientation)
        position = [float(x) for x in body.position]
        if body.motion is Motion.FIXED:
            items[body.name] = int(mbs.AddObject(eii.ObjectGround(
                name=body.name, referencePosition=position,
                referenceRotation=rotation.tolist())))
            continue
        com = np.asarray(body.center_of_mass, dtype=float)
        omega_world = rotation @ np.asarray(body.angular_velocity, dtype=float)
        origin_velocity = (np.asarray(body.velocity, dtype=float)
                           - np.cross(omega_world, rotation @ com))
        inertia = exu.rigidBodyUtilities.RigidBodyInertia(
            body.mass, np.asarray(body.inertia, dtype=float), com, inertiaTensorAtCOM=True)
        created = mbs.CreateRigidBody(
            name=body.name, inertia=inertia, referencePosition=position,
            nodeType=getattr(exu.NodeType, NODE_TYPES[settings.rotation_coordinates]),
            referenceRotationMatrix=rotation, initialVelocity=list(origin_velocity),
            initialAngularVelocity=list(omega_world), gravity=gravity, show=False,
            returnDict=True)
        items[body.name] = int(created["bodyNumber"])
        nodes[body.name] = int(created["nodeNumber"])

    built = BuiltSystem(container, mbs, None, items, [], [], time_step)  # type: ignore[arg-type]
    _add_joints(mbs, scene, items)
    markers: dict[tuple, int] = {}
    _add_contacts(built, scene, settings, markers)
    _add_loads(built, scene, settings)
    _add_drivers(built, scene, settings)
    mbs.Assemble()
    built.bodies = _body_map(mbs, scene, nodes, settings.rotation_coordinates)
    for ref in built.connectors:  # data coordinate of each connector's gap
        ref.data_index = int(mbs.systemData.GetNodeLTGData(ref.data_index)[0])
    return built


def _body_map(mbs, scene: Scene, nodes: dict[str, int], rotation_coordinates: str) -> BodyMap:
    exu = load_exudyn()
    nb = len(scene.bodies)
    movable = np.array([b.motion is not Motion.FIXED for b in scene.bodies])
    node_numbers = np.array([nodes.get(b.name, -1) for b in scene.bodies], dtype=np.int64)
    com = np.array([b.center_of_mass for b in scene.bodies], dtype=float).reshape(nb, 3)
    fixed_pose = np.zeros((nb, 7))
    for i, body in enumerate(scene.bodies):
        q = np.asarray(body.orientation, dtype=float)
        fixed_pose[i, :3] = body.position
        fixed_pose[i, 3:] = q / np.linalg.norm(q)
    if rotation_coordinates != "euler_parameters":
        return BodyMap(movable, None, None, fixed_pose, com, node_numbers)
    index = -np.ones((nb, 7), dtype=np.int64)
    reference = np.zeros((nb, 7))
    reference_q = mbs.systemData.GetODE2Coordinates(configuration=exu.ConfigurationType.Reference)
    for i, body in enumerate(scene.bodies):
        if body.name in nodes:
            index[i] = mbs.systemData.GetNodeLTGODE2(nodes[body.name])
            reference[i] = reference_q[index[i]]
    return BodyMap(movable, index, reference, fixed_pose, com, node_numbers)


# ---------------------------------------------------------------------------- joints
def _add_joints(mbs, scene: Scene, items: dict[str, int]) -> None:
    for joint in scene.joints:
        pair = [items[joint.body_a], items[joint.body_b]]
        anchor = [float(x) for x in joint.anchor]
        if isinstance(joint, RevoluteJoint):
            mbs.CreateRevoluteJoint(name=joint.name, itemNumbers=pair, position=anchor,
                                    axis=[float(x) for x in joint.axis], useGlobalFrame=True,
                                    show=False)
        elif isinstance(joint, PrismaticJoint):
            mbs.CreatePrismaticJoint(name=joint.name, itemNumbers=pair, position=anchor,
                                     axis=[float(x) for x in joint.axis], useGlobalFrame=True,
                                     show=False)
        elif isinstance(joint, SphericalJoint):
            mbs.CreateSphericalJoint(name=joint.name, itemNumbers=pair, position=anchor,
                                     useGlobalFrame=True, show=False)
        elif isinstance(joint, FixedJoint):
            mbs.CreateGenericJoint(name=joint.name, itemNumbers=pair, position=anchor,
                                   constrainedAxes=[1, 1, 1, 1, 1, 1], useGlobalFrame=True,
                                   show=False)
        else:  # pragma: no cover - every joint kind is handled above
            raise TypeError(f"unhandled joint kind {joint.kind!r}")


# ---------------------------------------------------------------------------- contacts
def _velocity_to_model(scene: Scene, value_si: float) -> float:
    """A velocity given in m/s in the model's units."""
    return value_si * SI.factor_to(scene.units, VELOCITY)


def _marker(mbs, markers: dict, item: int, point) -> int:
    key = (item, tuple(round(float(x), 15) for x in point))
    if key not in markers:
        markers[key] = int(mbs.AddMarker(load_exudyn().itemInterface.MarkerBodyRigid(
            bodyNumber=item, localPosition=[float(x) for x in point])))
    return markers[key]


def _add_contacts(built: BuiltSystem, scene: Scene, settings: ExudynSettings,
                  markers: dict) -> None:
    exu = load_exudyn()
    eii = exu.itemInterface
    mbs, items = built.mbs, built.items
    built.pair_plans = plan_contacts(scene, settings)
    v_reg = _velocity_to_model(scene, settings.friction_regularisation_velocity)
    v_min = _velocity_to_model(scene, settings.minimum_impact_velocity)
    for index, plan in enumerate(built.pair_plans):
        contact = plan.contact
        mass = reduced_mass(scene, contact)
        step = built.time_step if settings.stiffness_time_step == "run" else scene.time_step
        k = contact_stiffness(settings, mass, step)
        d = contact_damping(settings, k, mass)
        built.stiffness[contact.name] = k
        common = dict(dynamicFriction=float(contact.friction), frictionProportionalZone=v_reg,
                      contactStiffness=k, contactDamping=d,
                      contactStiffnessExponent=settings.contact_stiffness_exponent,
                      restitutionCoefficient=exudyn_restitution(contact.restitution, settings),
                      minimumImpactVelocity=v_min, impactModel=settings.impact_model)
        for connector in plan.connectors:
            m0 = _marker(mbs, markers, items[connector.sphere_body], connector.sphere_point)
            m1 = _marker(mbs, markers, items[connector.other_body], connector.other_point)
            data = int(mbs.AddNode(eii.NodeGenericData(initialCoordinates=[0.0] * 4,
                                                       numberOfDataCoordinates=4)))
            if connector.kind == "sphere_sphere":
                obj = mbs.AddObject(eii.ObjectContactSphereSphere(
                    markerNumbers=[m0, m1], nodeNumber=data,
                    spheresRadii=[connector.sphere_radius, connector.other_radius],
                    isHollowSphere1=connector.hollow, **common))
            else:
                obj = mbs.AddObject(eii.ObjectContactSphereTriangle(
                    markerNumbers=[m0, m1], nodeNumber=data,
                    sphereRadius=connector.sphere_radius,
                    trianglePoints=exu.Vector3DList([list(p) for p in connector.triangle]),
                    includeEdges=connector.include_edges, **common))
            # data_index holds the node number until the system is assembled.
            built.connectors.append(ConnectorRef(index, int(obj), data,
                                                 1.0 if connector.sphere_is_b else -1.0))


# ---------------------------------------------------------------------------- loads
def _window_function(start: float, end: float | None, vector: list[float]):
    """A load user function returning ``vector`` for start <= t < end, else zero, written
    with exudyn.symbolic operations (recorded into a compiled symbolic user function)."""
    esym = load_exudyn().symbolic

    def function(mbs, t, load):
        on = t >= start
        if end is not None:
            on = on * (t < end)
        switch = esym.IfThenElse(on, esym.Real(1.0), esym.Real(0.0))
        return [switch * float(v) for v in vector]

    return function


def _add_loads(built: BuiltSystem, scene: Scene, settings: ExudynSettings) -> None:
    create_symbolic = load_exudyn().advancedUtilities.CreateSymbolicUserFunction
    mbs, items = built.mbs, built.items
    for load in scene.loads:
        if isinstance(load, LinearSpringDamper):
            mbs.CreateSpringDamper(name=load.name, itemNumbers=[items[load.body_a],
                                                                items[load.body_b]],
                                   localPosition0=list(load.point_a),
                                   localPosition1=list(load.point_b),
                                   referenceLength=float(load.rest_length),
                                   stiffness=float(load.stiffness), damping=float(load.damping),
                                   force=float(load.preload), show=False)
        elif isinstance(load, TorsionalSpringDamper):
            anchor = scene.body(load.body_b).position
            mbs.CreateTorsionalSpringDamper(
                name=load.name, itemNumbers=[items[load.body_a], items[load.body_b]],
                position=[float(x) for x in anchor], axis=[float(x) for x in load.axis],
                stiffness=float(load.stiffness), damping=float(load.damping),
                offset=float(load.rest_angle), torque=float(load.preload), useGlobalFrame=True,
                show=False)
        elif isinstance(load, PointForce | Moment):
            switched = load.start_time > 0 or load.end_time is not None
            body_fixed = load.frame == "body"
            if isinstance(load, PointForce):
                vector = [float(x) for x in load.force]
                index = mbs.CreateForce(name=load.name, itemNumber=items[load.body],
                                        loadVector=vector, localPosition=list(load.point),
                                        bodyFixed=body_fixed, show=False)
            else:
                vector = [float(x) for x in load.moment]
                index = mbs.CreateTorque(name=load.name, itemNumber=items[load.body],
                                         loadVector=vector, bodyFixed=body_fixed, show=False)
            if switched:
                function = create_symbolic(
                    mbs, _window_function(load.start_time, load.end_time, vector),
                    "loadVectorUserFunction", index)
                mbs.SetLoadParameter(index, "loadVectorUserFunction", function)
                built.keep_alive.append(function)
        elif isinstance(load, AngleLawLoad | DistanceLawLoad):
            continue  # all law loads together below
        else:  # pragma: no cover
            raise TypeError(f"unhandled load kind {load.kind!r}")
    found = law_forces(scene)
    if found is None:
        return
    laws, acted = found
    built.law_forces = laws
    for b in acted:
        item = items[laws.body_names[b]]
        com = list(scene.body(laws.body_names[b]).center_of_mass)
        force = mbs.CreateForce(itemNumber=item, loadVector=[0.0, 0.0, 0.0], localPosition=com,
                                show=False)
        torque = mbs.CreateTorque(itemNumber=item, loadVector=[0.0, 0.0, 0.0], show=False)
        built.law_loads.append((int(b), force, torque))


# ---------------------------------------------------------------------------- drivers
class DriverProfile:
    """Prescribed displacement of a driver's component from t = 0 (a position driver's
    profile, a velocity driver's integral from 0), through the compiled scalar kernels of
    :mod:`clearbench.kernels.time_profiles`: fast enough for Exudyn to call in every Newton
    residual (``Driver.displacement``, the array front end, cost 0.22 ms per call)."""

    def __init__(self, driver):
        self.times = np.ascontiguousarray(driver.times, dtype=np.float64)
        self.values = np.ascontiguousarray(driver.values, dtype=np.float64)
        self.integrate = driver.quantity == "velocity"

    def displacement(self, t: float) -> float:
        """Displacement of the component at ``t`` [L or rad]."""
        if self.integrate:
            return float(profile_integral(self.times, self.values, float(t)))
        return float(profile_value(self.times, self.values, float(t)))


def _add_drivers(built: BuiltSystem, scene: Scene, settings: ExudynSettings) -> None:
    """One generic joint per driven body, from a ground at its centre of mass (world axes)."""
    eii = load_exudyn().itemInterface
    mbs, items = built.mbs, built.items
    by_body: dict[str, list] = {}
    for driver in scene.drivers:
        by_body.setdefault(driver.body, []).append(driver)
    for name, drivers in by_body.items():
        body = scene.body(name)
        rotation = _rotation(body.orientation)
        com = np.asarray(body.position, dtype=float) + rotation @ np.asarray(
            body.center_of_mass, dtype=float)
        ground = int(mbs.AddObject(eii.ObjectGround(referencePosition=com.tolist())))
        constrained = [0] * 6
        for driver in drivers:
            constrained[DRIVER_AXES[driver.component]] = 1
        plan = [(DRIVER_AXES[d.component], DriverProfile(d)) for d in drivers]

        def offset(mbs, t, item, parameters, plan=plan):
            out = [0.0] * 6
            for axis, profile in plan:
                out[axis] = profile.displacement(t)
            return out

        joint = mbs.CreateGenericJoint(name=f"{name}:driver", itemNumbers=[ground, items[name]],
                                       position=com.tolist(), constrainedAxes=constrained,
                                       useGlobalFrame=True, offsetUserFunction=offset,
                                       show=False)
        built.keep_alive.append((joint, offset))
        if any(d.component.startswith("r") for d in drivers) and len(
                [d for d in drivers if d.component.startswith("r")]) > 1:
            built.warnings.append(f"driver of {name}: several rotations are prescribed as "
                                  "Tait-Bryan angles of the generic joint (exact for one)")
