"""Siconos worker: run one scene with the Siconos kernel and return the common trajectory.

Runs under Debian's /usr/bin/python3 with a clean environment (Siconos 4.4 imports only with
Debian's numpy); it imports numpy, siconos, its siblings ``geometry`` and ``project_kernels``
(the script's folder is on ``sys.path``) and, through the latter, the project's kernels
(``clearbench.kernels``, imported by path: nothing else of clearbench).

Protocol (files, never stdout, which Siconos fills with noise such as "BLOCK COPY !!!!"):

    /usr/bin/python3 engine.py INPUT.npz OUTPUT.npz

INPUT.npz holds ``scene_json`` (the scene with its clearance joints expanded, as
``scenarios.serialization.scene_to_json`` writes it) and ``settings_json`` (time step, horizon,
record_every and the resolved options, see :data:`SETTINGS_KEYS`).

OUTPUT.npz holds ``ok`` (the worker finished and wrote a trajectory), ``status`` ("ok",
"diverged" or "failed": Siconos raised during stepping, the samples so far are kept),
``message``, the trajectory arrays of ``adapters.trajectory.Trajectory`` (float64 / int64 /
bool), ``build_seconds``, ``stepping_seconds``, ``steps`` and ``metadata_json``.

The model (kernel API, no io layer):

- bodies: ``NewtonEulerDS`` (q = centre of mass + quaternion w, x, y, z; twist = centre-of-mass
  velocity in world axes + angular velocity in body axes); fixed bodies have no dynamical
  system; gravity, point forces, moments and spring-dampers enter through ``computeFExt`` /
  ``computeMExt`` (moments given in body axes), evaluated by Moreau-Jean at the current iterate;
- drivers: a ``BoundaryCondition`` whose ``computePrescribedVelocity(t)`` sets the prescribed
  twist components at the end of the step;
- ideal joints: ``PivotJointR`` / ``KneeJointR`` / ``PrismaticJointR`` / ``FixedJointR`` with an
  ``EqualityConditionNSL``;
- contacts: one ``Interaction`` (``NewtonImpactFrictionNSL``) per candidate point of each pair,
  whose relation is :class:`ContactRelation`, a Python subclass of ``NewtonEuler3DR`` computing h
  and the Jacobian from the shared geometry conventions (the built-in frame of Siconos 4.4 has a
  first tangent that is not orthogonal to the normal when n_z dominates and n_x != n_y); a pair
  with a bounded face or a bore keeps one interaction per candidate SLOT, and a slot the
  geometry drops (candidate off the face, deeper than its depth, outside the bore) gets the gap
  ``geometry.DROPPED_GAP``: its interaction is inactive until the candidate
  comes back (then with whatever gap it has, as in the reference solver);
- law loads (angle and distance laws) enter ``computeFExt`` / ``computeMExt`` like the springs,
  evaluated at the current iterate;
- integrator: ``MoreauJeanOSI`` (+ ``TimeStepping``) or ``MoreauJeanCombinedProjectionOSI`` (+
  ``TimeSteppingCombinedProjection`` with an ``MLCPProjectOnConstraints``); one-step problem
  ``FrictionContact`` (contacts only) or ``GenericMechanical`` (contacts and joints).

Every Python object handed to Siconos (relations, boundary conditions, dynamical systems) is
kept referenced by :class:`SiconosModel` for the whole run: a Python relation collected while
Siconos still calls it crashes the process.
"""

import json
import math
import os
import signal
import sys
import time
import traceback
from time import perf_counter

import geometry
import numpy as np
from project_kernels import quaternion, time_profiles

#: Keys of ``settings_json``.
SETTINGS_KEYS = (
    "time_step",            # [T]
    "horizon",              # [T]
    "record_every",         # keep one sample every that many steps (and the last)
    "theta",                # Moreau-Jean theta
    "projection",           # combined projection on/off
    "solver",               # "nsgs" or "nsn-ac"
    "tolerance",            # one-step solver tolerance (Siconos's normalised residual)
    "max_iterations",       # one-step solver iteration limit
    "newton_iterations",    # Newton iterations of the time stepping (Siconos default 50)
    "newton_tolerance",     # Newton tolerance
    "constraint_tolerance",  # projection tolerance, unilateral and equality [L]
    "projection_max_iterations",
    "projection_solver",    # MLCP solver of the projection: "enum" or "pgs"
    "activation_threshold",  # MoreauJeanOSI: active when y + h/2 y' <= threshold [L]
    "contact_frame",        # "shared" (Python relation frame) or "siconos-builtin"
    "gmp_reduction",        # GenericMechanical equality handling: "gs", "substitute",
                            # "assemble", "mlcp"
    "fault",                # fault injection for tests: "", "segfault", "hang", "exception"
)

#: Load kinds the worker applies (``scenarios.loads``); any other kind is refused.
LOAD_KINDS = ("point_force", "moment", "linear_spring", "torsional_spring", "angle_law",
              "distance_law")
_LAW_KINDS = ("angle_law", "distance_law")

#: Twist index of each driver component (rotations: resolved to a body axis, see DriverBC).
_TRANSLATION = {"x": 0, "y": 1, "z": 2}
_NEVER = 1e300


# ---------------------------------------------------------------------------- small maths
def _skew(r):
    return np.array([[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]])


