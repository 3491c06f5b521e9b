"""The C-60's law loads (angle and distance laws) in Exudyn.

One implementation of the laws: the shared
:class:`~clearbench.adapters.force_elements.ForceElements` (the reference solver's own force
elements, compiled with numba), as the reference, MuJoCo and PyBullet adapters use them. Each
body acted on gets one ``LoadForceVector`` at its centre of mass and one ``LoadTorqueVector``
(world axes). Two modes (option ``law_loads``):

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

import numpy as np

from clearbench.adapters.force_elements import LAW_KINDS, ForceElements, scene_force_elements
from clearbench.scenarios.loads import AngleLawLoad, DistanceLawLoad
from clearbench.scenarios.scene import Scene

__all__ = ["law_forces"]


def law_forces(scene: Scene) -> tuple[ForceElements, np.ndarray] | None:
    """The law loads of ``scene`` (the model's units) as force elements, and the sorted indices
    (na,) of the bodies some law acts on (into ``elements.body_names``; the other bodies get no
    Exudyn load); None when it has none. ValueError when
    :func:`~clearbench.adapters.force_elements.law_load_problems` finds any."""
    elements = scene_force_elements(scene, LAW_KINDS)
    if elements is None:
        return None
    names = elements.body_names
    acted = {names.index(application.body) for load in scene.loads
             if isinstance(load, AngleLawLoad | DistanceLawLoad)
             for application in load.applications}
    return elements, np.array(sorted(acted), dtype=np.int64)
