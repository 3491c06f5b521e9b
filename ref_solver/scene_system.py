"""Scene -> :class:`~clearbench.ref_solver.system.MultibodySystem` and initial
:class:`~clearbench.ref_solver.system.State`: the array form the solver steps.

Clearance joints are expanded into their shapes and contact pairs (Scene.expanded); bodies are
described at their centre of mass with the scene's body axes; everything stays in the scene's
units. The reference engine builds its runs with it, and the MuJoCo and Exudyn adapters pack
their law loads with it (one evaluation of the laws, :mod:`clearbench.ref_solver.forces`;
:func:`law_load_problems` says which law loads the packing cannot take).
"""

from __future__ import annotations

import numpy as np

from clearbench.kernels.poses import centre_of_mass_frames
from clearbench.kernels.quaternion import (
    quat_conjugate,
    quat_multiply,
    quat_normalize,
    quat_to_matrix,
)
from clearbench.ref_solver.system import (
    FORCE_ANGLE_LAW,
    FORCE_DISTANCE_LAW,
    FORCE_LINEAR_SPRING,
    FORCE_MOMENT,
    FORCE_POINT_FORCE,
    FORCE_TORSIONAL_SPRING,
    JOINT_CODES,
    MultibodySystem,
    State,
)
from clearbench.scenarios.bodies import Motion
from clearbench.scenarios.drivers import COMPONENTS
from clearbench.scenarios.geometry import contact_frame, pack_shape_parameters, shape_code
from clearbench.scenarios.loads import (
    AngleLawLoad,
    DistanceLawLoad,
    LinearSpringDamper,
    LoadApplication,
    Moment,
    PointForce,
    TorsionalSpringDamper,
)
from clearbench.scenarios.scene import Scene

NEVER = 1e300  # end time of loads that are never switched off


def _unit(quaternion) -> np.ndarray:
    return quat_normalize(np.asarray(quaternion, dtype=float))


def body_frames(scene: Scene) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Centre-of-mass positions (nb, 3) [L], unit quaternions (nb, 4) and rotations
    (nb, 3, 3) of the scene's bodies at t = 0."""
    return centre_of_mass_frames([b.position for b in scene.bodies],
                                 [b.orientation for b in scene.bodies],
                                 [b.center_of_mass for b in scene.bodies])


def initial_state(scene: Scene) -> State:
    """State at t = 0: centres of mass, orientations, twists (fixed bodies at rest)."""
    x, p, _ = body_frames(scene)
    v = np.array([b.velocity for b in scene.bodies], dtype=float)
    omega = np.array([b.angular_velocity for b in scene.bodies], dtype=float)
    fixed = np.array([b.motion is Motion.FIXED for b in scene.bodies])
    v[fixed] = 0.0
    omega[fixed] = 0.0
    return State(0.0, x, p, v, omega)