def siconos_builtin_frame(normal):
    """The contact frame Siconos 4.4 builds (numerics ``orthoBaseFromVector``), rows (n, t1,
    t2). Its t1 is not orthogonal to n when |n_z| is the largest component and n_x != n_y; it
    is used only to read the forces of the ``siconos-builtin`` relation variant."""
    ax, ay, az = (float(v) for v in normal)
    norm = math.sqrt(ax * ax + ay * ay + az * az)
    ax, ay, az = ax / norm, ay / norm, az / norm
    if abs(ax) > abs(ay):
        first = (ay, -ax, 0.0) if abs(ax) > abs(az) else (0.0, -az, ax)
    elif abs(ay) > abs(az):
        first = (-ay, ax, 0.0)
    else:
        first = (0.0, -az, ax)
    first = np.array(first) / math.sqrt(sum(v * v for v in first))
    n = np.array([ax, ay, az])
    return np.array([n, first, np.cross(n, first)])


# ---------------------------------------------------------------------------- scene model
class Body:
    """A scene body: inertial data, initial Siconos state, shapes placed at its centre of mass."""

    def __init__(self, index, data):
        self.index = index
        self.name = data["name"]
        self.fixed = data.get("motion", "free") == "fixed"
        self.driven = data.get("motion", "free") == "driven"
        self.mass = float(data.get("mass", 1.0))
        self.inertia = np.array(data.get("inertia", np.eye(3)), dtype=float)
        self.com = np.array(data.get("center_of_mass", (0.0, 0.0, 0.0)), dtype=float)
        orientation = quaternion.quat_normalize(
            np.array(data.get("orientation", (1.0, 0.0, 0.0, 0.0)), dtype=float))
        rotation = quaternion.quat_to_matrix(orientation)
        position = np.array(data.get("position", (0.0, 0.0, 0.0)), dtype=float)
        self.q0 = np.concatenate([position + rotation @ self.com, orientation])
        self.rotation0 = rotation
        velocity = np.array(data.get("velocity", (0.0, 0.0, 0.0)), dtype=float)
        omega = np.array(data.get("angular_velocity", (0.0, 0.0, 0.0)), dtype=float)
        self.twist0 = np.zeros(6) if self.fixed else np.concatenate([velocity, omega])
        self.shapes = {}
        for shape in data.get("shapes", []):
            kind = shape["kind"]
            self.shapes[shape["name"]] = (
                kind, geometry.packed_shape(kind, _packed_parameters(shape)),
                np.array(shape.get("position", (0.0, 0.0, 0.0)), dtype=float) - self.com,
                quaternion.quat_to_matrix(quaternion.quat_normalize(np.array(
                    shape.get("orientation", (1.0, 0.0, 0.0, 0.0)), dtype=float))),
            )
        self.ds = None  # the Siconos dynamical system (None for a fixed body)

    def state(self):
        """(q (7,), twist (6,)) now: Siconos's current values, or the fixed pose."""
        if self.ds is None:
            return self.q0, self.twist0
        return np.array(self.ds.q()), np.array(self.ds.twist())


def _packed_parameters(shape):
    kind = shape["kind"]
    if kind == "sphere":
        return [shape.get("radius", 1.0)]
    if kind == "box":
        return list(shape.get("half_extents", (0.5, 0.5, 0.5)))
    if kind in ("capsule", "cylinder"):
        return [shape.get("radius", 0.1), shape.get("half_length", 0.5)]
    if kind == "plane":
        return []
    if kind == "circle":
        return [shape.get("radius", 0.1)]
    if kind == "arc":
        return [shape.get("radius", 0.1), shape.get("start_angle", 0.0),
                shape.get("end_angle", math.pi)]
    # An absent face or bore depth (None) is 0 in the packed form: no bound.
    if kind == "rectangle":
        return list(shape.get("half_extents", (0.5, 0.5))) + [shape.get("depth") or 0.0]
    if kind == "disc":
        return [shape.get("radius", 0.5), shape.get("depth") or 0.0]
    if kind == "bore":
        return [shape.get("radius", 0.1), shape.get("half_length", 0.5),
                shape.get("start_angle", 0.0), shape.get("end_angle", 2.0 * math.pi),
                shape.get("depth") or 0.0]
    raise ValueError(f"unknown shape kind {kind!r}")


class Pair:
    """One contact pair: the shared geometry of its candidates, cached per configuration."""

    def __init__(self, index, data, bodies):
        self.index = index
        self.name = data["name"]
        self.body_a = bodies[data["body_a"]]
        self.body_b = bodies[data["body_b"]]
        self.shape_a = self.body_a.shapes[data["shape_a"]]
        self.shape_b = self.body_b.shapes[data["shape_b"]]
        self.friction = float(data.get("friction", 0.0))
        self.restitution = float(data.get("restitution", 0.0))
        self.offset = float(data.get("offset", 0.0))
        count = geometry.candidate_count(self.shape_a[0], self.shape_b[0])
        if count is None:
            raise ValueError(f"pair {self.name!r}: "
                             + geometry.unsupported_reason(self.shape_a[0], self.shape_b[0]))
        self.candidates = count
        # Siconos's first dynamical system must move: B when it does, else A.
        self.b_first = not self.body_b.fixed
        self._key = None
        self._value = None
        self.dropped = 0  # dropped slots over all evaluated configurations (statistics)
        self._fixed_a = None
        self._fixed_b = None

    @staticmethod
    def _placement(shape, q):
        rotation = quaternion.quat_to_matrix(q[3:7])
        return q[:3] + rotation @ shape[2], rotation @ shape[3], rotation

    def evaluate(self, q_a, q_b):
        """Candidate slots at the body states q_a, q_b (7,) each: (gap - offset (K,), point_a
        (K, 3), point_b (K, 3), frame (K, 3, 3)); a dropped slot (off a bounded face, outside a
        bore) has the gap DROPPED_GAP and keeps the kernel's points and frame for its Jacobian.
        Cached on the last configuration; the placement of a fixed body's shape is computed
        once."""
        key = (q_a.tobytes(), q_b.tobytes())
        if key != self._key:
            if self._fixed_a is None or not self.body_a.fixed:
                self._fixed_a = self._placement(self.shape_a, q_a)
            if self._fixed_b is None or not self.body_b.fixed:
                self._fixed_b = self._placement(self.shape_b, q_b)
            position_a, orientation_a, _ = self._fixed_a
            position_b, orientation_b, _ = self._fixed_b
            gap, point_a, point_b, frame, kept = geometry.pair_contact_slots(
                self.shape_a[1], position_a, orientation_a, self.shape_b[1], position_b,
                orientation_b)
            gap = np.where(kept, gap - self.offset, geometry.DROPPED_GAP)
            self.dropped += int(np.count_nonzero(~kept))
            self._value = (gap, point_a, point_b, frame)
            self._key = key
        return self._value

    def split(self, first, second):
        """(q_a, q_b) from the Siconos block states (first DS, second DS or None)."""
        if self.b_first:
            return (second if second is not None else self.body_a.q0), first
        return first, (second if second is not None else self.body_b.q0)


