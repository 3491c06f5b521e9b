"""Law loads (angle and distance laws) in MuJoCo: evaluated by the reference solver's own force
function from the MuJoCo state at the start of every step and applied through ``xfrc_applied``.

The evaluation is the shared one (:mod:`clearbench.adapters.force_elements`); this module maps
it onto MuJoCo's bodies. The force acts at the start-of-step configuration during the whole
step (explicit, one step lag). Law loads depend on the configuration only (angles, a
distance), not on velocities.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from clearbench.adapters.force_elements import (
    LAW_KINDS,
    ForceElements,
    law_load_problems,
    scene_force_elements,
)
from clearbench.scenarios.scene import Scene

__all__ = ["LAW_KINDS", "LawForces", "law_forces", "law_load_problems"]


@dataclass
class LawForces:
    """The law loads of a scene on the bodies of a MuJoCo model.

    Attributes
    ----------
    elements : ForceElements
        The law loads as force elements (indices in scene body order).
    body_ids : (nb,) int array
        MuJoCo body id of each body of the scene (in ``scene.expanded.bodies`` order).
    """

    elements: ForceElements
    body_ids: np.ndarray

    def _pose(self, data) -> tuple[np.ndarray, np.ndarray]:
        """Centres of mass (nb, 3) and rotations (nb, 3, 3) of the scene's bodies in ``data``."""
        ids = self.body_ids
        return (np.ascontiguousarray(data.xipos[ids]),
                np.ascontiguousarray(data.xmat[ids].reshape(-1, 3, 3)))

    def wrenches(self, data, time: float = 0.0) -> np.ndarray:
        """(nb, 6) force [F] and moment about the centre of mass [F L], both in world axes, of
        every body at the configuration in ``data`` (xipos and xmat must be current)."""
        return self.elements.wrenches(time, *self._pose(data))

    def apply(self, data) -> None:
        """Add the law wrenches to ``data.xfrc_applied`` (applied at each centre of mass)."""
        x, rotation = self._pose(data)
        np.add.at(data.xfrc_applied, self.body_ids,
                  self.elements.wrenches(float(data.time), x, rotation))
        self.elements.remember(rotation)


def law_forces(scene: Scene, model) -> LawForces | None:
    """Law loads of ``scene`` (the model's internal units) for the compiled ``model``; None
    when the scene has none. ValueError when :func:`law_load_problems` finds any."""
    elements = scene_force_elements(scene, LAW_KINDS)
    if elements is None:
        return None
    body_ids = np.array([model.body(name).id for name in elements.body_names], dtype=np.int64)
    return LawForces(elements, body_ids)
