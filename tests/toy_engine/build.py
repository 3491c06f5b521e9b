"""The toy's model of a scene: free rigid bodies in gravity, sphere-plane contacts as a penalty
spring-damper with regularised Coulomb friction, semi-implicit (symplectic) Euler steps. Numpy
only.

Per contact pair, with m the pair's effective mass (the reduced mass of its moving bodies) and h
the time step, the contact is a linear spring-damper tuned so that an impact lasts about
``contact_steps`` steps: angular frequency omega = pi / (contact_steps h), stiffness m omega^2,
damping 2 zeta m omega with zeta from the pair's restitution e (the linear oscillator's
e = exp(-zeta pi / sqrt(1 - zeta^2)); e = 0: critical damping). The normal force is the spring
and damper clamped at 0 (a contact only pushes), so a ball resting on a plane sinks g / omega^2
(0.4 mm at h = 1 ms and 20 steps per impact). Friction opposes the slip velocity at the contact
point with at most mu times the normal force, viscous below that (rate m omega): a body that
must stick creeps.
"""

from __future__ import annotations

import math

import numpy as np

from clearbench.scenarios.bodies import Motion
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.shapes import Plane, Sphere

from .settings import ToySettings


def build_model(scene: Scene, settings: ToySettings, time_step: float) -> Model:
    """The toy's model of ``scene`` (its own units) at step ``time_step`` [T]."""
    return Model(scene, time_step, settings.contact_steps)


def _rotation(q: np.ndarray) -> np.ndarray:
    """(3, 3) rotation of the unit quaternion q = (w, x, y, z)."""
    w, x, y, z = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def _rotate_by(q: np.ndarray, rotation: np.ndarray) -> np.ndarray:
    """q times exp(rotation / 2): q turned by the body-axes rotation vector ``rotation``."""
    angle = float(np.linalg.norm(rotation))
    if angle == 0.0:
        return q
    axis = rotation / angle
    p = np.concatenate(([math.cos(angle / 2)], math.sin(angle / 2) * axis))
    w1, v1, w2, v2 = q[0], q[1:], p[0], p[1:]
    out = np.concatenate(([w1 * w2 - v1 @ v2], w1 * v2 + w2 * v1 + np.cross(v1, v2)))
    return out / np.linalg.norm(out)


def _damping_ratio(restitution: float) -> float:
    """zeta of a linear oscillator whose velocity after half a period is e times before."""
    if restitution <= 0.0:
        return 1.0
    log_e = math.log(restitution)
    return -log_e / math.sqrt(math.pi ** 2 + log_e ** 2)