# ---------------------------------------------------------------------------- Siconos classes
def define_siconos_classes(sk):
    """The Python subclasses of Siconos classes (defined once Siconos is imported)."""

    class ContactRelation(sk.NewtonEuler3DR):
        """Candidate ``index`` of a pair as a NewtonEuler3DR with the shared gap and frame.

        The first dynamical system is B when B moves (contact normal n, from A toward B), else
        A (normal -n, frame rows (-n, t1, -t2), still right-handed). ``frame`` holds the
        frame of the last Jacobian (the frame of the impulse ``lambda(1)``).
        """

        def __init__(self, pair, index, clock, two_bodies):
            sk.NewtonEuler3DR.__init__(self)
            self.pair = pair
            self.two_bodies = two_bodies
            self.index = index
            self.clock = clock
            self.sign = np.array([1.0, 1.0, 1.0]) if pair.b_first else \
                np.array([-1.0, 1.0, -1.0])
            self.frame = None

        def _geometry(self, first, second):
            q_a, q_b = self.pair.split(first, second)
            gap, point_a, point_b, frame = self.pair.evaluate(q_a, q_b)
            k = self.index
            if self.pair.b_first:
                return gap[k], point_b[k], point_a[k], frame[k] * self.sign[:, None], q_b, q_a
            return gap[k], point_a[k], point_b[k], frame[k] * self.sign[:, None], q_a, q_b

        def computeh(self, time, q0, y):
            tick = perf_counter()
            q = np.asarray(q0)
            second = q[7:14] if q.size > 7 else None
            gap, point_1, point_2, frame, _, _ = self._geometry(q[:7], second)
            y[0] = gap
            self.pc1()[:] = point_1
            self.pc2()[:] = point_2
            self.nc()[:] = frame[0]
            self.clock[0] += perf_counter() - tick

        def computeJachqT(self, inter, q0):
            tick = perf_counter()
            first = np.array(q0.vector(0))
            second = np.array(q0.vector(1)) if self.two_bodies else None
            _, point_1, point_2, frame, q_1, q_2 = self._geometry(first, second)
            jacobian = self.jachqT()
            rotation_1 = quaternion.quat_to_matrix(q_1[3:7])
            # velocity of the contact point of body 1: v + (R w) x r = v - [r]x R w (w body)
            jacobian[:, 0:3] = frame
            jacobian[:, 3:6] = -frame @ _skew(point_1 - q_1[:3]) @ rotation_1
            if second is not None:
                rotation_2 = quaternion.quat_to_matrix(q_2[3:7])
                jacobian[:, 6:9] = -frame
                jacobian[:, 9:12] = frame @ _skew(point_2 - q_2[:3]) @ rotation_2
            self.frame = frame
            self.clock[0] += perf_counter() - tick

    class BuiltinFrameRelation(ContactRelation):
        """The same gap and points, but Siconos 4.4's own Jacobian and contact frame
        (``NewtonEuler3DR::computeJachqT``): kept to document the frame bug."""

        def computeJachqT(self, inter, q0):
            sk.NewtonEuler3DR.computeJachqT(self, inter, q0)
            self.frame = siconos_builtin_frame(np.array(self.nc()))

    class LoadedDS(sk.NewtonEulerDS):
        """A NewtonEulerDS whose external force and moment come from the scene's loads."""

        def __init__(self, q0, twist0, mass, inertia, loads, body):
            sk.NewtonEulerDS.__init__(self, q0, twist0, mass, inertia)
            self.loads = loads
            self.body = body
            self.setFExtPtr(np.zeros(3))
            self.setMExtPtr(np.zeros(3))
            self.setIsMextExpressedInInertialFrame(False)

        def computeFExt(self, time, f_ext=None):
            force, _ = self.loads.on_body(self.body, time)
            target = self.fExt() if f_ext is None else f_ext
            for i in range(3):
                target[i] = force[i]

        def computeMExt(self, time, m_ext=None):
            _, moment = self.loads.on_body(self.body, time)
            if m_ext is None:
                # A fresh vector, not a write into ``self._mExt``: that SWIG member getter of
                # Siconos 4.4 (Debian, Python 3.11) drops a reference to None at each access
                # (about 1.6 per call with the write); None's count (~1e4) reached 0 after a
                # few hundred steps of C-60 ("none_dealloc", abort).
                self.setMExtPtr(np.array(moment, dtype=float))
            else:
                for i in range(3):
                    m_ext[i] = moment[i]

    class DriverBC(sk.BoundaryCondition):
        """Prescribed twist components of a driven body, evaluated at the time Siconos asks
        (the end of the step)."""

        def __init__(self, indices, drivers):
            sk.BoundaryCondition.__init__(self, [int(i) for i in indices], [0.0] * len(indices))
            self.drivers = drivers  # (scale, quantity, times, values) per index

        def computePrescribedVelocity(self, time):
            target = self.prescribedVelocity()
            for i, (scale, quantity, times, values) in enumerate(self.drivers):
                rate = time_profiles.profile_value(times, values, time) \
                    if quantity == "velocity" else time_profiles.profile_slope(times, values, time)
                target[i] = scale * rate

    return ContactRelation, BuiltinFrameRelation, LoadedDS, DriverBC



