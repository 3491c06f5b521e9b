"""The mechanical energy of a scene's state: kinetic, gravitational and spring potential energy.

One implementation for every user: the harness measures a trajectory with it (a time axis in
front: arrays (T, nb, 3)), and each stepping engine's energy guard feeds it one state (arrays
(nb, 3)) in the engine's internal units. Loads whose work it does not count (drivers, point
forces, moments, law loads) are :data:`~clearbench.scenarios.features.WORK_FEATURES`.

Units are the scene's (or the internal units the caller's arrays are in): energy
[M L^2 / T^2].
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass

import numpy as np

from clearbench.scenarios.bodies import Motion
from clearbench.scenarios.loads import LinearSpringDamper, TorsionalSpringDamper
from clearbench.scenarios.scene import Scene

__all__ = ["Energy", "SpringPoints", "dissipative_elements", "mechanical_energy",
           "rigid_spring_points"]

#: ``points(load) -> (point_a, point_b)``: the world positions (..., 3) [L] of a linear
#: spring's two attachment points in the state measured.
SpringPoints = Callable[[LinearSpringDamper], tuple[np.ndarray, np.ndarray]]


@dataclass(frozen=True)
class Energy:
    """Kinetic, gravitational potential, spring potential and contact energy, and their total
    [M L^2 / T^2], each of the shape of the state's leading axes ((T,) for a trajectory, () for
    one state). Time-switched forces, moments and drivers do work not counted here, and so do
    law loads (``angle_law``, ``distance_law``): their forces are not the gradient of a
    potential in general (a torsion law applied as a force on a body-fixed lever, a distance
    law pushing along a body axis), so no potential energy exists to count for them.
    ``contacts`` is the elastic energy stored in the contacts, which only the harness estimates
    (``harness.measure.series.contact_energy``; 0 here)."""

    kinetic: np.ndarray
    gravity: np.ndarray
    springs: np.ndarray
    contacts: np.ndarray | float = 0.0

    @property
    def total(self) -> np.ndarray:
        return self.kinetic + self.gravity + self.springs + self.contacts

    def at(self, samples: np.ndarray) -> Energy:
        """The same energies on a subset of the samples (boolean mask or indices)."""
        contacts = self.contacts[samples] if np.ndim(self.contacts) else self.contacts
        return Energy(self.kinetic[samples], self.gravity[samples], self.springs[samples],
                      contacts)


def mechanical_energy(scene: Scene, com: np.ndarray, velocity: np.ndarray, omega: np.ndarray,
                      spring_points: SpringPoints,
                      torsion_angles: Mapping[str, np.ndarray | float] | None = None) -> Energy:
    """Kinetic, gravity and spring energy of one state or of a trajectory of states.

    Parameters
    ----------
    scene : Scene
        The scene (masses, inertia about the centre of mass in body axes, gravity, loads), in
        the units of the arrays.
    com : ndarray, shape (..., nb, 3)
        Centre-of-mass positions, world [L].
    velocity : ndarray, shape (..., nb, 3)
        Centre-of-mass velocities, world [L/T].
    omega : ndarray, shape (..., nb, 3)
        Angular velocities in body axes [1/T].
    spring_points : callable
        World attachment points of a linear spring (:data:`SpringPoints`; see
        :func:`rigid_spring_points`).
    torsion_angles : mapping, optional
        Torsional spring name -> its angle (...,) [rad] measured from the scene's initial
        configuration. A torsional spring not in it is not counted (an engine that cannot
        measure the angle leaves it out and keeps its energy guard off for such scenes).

    Returns
    -------
    Energy
        With ``contacts`` 0; fixed bodies count no kinetic or potential energy.
    """
    torsion_angles = torsion_angles or {}
    shape = np.shape(com)[:-2]
    kinetic = np.zeros(shape)
    potential = np.zeros(shape)
    gravity = np.asarray(scene.gravity, dtype=float)
    for b, body in enumerate(scene.bodies):
        if body.motion is Motion.FIXED:
            continue
        v = velocity[..., b, :]
        w = omega[..., b, :]
        inertia = np.asarray(body.inertia, dtype=float)
        kinetic += 0.5 * body.mass * np.sum(v * v, axis=-1)
        kinetic += 0.5 * np.einsum("...i,ij,...j->...", w, inertia, w)
        potential -= body.mass * com[..., b, :] @ gravity
    springs = np.zeros(shape)
    for load in scene.loads:
        if isinstance(load, LinearSpringDamper):
            point_a, point_b = spring_points(load)
            stretch = np.linalg.norm(point_b - point_a, axis=-1) - load.rest_length
            springs += load.preload * stretch + 0.5 * load.stiffness * stretch**2
        elif isinstance(load, TorsionalSpringDamper) and load.name in torsion_angles:
            phi = torsion_angles[load.name]
            springs += load.preload * phi + 0.5 * load.stiffness * (phi - load.rest_angle) ** 2
    return Energy(kinetic, potential, springs)


def rigid_spring_points(scene: Scene, origins: np.ndarray, rotations: np.ndarray
                        ) -> SpringPoints:
    """:data:`SpringPoints` of one state given by its body-frame origins (nb, 3) [L] and
    rotation matrices body -> world (nb, 3, 3)."""
    def points(load: LinearSpringDamper) -> tuple[np.ndarray, np.ndarray]:
        a, b = scene.body_index(load.body_a), scene.body_index(load.body_b)
        return (origins[a] + rotations[a] @ np.asarray(load.point_a, dtype=float),
                origins[b] + rotations[b] @ np.asarray(load.point_b, dtype=float))

    return points


def dissipative_elements(scene: Scene) -> tuple[str, ...]:
    """What in ``scene`` can take mechanical energy, in words (``"contact ball_floor:
    restitution 0"``, ``"spring tie: damping 0.5"``): every contact pair, explicit or generated
    by a clearance joint, with friction or with restitution e < 1 (an impact on it loses
    (1 - e^2) of its normal kinetic energy, a slip rubs), and every spring-damper with
    damping. Empty: the scene conserves energy wherever its energy balance is complete (no
    driver or working load, :data:`~clearbench.scenarios.features.WORK_FEATURES`): ideal
    joints, gravity and undamped springs exchange energy without loss, and elastic
    frictionless impacts (Newton, e = 1) give back what they take."""
    found = []
    for contact in scene.all_contacts:
        if contact.friction > 0:
            found.append(f"contact {contact.name}: friction {contact.friction:g}")
        elif contact.restitution < 1:
            found.append(f"contact {contact.name}: restitution {contact.restitution:g}")
    for load in scene.loads:
        if isinstance(load, LinearSpringDamper | TorsionalSpringDamper) and load.damping > 0:
            found.append(f"spring {load.name}: damping {load.damping:g}")
    return tuple(found)