class Model:
    """The state of every body (centre of mass x (nb, 3), orientation q (nb, 4), velocity v
    (nb, 3), body-axes angular velocity w (nb, 3)) and the contact pairs, stepped by
    :meth:`step`."""

    def __init__(self, scene: Scene, h: float, contact_steps: float):
        bodies = scene.bodies
        self.h = h
        self.time_step = h
        self.moving = np.array([b.motion is Motion.FREE for b in bodies])
        self.mass = np.array([b.mass for b in bodies], dtype=float)
        self.inertia = np.array([b.inertia for b in bodies], dtype=float)
        self.inverse_inertia = np.linalg.inv(self.inertia)
        self.com = np.array([b.center_of_mass for b in bodies], dtype=float)
        self.q = np.array([b.orientation for b in bodies], dtype=float)
        self.q /= np.linalg.norm(self.q, axis=1)[:, None]
        origins = np.array([b.position for b in bodies], dtype=float)
        self.x = origins + np.einsum("bij,bj->bi", self._rotations(), self.com)
        self.v = np.array([b.velocity for b in bodies], dtype=float) * self.moving[:, None]
        self.w = np.array([b.angular_velocity for b in bodies], dtype=float) \
            * self.moving[:, None]
        self.gravity = np.asarray(scene.gravity, dtype=float)
        omega = math.pi / (contact_steps * h)
        index = {b.name: i for i, b in enumerate(bodies)}
        self.pairs = []
        for pair in scene.all_contacts:
            a, b = index[pair.body_a], index[pair.body_b]
            shape_a = next(s for s in bodies[a].shapes if s.name == pair.shape_a)
            shape_b = next(s for s in bodies[b].shapes if s.name == pair.shape_b)
            if isinstance(shape_a, Sphere) and isinstance(shape_b, Plane):
                a, b, shape_a, shape_b = b, a, shape_b, shape_a
            inverse_masses = sum(1.0 / self.mass[i] for i in (a, b) if self.moving[i])
            effective = 1.0 / inverse_masses if inverse_masses else 1.0
            self.pairs.append((a, b, shape_a, shape_b, pair, effective * omega ** 2,
                               2.0 * _damping_ratio(pair.restitution) * effective * omega,
                               effective * omega, pair.body_b == bodies[b].name))

    def rotations(self) -> np.ndarray:
        """(nb, 3, 3) body rotations."""
        return self._rotations()

    def _rotations(self) -> np.ndarray:
        return np.array([_rotation(q) for q in self.q])

    def sample(self) -> tuple[np.ndarray, ...]:
        """Body-frame origins, orientations, centre-of-mass velocities, body-axes angular
        velocities: (nb, 3), (nb, 4), (nb, 3), (nb, 3)."""
        origins = self.x - np.einsum("bij,bj->bi", self._rotations(), self.com)
        return origins, self.q.copy(), self.v.copy(), self.w.copy()

    def _contact_forces(self, rotations: np.ndarray):
        """Force and torque on every body (world), and per pair the normal force and the
        force on its body B."""
        force = np.zeros_like(self.x)
        torque = np.zeros_like(self.x)
        normal_forces = np.zeros(len(self.pairs))
        on_b = np.zeros((len(self.pairs), 3))
        for k, (plane, ball, plane_shape, sphere, pair, stiffness, damping, viscous,
                ball_is_b) in enumerate(self.pairs):
            r_plane, r_ball = rotations[plane], rotations[ball]
            origin_plane = self.x[plane] - r_plane @ self.com[plane]
            origin_ball = self.x[ball] - r_ball @ self.com[ball]
            normal = r_plane @ _rotation(np.asarray(plane_shape.orientation) /
                                         np.linalg.norm(plane_shape.orientation))[:, 2]
            centre = origin_ball + r_ball @ np.asarray(sphere.position)
            height = (centre - origin_plane - r_plane @ np.asarray(plane_shape.position)) @ normal
            depth = sphere.radius + pair.offset - height
            if depth <= 0.0:
                continue
            point = centre - sphere.radius * normal
            arms = (point - self.x[ball], point - self.x[plane])
            velocity = (self.v[ball] + np.cross(r_ball @ self.w[ball], arms[0])
                        - self.v[plane] - np.cross(r_plane @ self.w[plane], arms[1]))
            approach = velocity @ normal
            pushing = max(0.0, stiffness * depth - damping * approach)
            slip = velocity - approach * normal
            speed = float(np.linalg.norm(slip))
            friction = np.zeros(3) if speed == 0.0 else \
                -min(pair.friction * pushing, viscous * speed) * slip / speed
            total = pushing * normal + friction   # on the ball
            for body, arm, sign in ((ball, arms[0], 1.0), (plane, arms[1], -1.0)):
                force[body] += sign * total
                torque[body] += sign * np.cross(arm, total)
            normal_forces[k] = pushing
            on_b[k] = total if ball_is_b else -total
        return force, torque, normal_forces, on_b

    def step(self) -> tuple[np.ndarray, np.ndarray, int]:
        """One semi-implicit Euler step; the contact forces of the step (normal force (np,),
        force on each pair's body B (np, 3), active contacts)."""
        rotations = self._rotations()
        force, torque, normal_forces, on_b = self._contact_forces(rotations)
        moving = self.moving[:, None]
        self.v += self.h * (self.gravity + force / self.mass[:, None]) * moving
        self.x += self.h * self.v * moving
        body_torque = np.einsum("bji,bj->bi", rotations, torque)   # R^T torque
        momentum = np.einsum("bij,bj->bi", self.inertia, self.w)
        self.w += self.h * np.einsum("bij,bj->bi", self.inverse_inertia,
                                     body_torque - np.cross(self.w, momentum)) * moving
        self.q = np.array([_rotate_by(q, self.h * w) for q, w in zip(self.q, self.w,
                                                                      strict=True)])
        return normal_forces, on_b, int(np.count_nonzero(normal_forces))