class Loads:
    """Gravity and the scene's loads, as world forces and body-axis moments on each body."""

    def __init__(self, scene, bodies):
        self.bodies = bodies
        self.gravity = np.array(scene.get("gravity", (0.0, 0.0, -9.81)), dtype=float)
        self.loads = scene.get("loads", [])
        self.per_body = {name: [] for name in bodies}
        for load in self.loads:
            kind = load["kind"]
            if kind not in LOAD_KINDS:
                raise ValueError(f"load {load.get('name')!r}: unknown load kind {kind!r}")
            if kind in _LAW_KINDS:
                # A law load acts only on the bodies of its applications.
                targets = []
                for application in load["applications"]:
                    if application["body"] not in targets:
                        targets.append(application["body"])
            else:
                targets = [load[key] for key in ("body", "body_a", "body_b") if key in load]
            for target in targets:
                self.per_body[target].append(load)
        self._unwrap = {}
        # (law name, body name) -> the body's continuous angle at the last step
        self.angle_memory = {}
        self.nonfinite = False  # set when a load evaluated to NaN / inf (a diverging run)

    def has_loads(self, name):
        return bool(self.per_body[name])

    def _point(self, body, local):
        q, twist = body.state()
        rotation = quaternion.quat_to_matrix(q[3:7])
        arm = rotation @ (np.asarray(local, dtype=float) - body.com)
        velocity = twist[:3] + np.cross(rotation @ twist[3:6], arm)
        return q[:3] + arm, velocity, arm, rotation

    def on_body(self, name, time):
        """World force (3,) [F] and moment about the centre of mass in body axes (3,) [F L]."""
        body = self.bodies[name]
        q, twist = body.state()
        rotation = quaternion.quat_to_matrix(q[3:7])
        force = body.mass * self.gravity
        moment_world = np.zeros(3)
        for load in self.per_body[name]:
            kind = load["kind"]
            if kind == "point_force":
                if not load.get("start_time", 0.0) <= time < load.get("end_time", _NEVER):
                    continue
                f = np.array(load["force"], dtype=float)
                if load.get("frame", "world") == "body":
                    f = rotation @ f
                arm = rotation @ (np.array(load.get("point", (0.0, 0.0, 0.0))) - body.com)
                force = force + f
                moment_world += np.cross(arm, f)
            elif kind == "moment":
                if not load.get("start_time", 0.0) <= time < load.get("end_time", _NEVER):
                    continue
                m = np.array(load["moment"], dtype=float)
                moment_world += rotation @ m if load.get("frame", "world") == "body" else m
            elif kind == "linear_spring":
                point_a, velocity_a, _, _ = self._point(self.bodies[load["body_a"]],
                                                        load.get("point_a", (0.0, 0.0, 0.0)))
                point_b, velocity_b, _, _ = self._point(self.bodies[load["body_b"]],
                                                        load.get("point_b", (0.0, 0.0, 0.0)))
                d = point_b - point_a
                length = float(np.linalg.norm(d))
                direction = d / length if length > 0.0 else np.zeros(3)
                rate = float(direction @ (velocity_b - velocity_a))
                tension = load.get("preload", 0.0) + load.get("stiffness", 0.0) * (
                    length - load.get("rest_length", 0.0)) + load.get("damping", 0.0) * rate
                if name == load["body_a"]:
                    f, local = tension * direction, load.get("point_a", (0.0, 0.0, 0.0))
                else:
                    f, local = -tension * direction, load.get("point_b", (0.0, 0.0, 0.0))
                arm = rotation @ (np.asarray(local, dtype=float) - body.com)
                force = force + f
                moment_world += np.cross(arm, f)
            elif kind == "torsional_spring":
                moment_world += self._torsion(load, name)
            else:  # angle_law, distance_law
                scalar = self._law_scalar(load)
                for application in load["applications"]:
                    if application["body"] != name:
                        continue
                    f, m = _law_action(application, scalar, kind == "angle_law", rotation,
                                       body.com)
                    force = force + f
                    moment_world += m
        moment = rotation.T @ moment_world
        if not (np.isfinite(force).all() and np.isfinite(moment).all()):
            # Siconos aborts (assert) on a NaN force: hand it zeros and let the step loop stop
            # the run as diverged.
            self.nonfinite = True
            return np.zeros(3), np.zeros(3)
        return force, moment

    def _law_scalar(self, load):
        """The scalar s of a law load: a moment [F L] (angle law) or a force [F] (distance
        law), as ``scenarios.loads`` defines it (formulas of ``ref_solver.forces``)."""
        if load["kind"] == "angle_law":
            axis = [float(v) for v in load.get("axis", (0.0, 0.0, 1.0))]
            total = float(load.get("offset", 0.0))
            for body_name, coefficient in zip(load["angle_bodies"], load["angle_coefficients"],
                                              strict=True):
                total += float(coefficient) * self._law_angle(load, body_name, axis)
            return float(load.get("stiffness", 0.0)) * total
        point_a, _, _, _ = self._point(self.bodies[load["body_a"]],
                                       load.get("point_a", (0.0, 0.0, 0.0)))
        point_b, _, _, _ = self._point(self.bodies[load["body_b"]],
                                       load.get("point_b", (0.0, 0.0, 0.0)))
        d = point_b - point_a
        return float(load.get("stiffness", 0.0)) * (
            float(load.get("rest_length", 0.0)) - math.sqrt(float(d @ d)))

    def _law_angle(self, load, body_name, axis):
        """The body's angle about the law's axis, continuous across steps (``continuous_angle``
        with the angle remembered at the last step)."""
        q, _ = self.bodies[body_name].state()
        raw = twist_angle(quaternion.quat_to_matrix(q[3:7]), axis)
        return continuous_angle(raw, self.angle_memory.get((load["name"], body_name), math.nan))

    def remember_angles(self):
        """After a step: remember every angle law's continuous body angles."""
        for load in self.loads:
            if load["kind"] == "angle_law":
                axis = [float(v) for v in load.get("axis", (0.0, 0.0, 1.0))]
                for body_name in load["angle_bodies"]:
                    self.angle_memory[(load["name"], body_name)] = self._law_angle(
                        load, body_name, axis)

    def _torsion(self, load, name):
        body_a = self.bodies[load["body_a"]]
        body_b = self.bodies[load["body_b"]]
        q_a, twist_a = body_a.state()
        q_b, twist_b = body_b.state()
        rotation_a = quaternion.quat_to_matrix(q_a[3:7])
        rotation_b = quaternion.quat_to_matrix(q_b[3:7])
        axis0 = np.array(load.get("axis", (0.0, 0.0, 1.0)), dtype=float)
        axis_local = body_a.rotation0.T @ axis0
        axis = rotation_a @ axis_local
        # phi: rotation of B relative to A about the axis since t = 0 (metrics.relative_angle)
        p_a, p_b = q_a[3:7], q_b[3:7]
        relative = quaternion.quat_multiply(quaternion.quat_conjugate(p_a), p_b)
        relative0 = quaternion.quat_multiply(quaternion.quat_conjugate(body_a.q0[3:7]),
                                             body_b.q0[3:7])
        change = quaternion.quat_multiply(quaternion.quat_conjugate(relative0), relative)
        phi = 2.0 * math.atan2(float(change[1:] @ axis_local), float(change[0]))
        previous = self._unwrap.get(load["name"], phi)
        phi = previous + math.remainder(phi - previous, 2.0 * math.pi)
        self._unwrap[load["name"]] = phi
        rate = float(axis @ (rotation_b @ twist_b[3:6] - rotation_a @ twist_a[3:6]))
        torque = -(load.get("preload", 0.0) + load.get("stiffness", 0.0) * (
            phi - load.get("rest_angle", 0.0)) + load.get("damping", 0.0) * rate)
        return torque * axis if name == load["body_b"] else -torque * axis