def build_system(scene: Scene) -> MultibodySystem:
    """Array form of ``scene`` (clearance joints expanded)."""
    scene = scene.expanded
    index = {b.name: i for i, b in enumerate(scene.bodies)}
    x, p, rotation = body_frames(scene)
    com = np.array([b.center_of_mass for b in scene.bodies], dtype=float)
    fixed = np.array([b.motion is Motion.FIXED for b in scene.bodies])
    mass = np.array([1.0 if fixed[i] else b.mass for i, b in enumerate(scene.bodies)])
    inertia = np.array([np.eye(3) if fixed[i] else np.array(b.inertia, dtype=float)
                        for i, b in enumerate(scene.bodies)])
    inverse_inertia = np.array([np.linalg.inv(j) for j in inertia])

    def local(body: int, world_point) -> np.ndarray:
        return rotation[body].T @ (np.asarray(world_point, dtype=float) - x[body])

    def local_direction(body: int, world_direction) -> np.ndarray:
        return rotation[body].T @ np.asarray(world_direction, dtype=float)

    # shapes
    shape_index: dict[tuple[str, str], int] = {}
    kinds, params, bodies, positions, rotations = [], [], [], [], []
    for b, body in enumerate(scene.bodies):
        for shape in body.shapes:
            shape_index[(body.name, shape.name)] = len(kinds)
            kinds.append(shape_code(shape))
            params.append(pack_shape_parameters(shape))
            bodies.append(b)
            positions.append(np.asarray(shape.position, dtype=float) - com[b])
            rotations.append(quat_to_matrix(_unit(shape.orientation)))
    # pairs
    contacts = scene.contacts
    pair_a = [shape_index[(c.body_a, c.shape_a)] for c in contacts]
    pair_b = [shape_index[(c.body_b, c.shape_b)] for c in contacts]
    # joints
    jk, ja, jb, anchor_a, anchor_b, frame_a, axis_b, relative = [], [], [], [], [], [], [], []
    for joint in scene.joints:
        a, b = index[joint.body_a], index[joint.body_b]
        axis = np.asarray(getattr(joint, "axis", (0.0, 0.0, 1.0)), dtype=float)
        axis = axis / np.linalg.norm(axis)
        frame_world = contact_frame(axis)  # rows (axis, t1, t2)
        jk.append(JOINT_CODES[joint.kind])
        ja.append(a)
        jb.append(b)
        anchor_a.append(local(a, joint.anchor))
        anchor_b.append(local(b, joint.anchor))
        frame_a.append(rotation[a].T @ frame_world.T)  # columns in A's axes
        axis_b.append(local_direction(b, axis))
        relative.append(quat_multiply(quat_conjugate(p[a]), p[b]))
    # drivers
    dbody, dcomp, dquant, dstart, dtimes, dvalues, dinit = [], [], [], [0], [], [], []
    dref = []
    for driver in scene.drivers:
        b = index[driver.body]
        component = COMPONENTS.index(driver.component)
        dbody.append(b)
        dcomp.append(component)
        dquant.append(0 if driver.quantity == "velocity" else 1)
        dtimes.extend(driver.times)
        dvalues.extend(driver.values)
        dstart.append(len(dtimes))
        dinit.append(x[b, component] if component < 3 else 0.0)
        dref.append(p[b])
    # force elements
    fk, fa, fb, fp = [], [], [], []

    def application_parameters(prm, application: LoadApplication, a: int, b: int,
                               scalar_is_moment: bool) -> None:
        target = index[application.body]
        prm[7] = 0.0 if target == a else 1.0
        prm[8] = 1.0 if application.action == "moment" else 0.0
        prm[9] = 1.0 if application.frame == "body" else 0.0
        prm[10:13] = application.unit_direction()
        prm[13:16] = np.asarray(application.point) - com[target]
        prm[16] = application.gain(scalar_is_moment)

    for load in scene.loads:
        if isinstance(load, AngleLawLoad | DistanceLawLoad):
            if isinstance(load, AngleLawLoad):
                names = load.angle_bodies
                if len(names) > 2:
                    raise ValueError(f"load {load.name!r}: the reference engine takes angle "
                                     f"laws of at most two bodies, got {names}")
            else:
                names = (load.body_a, load.body_b)
            a, b = index[names[0]], index[names[-1]]
            for application in load.applications:
                if application.body not in names:
                    raise ValueError(
                        f"load {load.name!r}: the reference engine applies a law load only to "
                        f"the bodies of its law {names}, not to {application.body!r}")
                prm = np.zeros(24)
                if isinstance(load, AngleLawLoad):
                    coefficients = list(load.angle_coefficients) + [0.0]
                    prm[0:3] = load.axis
                    prm[3] = load.stiffness
                    prm[4] = load.offset
                    prm[5] = coefficients[0]
                    prm[6] = coefficients[1] if len(names) == 2 else 0.0
                    application_parameters(prm, application, a, b, True)
                    kind = FORCE_ANGLE_LAW
                else:
                    prm[0:3] = np.asarray(load.point_a) - com[a]
                    prm[3:6] = np.asarray(load.point_b) - com[b]
                    prm[17] = load.stiffness
                    prm[18] = load.rest_length
                    application_parameters(prm, application, a, b, False)
                    kind = FORCE_DISTANCE_LAW
                fk.append(kind)
                fa.append(a)
                fb.append(b)
                fp.append(prm)
            continue
        prm = np.zeros(24)
        if isinstance(load, LinearSpringDamper):
            a, b = index[load.body_a], index[load.body_b]
            prm[0:3] = np.asarray(load.point_a) - com[a]
            prm[3:6] = np.asarray(load.point_b) - com[b]
            prm[6:10] = (load.stiffness, load.damping, load.rest_length, load.preload)
            kind = FORCE_LINEAR_SPRING
        elif isinstance(load, TorsionalSpringDamper):
            a, b = index[load.body_a], index[load.body_b]
            axis = np.asarray(load.axis, dtype=float)
            reference = contact_frame(axis / np.linalg.norm(axis))[1]
            prm[0:3] = local_direction(a, axis)
            prm[3:6] = local_direction(a, reference)
            prm[6:9] = local_direction(b, reference)
            prm[9:13] = (load.stiffness, load.damping, load.rest_angle, load.preload)
            kind = FORCE_TORSIONAL_SPRING
        elif isinstance(load, PointForce):
            a = b = index[load.body]
            prm[0:3] = np.asarray(load.point) - com[a]
            prm[3:6] = load.force
            prm[6] = 1.0 if load.frame == "body" else 0.0
            prm[7] = load.start_time
            prm[8] = NEVER if load.end_time is None else load.end_time
            kind = FORCE_POINT_FORCE
        elif isinstance(load, Moment):
            a = b = index[load.body]
            prm[0:3] = load.moment
            prm[3] = 1.0 if load.frame == "body" else 0.0
            prm[4] = load.start_time
            prm[5] = NEVER if load.end_time is None else load.end_time
            kind = FORCE_MOMENT
        else:  # pragma: no cover - every load kind of the scene description is handled above
            raise TypeError(f"unhandled load kind {load.kind!r}")
        fk.append(kind)
        fa.append(a)
        fb.append(b)
        fp.append(prm)

    def arr(values, shape, dtype=float):
        return np.array(values, dtype=dtype).reshape(shape)

    return MultibodySystem(
        mass=mass, inertia=inertia, inverse_inertia=inverse_inertia, body_fixed=fixed,
        gravity=np.asarray(scene.gravity, dtype=float),
        shape_kind=arr(kinds, (-1,), np.int64), shape_parameters=arr(params, (len(kinds), -1))
        if kinds else np.zeros((0, 8)),
        shape_body=arr(bodies, (-1,), np.int64), shape_position=arr(positions, (-1, 3)),
        shape_rotation=arr(rotations, (-1, 3, 3)),
        pair_shape_a=arr(pair_a, (-1,), np.int64), pair_shape_b=arr(pair_b, (-1,), np.int64),
        pair_friction=arr([c.friction for c in contacts], (-1,)),
        pair_restitution=arr([c.restitution for c in contacts], (-1,)),
        pair_offset=arr([c.offset for c in contacts], (-1,)),
        joint_kind=arr(jk, (-1,), np.int64), joint_body_a=arr(ja, (-1,), np.int64),
        joint_body_b=arr(jb, (-1,), np.int64), joint_anchor_a=arr(anchor_a, (-1, 3)),
        joint_anchor_b=arr(anchor_b, (-1, 3)), joint_frame_a=arr(frame_a, (-1, 3, 3)),
        joint_axis_b=arr(axis_b, (-1, 3)), joint_relative_rotation=arr(relative, (-1, 4)),
        driver_body=arr(dbody, (-1,), np.int64), driver_component=arr(dcomp, (-1,), np.int64),
        driver_quantity=arr(dquant, (-1,), np.int64), driver_start=arr(dstart, (-1,), np.int64),
        driver_times=arr(dtimes, (-1,)), driver_values=arr(dvalues, (-1,)),
        driver_initial=arr(dinit, (-1,)), driver_reference=arr(dref, (-1, 4)),
        force_kind=arr(fk, (-1,), np.int64), force_body_a=arr(fa, (-1,), np.int64),
        force_body_b=arr(fb, (-1,), np.int64), force_parameters=arr(fp, (-1, 24)),
        body_names=tuple(b.name for b in scene.bodies),
        pair_names=tuple(c.name for c in contacts),
        joint_names=tuple(j.name for j in scene.joints),
    )


def law_load_problems(scene: Scene) -> list[tuple[str, str]]:
    """(feature, reason) for every law load of ``scene`` that :func:`build_system`'s packing
    cannot take (angle laws of at most two bodies, applied to the law's own bodies); empty when
    all can. The adapters that evaluate the laws through this packing (MuJoCo, Exudyn) report
    these as unsupported."""
    out = []
    for load in scene.loads:
        if isinstance(load, AngleLawLoad):
            feature, names = "angle_law_loads", load.angle_bodies
            if len(names) > 2:
                out.append((feature, f"{load.name}: angle law of {len(names)} bodies (the "
                                     "shared law evaluation takes at most 2)"))
        elif isinstance(load, DistanceLawLoad):
            feature, names = "distance_law_loads", (load.body_a, load.body_b)
        else:
            continue
        strangers = sorted({a.body for a in load.applications} - set(names))
        if strangers:
            out.append((feature, f"{load.name}: applied to {strangers}, not to bodies of its "
                                 f"law {names} (the shared law evaluation cannot)"))
    return out
