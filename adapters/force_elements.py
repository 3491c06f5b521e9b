"""Scene loads as the reference solver's force elements, evaluated from any engine's state.

One implementation of the loads for every engine that applies them as external forces (MuJoCo's
law loads, PyBullet's loads): the scene's loads are packed by
:func:`clearbench.ref_solver.scene_system.build_system` and evaluated by
:func:`clearbench.ref_solver.forces.element_forces`, exactly as the reference engine does. An
engine evaluates them at the state of a step start and holds them during the step (explicit,
one step lag).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from clearbench.ref_solver.forces import element_forces, no_angle_memory, remember_angles
from clearbench.ref_solver.scene_system import build_system, law_load_problems
from clearbench.ref_solver.system import FORCE_ANGLE_LAW, FORCE_DISTANCE_LAW
from clearbench.scenarios.scene import Scene

__all__ = ["LAW_KINDS", "ForceElements", "law_load_problems", "scene_force_elements"]

#: Element kinds of the C-60's law loads (angle and distance laws).
LAW_KINDS = (FORCE_ANGLE_LAW, FORCE_DISTANCE_LAW)


@dataclass
class ForceElements:
    """Loads of a scene as force elements of the reference solver.

    Attributes
    ----------
    kinds, body_a, body_b : (ne,) int arrays
        Element kind and bodies (indices into ``body_names``).
    parameters : (ne, 24) array
        Element parameters (layout in :mod:`clearbench.ref_solver.forces`).
    body_names : tuple of str
        The bodies the indices refer to (the scene's bodies, in scene order).
    angle_memory : (ne, 2) array
        The angle laws' continuous angles at the last :meth:`remember` (NaN: none yet; see
        ``ref_solver.forces.remember_angles``), so that a body turning through the cut of its
        raw angle does not make its law jump by k 2 pi.
    """

    kinds: np.ndarray
    body_a: np.ndarray
    body_b: np.ndarray
    parameters: np.ndarray
    body_names: tuple = ()
    angle_memory: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))

    def __post_init__(self) -> None:
        if self.angle_memory.shape != (self.kinds.shape[0], 2):
            self.angle_memory = no_angle_memory(self.kinds.shape[0])

    def wrenches(self, time: float, com: np.ndarray, rotation: np.ndarray,
                 velocity: np.ndarray | None = None,
                 omega_body: np.ndarray | None = None) -> np.ndarray:
        """(nb, 6): force [F] and moment about the centre of mass [F L], both world axes.

        Parameters
        ----------
        time : float [T]
        com : (nb, 3) centres of mass, world [L]
        rotation : (nb, 3, 3) body-to-world rotations
        velocity : (nb, 3), optional
            Centre-of-mass velocities, world [L/T] (None: zero; law loads read none).
        omega_body : (nb, 3), optional
            Angular velocities, body axes [1/T] (None: zero).
        """
        com = np.ascontiguousarray(com, dtype=float)
        rotation = np.ascontiguousarray(rotation, dtype=float)
        zeros = np.zeros_like(com)
        velocity = zeros if velocity is None else np.ascontiguousarray(velocity, dtype=float)
        omega_body = zeros if omega_body is None else np.ascontiguousarray(omega_body,
                                                                           dtype=float)
        out = np.zeros((com.shape[0], 6))
        element_forces(float(time), com, rotation, velocity, omega_body, self.kinds,
                       self.body_a, self.body_b, self.parameters, self.angle_memory, False, out)
        # element_forces gives moments in body axes; engines want world axes.
        out[:, 3:] = np.einsum("bij,bj->bi", rotation, out[:, 3:])
        return out

    def remember(self, rotation: np.ndarray) -> None:
        """Store the angle laws' continuous angles of the configuration just used."""
        remember_angles(np.ascontiguousarray(rotation, dtype=float), self.kinds, self.body_a,
                        self.body_b, self.parameters, self.angle_memory)


def scene_force_elements(scene: Scene, kinds: tuple | None = None) -> ForceElements | None:
    """The loads of ``scene`` (in its units) as force elements, only those of ``kinds`` when
    given (``ref_solver.system`` FORCE_* constants); None when there are none. ValueError when
    :func:`law_load_problems` finds any."""
    problems = law_load_problems(scene)
    if problems:
        raise ValueError("law loads the shared evaluation cannot apply: "
                         + "; ".join(reason for _, reason in problems))
    if not scene.loads:
        return None
    system = build_system(scene)
    keep = (np.ones(system.force_kind.shape[0], dtype=bool) if kinds is None
            else np.isin(system.force_kind, kinds))
    if not keep.any():
        return None
    return ForceElements(np.ascontiguousarray(system.force_kind[keep]),
                         np.ascontiguousarray(system.force_body_a[keep]),
                         np.ascontiguousarray(system.force_body_b[keep]),
                         np.ascontiguousarray(system.force_parameters[keep]),
                         tuple(system.body_names))