def twist_angle(rotation, axis):
    """Absolute rotation angle [rad] of a body about the unit world ``axis``, from its rotation
    matrix (3, 3): 2 atan2(axis . vee(R - R^T), 1 + tr R) (``ref_solver.forces.twist_angle``:
    2 atan2(q . axis, q_w) for the quaternion with q_w >= 0)."""
    vee_x = rotation[2, 1] - rotation[1, 2]
    vee_y = rotation[0, 2] - rotation[2, 0]
    vee_z = rotation[1, 0] - rotation[0, 1]
    trace = rotation[0, 0] + rotation[1, 1] + rotation[2, 2]
    return 2.0 * math.atan2(axis[0] * vee_x + axis[1] * vee_y + axis[2] * vee_z, 1.0 + trace)


def continuous_angle(raw, previous):
    """``raw`` plus the whole turns that bring it nearest ``previous`` (NaN: raw as is); the
    worker's copy of ``ref_solver.forces.continuous_angle`` (no numba in this interpreter)."""
    if math.isnan(previous):
        return raw
    turns = round((previous - raw) / (2.0 * math.pi))
    return raw if turns == 0 else raw + 2.0 * math.pi * turns


def _law_action(application, scalar, scalar_is_moment, rotation, com):
    """World force (3,) [F] and world moment about the centre of mass (3,) [F L] of one
    application of a law load (``scenarios.loads.LoadApplication``) whose scalar is
    ``scalar``, on a body of rotation (3, 3) and centre of mass ``com`` (body frame [L])."""
    direction = np.array(application.get("direction", (1.0, 0.0, 0.0)), dtype=float)
    direction = direction / math.sqrt(float(direction @ direction))
    if application.get("frame", "body") == "body":
        direction = rotation @ direction
    coefficient = float(application.get("coefficient", 1.0))
    lever = application.get("lever")
    if lever is None:
        gain = coefficient
    elif scalar_is_moment:
        gain = coefficient / float(lever)
    else:
        gain = coefficient * float(lever)
    value = gain * scalar * direction
    if application.get("action", "force") == "moment":
        return np.zeros(3), value
    arm = rotation @ (np.array(application.get("point", (0.0, 0.0, 0.0)), dtype=float) - com)
    return value, np.cross(arm, value)


