"""Law loads (angle and distance laws) in MuJoCo: evaluated by the reference solver's own force
function from the MuJoCo state at the start of every step and applied through ``xfrc_applied``.

One implementation of the laws: the scene's law loads are packed into force elements by
:func:`clearbench.ref_solver.scene_system.build_system` and evaluated by
:func:`clearbench.ref_solver.forces.element_forces`, exactly as the reference engine does. The
force acts at the start-of-step configuration during the whole step (explicit, one step lag).
Law loads depend on the configuration only (angles, a distance), not on velocities.
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
        Element kind and the two law bodies (indices into ``body_ids``).
    parameters : (ne, 24) array
        Element parameters (layout in :mod:`clearbench.ref_solver.forces`).
    body_ids : (nb,) int array
        MuJoCo body id of each body of the scene (in ``scene.expanded.bodies`` order).
    angle_memory : (ne, 2) array
        The angle laws' continuous angles at the last :meth:`apply` (NaN: none yet; see
        ``ref_solver.forces.remember_angles``), so that a body turning through the cut of its
        raw angle does not make its law jump by k 2 pi.
    """

    kinds: np.ndarray
    body_a: np.ndarray
    body_b: np.ndarray
    parameters: np.ndarray
    body_ids: np.ndarray
    angle_memory: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))

    def __post_init__(self) -> None:
        if self.angle_memory.shape != (self.kinds.shape[0], 2):
            self.angle_memory = no_angle_memory(self.kinds.shape[0])

    def _pose(self, data) -> tuple[np.ndarray, np.ndarray]:
        """Centres of mass (nb, 3) and rotations (nb, 3, 3) of the scene's bodies in ``data``."""
        ids = self.body_ids
        return (np.ascontiguousarray(data.xipos[ids]),
                np.ascontiguousarray(data.xmat[ids].reshape(-1, 3, 3)))

    def wrenches(self, data, time: float = 0.0) -> np.ndarray:
        """(nb, 6) force [F] and moment about the centre of mass [F L], both in world axes, of
        every body at the configuration in ``data`` (xipos and xmat must be current)."""
        return self._wrenches(*self._pose(data), time)

    def _wrenches(self, x: np.ndarray, rotation: np.ndarray, time: float) -> np.ndarray:
        ids = self.body_ids
        zeros = np.zeros_like(x)  # the laws read no velocity
        out = np.zeros((len(ids), 6))
        element_forces(time, x, rotation, zeros, zeros, self.kinds, self.body_a, self.body_b,
                       self.parameters, self.angle_memory, False, out)
        # element_forces gives moments in body axes; xfrc_applied wants world axes.
        out[:, 3:] = np.einsum("bij,bj->bi", rotation, out[:, 3:])
        return out

    def apply(self, data) -> None:
        """Add the law wrenches to ``data.xfrc_applied`` (applied at each centre of mass)."""
        x, rotation = self._pose(data)
        np.add.at(data.xfrc_applied, self.body_ids, self._wrenches(x, rotation, float(data.time)))
        remember_angles(rotation, self.kinds, self.body_a, self.body_b, self.parameters,
                        self.angle_memory)


def law_forces(scene: Scene, model) -> LawForces | None:
    """Law loads of ``scene`` (the model's internal units) for the compiled ``model``; None
    when the scene has none. ValueError when :func:`law_load_problems` finds any."""
    if not any(isinstance(load, AngleLawLoad | DistanceLawLoad) for load in scene.loads):
        return None
    problems = law_load_problems(scene)
    if problems:
        raise ValueError("law loads MuJoCo cannot apply: "
                         + "; ".join(reason for _, reason in problems))
    system = build_system(scene)
    keep = np.isin(system.force_kind, LAW_KINDS)
    body_ids = np.array([model.body(name).id for name in system.body_names], dtype=np.int64)
    return LawForces(np.ascontiguousarray(system.force_kind[keep]),
                     np.ascontiguousarray(system.force_body_a[keep]),
                     np.ascontiguousarray(system.force_body_b[keep]),
                     np.ascontiguousarray(system.force_parameters[keep]), body_ids)
