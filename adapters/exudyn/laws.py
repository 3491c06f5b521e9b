"""The C-60's law loads (angle and distance laws) in Exudyn.

One implementation of the laws: the scene's law loads are packed into force elements by the
shared :func:`~clearbench.ref_solver.scene_system.build_system` and evaluated by
:func:`clearbench.ref_solver.forces.element_forces` (compiled with numba), as the reference and
MuJoCo adapters do. Each body acted on gets one ``LoadForceVector`` at its centre of mass and
one ``LoadTorqueVector`` (world axes). Two modes (option ``law_loads``):

- ``explicit``: the wrenches are evaluated once per step from the state at its start (a
  PreStep function) and held during the step (one step lag, as in MuJoCo);
- ``implicit``: Python ``loadVectorUserFunction`` s evaluate them from the current Newton
  iterate (Exudyn calls them in every residual; the laws are cached per state vector). Their
  Jacobian is not computed (``computeLoadsJacobian`` is 0): Newton treats them as a fixed point.

Exudyn's compiled symbolic user functions cannot express these laws: a load's symbolic
function only receives (mbs, t, load), not the configuration, and the laws' forces (body-fixed
directions, levers) are not the force of any connector whose user function does receive a
configuration (spring length, relative rotation).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from clearbench.ref_solver.forces import element_forces, no_angle_memory, remember_angles
from clearbench.ref_solver.scene_system import build_system, law_load_problems
from clearbench.ref_solver.system import FORCE_ANGLE_LAW, FORCE_DISTANCE_LAW
from clearbench.scenarios.loads import AngleLawLoad, DistanceLawLoad
from clearbench.scenarios.scene import Scene

LAW_KINDS = (FORCE_ANGLE_LAW, FORCE_DISTANCE_LAW)


@dataclass
class LawForces:
    """The law loads of a scene as force elements of the reference solver.

    Attributes
    ----------
    kinds, body_a, body_b : (ne,) int arrays
        Element kind and the two law bodies (indices into ``body_names``).
    parameters : (ne, 24) array
        Element parameters (layout in :mod:`clearbench.ref_solver.forces`).
    body_names : tuple of str
        Bodies in the order of the packed system (``scene.expanded.bodies``).
    acted : (na,) int array
        Indices of the bodies some law acts on (the others get no Exudyn load).
    angle_memory : (ne, 2) array
        The angle laws' continuous angles after the last step (see
        ``ref_solver.forces.remember_angles``).
    """

    kinds: np.ndarray
    body_a: np.ndarray
    body_b: np.ndarray
    parameters: np.ndarray
    body_names: tuple
    acted: np.ndarray
    angle_memory: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))

    def __post_init__(self) -> None:
        if self.angle_memory.shape != (self.kinds.shape[0], 2):
            self.angle_memory = no_angle_memory(self.kinds.shape[0])

    def wrenches(self, com: np.ndarray, rotation: np.ndarray, time: float) -> np.ndarray:
        """(nb, 6): force [F] and moment about the centre of mass [F L], world axes, of every
        body at centres of mass ``com`` (nb, 3) [L] and rotations ``rotation`` (nb, 3, 3)."""
        zeros = np.zeros_like(com)  # the laws read no velocity
        out = np.zeros((com.shape[0], 6))
        element_forces(time, np.ascontiguousarray(com), np.ascontiguousarray(rotation), zeros,
                       zeros, self.kinds, self.body_a, self.body_b, self.parameters,
                       self.angle_memory, False, out)
        out[:, 3:] = np.einsum("bij,bj->bi", rotation, out[:, 3:])  # body -> world axes
        return out

    def remember(self, rotation: np.ndarray) -> None:
        """Store the continuous angles after a step (rotations (nb, 3, 3))."""
        remember_angles(np.ascontiguousarray(rotation), self.kinds, self.body_a, self.body_b,
                        self.parameters, self.angle_memory)


def law_forces(scene: Scene) -> LawForces | None:
    """Law loads of ``scene`` (the model's units); None when it has none. ValueError when
    :func:`law_load_problems` finds any."""
    if not any(isinstance(load, AngleLawLoad | DistanceLawLoad) for load in scene.loads):
        return None
    problems = law_load_problems(scene)
    if problems:
        raise ValueError("law loads Exudyn cannot apply: "
                         + "; ".join(reason for _, reason in problems))
    system = build_system(scene)
    keep = np.isin(system.force_kind, LAW_KINDS)
    kinds = np.ascontiguousarray(system.force_kind[keep])
    body_a = np.ascontiguousarray(system.force_body_a[keep])
    body_b = np.ascontiguousarray(system.force_body_b[keep])
    parameters = np.ascontiguousarray(system.force_parameters[keep])
    names = tuple(system.body_names)
    acted = set()
    for load in scene.loads:
        if isinstance(load, AngleLawLoad | DistanceLawLoad):
            acted.update(names.index(a.body) for a in load.applications)
    return LawForces(kinds, body_a, body_b, parameters, names,
                     np.array(sorted(acted), dtype=np.int64))