# ---------------------------------------------------------------------------- the run
class SiconosModel:
    """The Siconos model of a scene and its stepping; every Siconos object stays referenced."""

    def __init__(self, scene, settings):
        # Lazy imports of the engine package: the tests import this module without Siconos.
        import siconos.kernel as sk
        import siconos.mechanics.joints as joints
        import siconos.numerics as sn

        self.sk, self.sn = sk, sn
        self.settings = settings
        self.scene = scene
        self.h = float(settings["time_step"])
        self.steps = int(math.ceil(float(settings["horizon"]) / self.h - 1e-9))
        self.callback_seconds = [0.0]
        ContactRelation, BuiltinFrameRelation, LoadedDS, DriverBC = define_siconos_classes(sk)

        self.body_list = [Body(i, data) for i, data in enumerate(scene.get("bodies", []))]
        self.bodies = {b.name: b for b in self.body_list}
        self.loads = Loads(scene, self.bodies)
        # Escape guard: far beyond anything a scene can mean, far below overflow.
        extent = max([1.0] + [float(np.max(np.abs(b.q0[:3]))) for b in self.body_list])
        self.escape_distance = 1e9 * extent
        self.nsds = sk.NonSmoothDynamicalSystem(0.0, (self.steps + 2) * self.h)
        self.keep = []  # every Python-side Siconos object, referenced for the whole run
        drivers_by_body = {}
        for driver in scene.get("drivers", []):
            drivers_by_body.setdefault(driver["body"], []).append(driver)
        for body in self.body_list:
            if body.fixed:
                continue
            if self.loads.has_loads(body.name):
                ds = LoadedDS(body.q0, body.twist0, body.mass, body.inertia, self.loads,
                              body.name)
            else:
                ds = sk.NewtonEulerDS(body.q0, body.twist0, body.mass, body.inertia)
                ds.setFExtPtr(body.mass * self.loads.gravity)
            if body.name in drivers_by_body:
                indices, specs = [], []
                for driver in drivers_by_body[body.name]:
                    index, scale = self._driver_index(body, driver["component"])
                    indices.append(index)
                    specs.append((scale, driver.get("quantity", "velocity"),
                                  np.array(driver.get("times", (0.0,)), dtype=float),
                                  np.array(driver.get("values", (0.0,)), dtype=float)))
                bc = DriverBC(indices, specs)
                ds.setBoundaryConditions(bc)
                self.keep.append(bc)
            self.nsds.insertDynamicalSystem(ds)
            body.ds = ds
            self.keep.append(ds)

        # ideal joints
        self.joint_interactions = []
        for joint in scene.get("joints", []):
            a, b = self.bodies[joint["body_a"]], self.bodies[joint["body_b"]]
            moving = [x.ds for x in (a, b) if x.ds is not None]
            if not moving:
                continue
            anchor = np.array(joint.get("anchor", (0.0, 0.0, 0.0)), dtype=float)
            axis = np.array(joint.get("axis", (0.0, 0.0, 1.0)), dtype=float)
            args = tuple(moving)
            kind = joint["kind"]
            if kind == "revolute":
                relation = joints.PivotJointR(anchor, axis, True, *args)
            elif kind == "spherical":
                relation = joints.KneeJointR(anchor, True, *args)
            elif kind == "prismatic":
                relation = joints.PrismaticJointR(axis, True, *args)
            elif kind == "fixed":
                relation = joints.FixedJointR(*args)
            else:
                raise ValueError(f"joint {joint['name']!r}: unknown kind {kind!r}")
            law = sk.EqualityConditionNSL(relation.numberOfConstraints())
            interaction = sk.Interaction(law, relation)
            self.nsds.link(interaction, *args)
            self.keep += [relation, law, interaction]
            self.joint_interactions.append(interaction)

        # contacts
        relation_class = ContactRelation if settings["contact_frame"] == "shared" \
            else BuiltinFrameRelation
        self.pairs = []
        self.contact_interactions = []  # per pair: list of (relation, interaction)
        for index, data in enumerate(scene.get("contacts", [])):
            pair = Pair(index, data, self.bodies)
            law = sk.NewtonImpactFrictionNSL(pair.restitution, 0.0, pair.friction, 3)
            self.keep.append(law)
            first, second = (pair.body_b, pair.body_a) if pair.b_first else \
                (pair.body_a, pair.body_b)
            items = []
            for k in range(pair.candidates):
                relation = relation_class(pair, k, self.callback_seconds, second.ds is not None)
                interaction = sk.Interaction(law, relation)
                if second.ds is not None:
                    self.nsds.link(interaction, first.ds, second.ds)
                else:
                    self.nsds.link(interaction, first.ds)
                items.append((relation, interaction))
                self.keep += [relation, interaction]
            self.pairs.append(pair)
            self.contact_interactions.append(items)

        # simulation
        self.td = sk.TimeDiscretisation(0.0, self.h)
        theta = float(settings["theta"])
        if self.joint_interactions:
            # GenericMechanical's only solver is NSGS over its blocks (Siconos 4.4); the
            # preset's solver chooses the local solver of each contact block. "nsgs": Newton
            # with line search, NSN_GP_HYBRID (the plain ONECONTACT_NSN failed on fast-sliding
            # contacts: Flores slider, residual 0.2, the slider went through its guide);
            # "nsn-ac": the Alart-Curnier Newton without line search, ONECONTACT_NSN.
            local_name, local_solver = {
                "nsgs": ("NSN_GP_HYBRID", sn.SICONOS_FRICTION_3D_ONECONTACT_NSN_GP_HYBRID),
                "nsn-ac": ("NSN (Alart-Curnier)", sn.SICONOS_FRICTION_3D_ONECONTACT_NSN),
            }[settings["solver"]]
            self.osnspb = sk.GenericMechanical(local_solver)
            self.problem = (f"GenericMechanical (NSGS, local {local_name}, equalities: "
                            f"{settings['gmp_reduction']})")
        else:
            solver = {"nsgs": sn.SICONOS_FRICTION_3D_NSGS,
                      "nsn-ac": sn.SICONOS_FRICTION_3D_NSN_AC}[settings["solver"]]
            self.osnspb = sk.FrictionContact(3, solver)
            self.problem = f"FrictionContact ({settings['solver'].upper()})"
        options = self.osnspb.numericsSolverOptions()
        options.dparam[sn.SICONOS_DPARAM_TOL] = float(settings["tolerance"])
        options.iparam[sn.SICONOS_IPARAM_MAX_ITER] = int(settings["max_iterations"])
        if self.joint_interactions:
            options.iparam[sn.SICONOS_GENERIC_MECHANICAL_IPARAM_ISREDUCED] = {
                "gs": sn.SICONOS_GENERIC_MECHANICAL_GS_ON_ALLBLOCKS,
                "substitute": sn.SICONOS_GENERIC_MECHANICAL_SUBS_EQUALITIES,
                "assemble": sn.SICONOS_GENERIC_MECHANICAL_ASSEMBLE_EQUALITIES,
                "mlcp": sn.SICONOS_GENERIC_MECHANICAL_MLCP_LIKE}[settings["gmp_reduction"]]
        self.solver_options = options
        if settings["projection"]:
            self.osi = sk.MoreauJeanCombinedProjectionOSI(theta)
            projection_solver = {"enum": sn.SICONOS_MLCP_ENUM,
                                 "pgs": sn.SICONOS_MLCP_PGS}[settings["projection_solver"]]
            self.position_problem = sk.MLCPProjectOnConstraints(projection_solver, 1.0)
            self.simulation = sk.TimeSteppingCombinedProjection(
                self.nsds, self.td, self.osi, self.osnspb, self.position_problem, 2)
            tolerance = float(settings["constraint_tolerance"])
            self.simulation.setConstraintTol(tolerance)
            self.simulation.setConstraintTolUnilateral(tolerance)
            self.simulation.setProjectionMaxIteration(int(settings["projection_max_iterations"]))
        else:
            self.osi = sk.MoreauJeanOSI(theta)
            self.osi.setConstraintActivationThreshold(float(settings["activation_threshold"]))
            self.position_problem = None
            self.simulation = sk.TimeStepping(self.nsds, self.td, self.osi, self.osnspb)
        self.simulation.setNewtonMaxIteration(int(settings["newton_iterations"]))
        self.simulation.setNewtonTolerance(float(settings["newton_tolerance"]))
        self.simulation.initialize()

    def _driver_index(self, body, component):
        """Twist index and sign of a driven component. Rotations about a world axis map to the
        body axis aligned with it at t = 0 (Siconos prescribes body-axis angular velocity)."""
        if component in _TRANSLATION:
            return _TRANSLATION[component], 1.0
        axis = "xyz".index(component[-1])
        alignment = body.rotation0[axis, :]  # world axis `axis` in body coordinates
        j = int(np.argmax(np.abs(alignment)))
        if abs(abs(alignment[j]) - 1.0) > 1e-9:
            raise ValueError(f"driver of {body.name!r} about world {component[-1]}: no body "
                             "axis is aligned with it at t = 0")
        return 3 + j, float(np.sign(alignment[j]))

    # ------------------------------------------------------------------ stepping
    def run(self):
        settings = self.settings
        nb, npair = len(self.body_list), len(self.pairs)
        record = list(range(0, self.steps + 1, int(settings["record_every"])))
        if record[-1] != self.steps:
            record.append(self.steps)
        samples = len(record)
        out = {
            "times": np.zeros(samples), "positions": np.zeros((samples, nb, 3)),
            "orientations": np.zeros((samples, nb, 4)), "velocities": np.zeros((samples, nb, 3)),
            "angular_velocities": np.zeros((samples, nb, 3)),
            "contact_normal_force": np.zeros((samples, npair)),
            "contact_force": np.zeros((samples, npair, 3)),
            "solver_iterations": np.zeros(samples, dtype=np.int64),
            "solver_residual": np.full(samples, np.nan),
            "solver_converged": np.ones(samples, dtype=bool),
            "active_contacts": np.zeros(samples, dtype=np.int64),
        }
        self._store_state(out, 0, 0.0)
        sn = self.sn
        options = self.solver_options
        tolerance = float(settings["tolerance"])
        status, message = "ok", ""
        stepping = 0.0
        taken = 0
        next_record = 1
        newton_total = 0
        unconverged = []
        projection_iterations = 0
        max_violation = 0.0
        iterations, residual, converged = 0, 0.0, True
        reported = False
        simulation = self.simulation
        for k in range(1, self.steps + 1):
            options.iparam[sn.SICONOS_IPARAM_ITER_DONE] = 0
            options.dparam[sn.SICONOS_DPARAM_RESIDU] = np.nan
            tick = time.perf_counter()
            try:
                simulation.computeOneStep()
            except Exception as error:  # Siconos raised (e.g. a projection that fails)
                stepping += time.perf_counter() - tick
                status, message = "failed", f"Siconos raised at step {k}: {error}"
                break
            elapsed = time.perf_counter() - tick
            self.loads.remember_angles()
            step_iterations = int(options.iparam[sn.SICONOS_IPARAM_ITER_DONE])
            step_residual = float(options.dparam[sn.SICONOS_DPARAM_RESIDU])
            newton_total += int(simulation.getNewtonNbIterations())
            if self.position_problem is not None:
                projection_iterations += int(simulation.nbProjectionIteration())
                max_violation = max(max_violation, float(simulation.maxViolationUnilateral()),
                                    float(simulation.maxViolationEquality()))
            if step_iterations > 0 or math.isfinite(step_residual):
                reported = True
                iterations += step_iterations
                residual = max(residual, step_residual)
                if not step_residual <= tolerance:
                    converged = False
                    unconverged.append(k)
            taken = k
            finite = not self.loads.nonfinite and all(
                body.ds is None or (np.isfinite(np.array(body.ds.q())).all() and float(
                    np.max(np.abs(np.array(body.ds.q())[:3]))) < self.escape_distance)
                for body in self.body_list)
            if next_record < samples and (k == record[next_record] or not finite):
                self._store_state(out, next_record, simulation.nextTime())
                self._store_contacts(out, next_record)
                out["solver_iterations"][next_record] = iterations
                out["solver_residual"][next_record] = residual if reported else np.nan
                out["solver_converged"][next_record] = converged
                next_record += 1
                iterations, residual, converged, reported = 0, 0.0, True, False
            tick = time.perf_counter()
            simulation.nextStep()
            stepping += elapsed + time.perf_counter() - tick
            if not finite:
                status, message = "diverged", (
                    f"non-finite or escaped state at step {k} (a load was not finite, or a "
                    f"body went beyond {self.escape_distance:g} from the origin)")
                break
        for key in out:
            out[key] = out[key][:next_record]
        metadata = {
            "theta": float(settings["theta"]), "projection": bool(settings["projection"]),
            "one_step_problem": self.problem, "tolerance": tolerance,
            "contact_frame": settings["contact_frame"],
            "newton_iterations_total": newton_total,
            "newton_max_iterations": int(settings["newton_iterations"]),
            "unconverged_steps": unconverged[:1000],
            "unconverged_count": len(unconverged),
            "python_relation_seconds": self.callback_seconds[0],
            "contact_interactions": sum(len(items) for items in self.contact_interactions),
            # Candidate slots found dropped (off a bounded face, outside a bore), summed over
            # the configurations the relations evaluated: each such slot was handed DROPPED_GAP.
            "dropped_slot_evaluations": sum(pair.dropped for pair in self.pairs),
            "joint_interactions": len(self.joint_interactions),
        }
        if self.position_problem is not None:
            metadata.update({
                "projection_iterations_total": projection_iterations,
                "projection_max_violation": max_violation,
                "constraint_tolerance": float(settings["constraint_tolerance"]),
                "projection_solver": settings["projection_solver"],
            })
        if unconverged and status == "ok":
            message = (f"{len(unconverged)} step(s) whose one-step problem did not reach the "
                       f"tolerance {tolerance:g} (first: {unconverged[:5]})")
        return out, status, message, stepping, taken, metadata

    def _store_state(self, out, i, t):
        out["times"][i] = t
        for b, body in enumerate(self.body_list):
            q, twist = body.state()
            rotation = quaternion.quat_to_matrix(q[3:7])
            out["positions"][i, b] = q[:3] - rotation @ body.com
            out["orientations"][i, b] = q[3:7]
            out["velocities"][i, b] = twist[:3]
            out["angular_velocities"][i, b] = twist[3:6]

    def _store_contacts(self, out, i):
        active = set()
        for interaction in self.simulation.indexSet(1).interactions():
            active.add(interaction.number())
        count = 0
        for p, items in enumerate(self.contact_interactions):
            pair = self.pairs[p]
            normal = 0.0
            force = np.zeros(3)
            for relation, interaction in items:
                if interaction.number() not in active or relation.frame is None:
                    continue
                count += 1
                impulse = np.array(interaction.lambda_(1))
                world = relation.frame.T @ impulse
                normal += impulse[0]
                force += world if pair.b_first else -world
            out["contact_normal_force"][i, p] = normal / self.h
            out["contact_force"][i, p] = force / self.h
        out["active_contacts"][i] = count


def _inject_fault(fault):
    """Fault injection for the tests of the outcome handling."""
    if fault == "segfault":
        os.kill(os.getpid(), signal.SIGSEGV)
    elif fault == "hang":
        while True:
            time.sleep(3600)
    elif fault == "exception":
        raise RuntimeError("fault injected: exception")


def main(argv):
    input_path, output_path = argv[1], argv[2]
    result = {"ok": False, "status": "failed", "message": ""}
    try:
        with np.load(input_path, allow_pickle=False) as inputs:
            scene = json.loads(str(inputs["scene_json"]))
            settings = json.loads(str(inputs["settings_json"]))
        start = time.perf_counter()
        model = SiconosModel(scene, settings)
        build_seconds = time.perf_counter() - start
        if settings.get("fault"):
            _inject_fault(settings["fault"])
        arrays, status, message, stepping, taken, metadata = model.run()
        result.update(arrays)
        result.update({
            "ok": True, "status": status, "message": message,
            "build_seconds": build_seconds, "stepping_seconds": stepping, "steps": taken,
            "metadata_json": json.dumps(metadata),
        })
    except Exception:  # reported through the output file; the parent decides
        result["message"] = traceback.format_exc()
    np.savez(output_path, **result)
    return 0 if result["ok"] else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv))
