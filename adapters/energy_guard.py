"""The energy guard every stepping adapter runs: on scenes whose expectations say energy may
only decrease, an energy gain above a fraction of the energy scale stops the run as diverged.

Engine-neutral: the engine computes the mechanical energy of its state
(:func:`clearbench.scenarios.energy.mechanical_energy`: kinetic, gravity, springs) and feeds it
here; this module decides whether the guard applies (not while loads do work that energy does
not count: :data:`~clearbench.scenarios.features.WORK_FEATURES`, and torsional springs for an
engine that cannot measure their angle), keeps the energy scale and words the stop.
"""

from __future__ import annotations

import numpy as np

from clearbench.scenarios.bodies import Motion
from clearbench.scenarios.expectation_kinds import energy_may_not_grow
from clearbench.scenarios.features import WORK_FEATURES
from clearbench.scenarios.scales import largest_shape_dimension
from clearbench.scenarios.scene import Scene

__all__ = ["EnergyGuard"]


class EnergyGuard:
    """Energy-gain guard of one run (energies in the run's internal units).

    Parameters
    ----------
    scene : Scene
        The scene as run (internal units).
    tolerance : float
        Gain above ``tolerance`` x the energy scale stops the run.
    interval : int
        Steps between checks (the engine also checks at every recorded sample).
    counts_torsional_springs : bool
        Whether the engine's energy counts torsional springs (it passes their angles to
        ``mechanical_energy``); if not, they do work it does not count.

    Attributes
    ----------
    applies : bool
        Whether the guard is on for this scene.
    notes : list of str
        Why it is on or off (for the run metadata).
    energy_initial, max_gain : float
        The initial energy [M L^2/T^2] and the largest gain so far relative to the scale.
    """

    def __init__(self, scene: Scene, tolerance: float, interval: int,
                 counts_torsional_springs: bool = True):
        self.tolerance = tolerance
        self.interval = interval
        self.notes: list[str] = []
        self.energy_initial = float("nan")
        self.max_gain = 0.0
        self._kinetic_max = 0.0
        uncounted = WORK_FEATURES if counts_torsional_springs else (*WORK_FEATURES,
                                                                     "torsional_springs")
        self.applies = self._applies(scene, uncounted)
        mass = sum(b.mass for b in scene.bodies if b.motion is not Motion.FIXED)
        gravity = float(np.linalg.norm(np.asarray(scene.gravity, dtype=float)))
        #: sum(m |g|) over the moving bodies x the largest shape dimension [M L^2/T^2].
        self.size_scale = float(mass) * gravity * largest_shape_dimension(scene)

    def _applies(self, scene: Scene, work_features: tuple) -> bool:
        if not any(energy_may_not_grow(e.kind) for e in scene.expectations):
            self.notes.append("energy guard off: no energy expectation")
            return False
        work = sorted(set(work_features) & scene.features)
        if work:
            self.notes.append(f"energy guard off: {', '.join(work)} do uncounted work")
            return False
        self.notes.append(
            f"energy guard on: stops when energy exceeds its initial value by more than "
            f"{self.tolerance:g} x the energy scale (largest kinetic energy so far, at least "
            f"sum(m |g|) x largest shape size), checked every {self.interval} steps and at "
            "every sample")
        return True

    def start(self, total: float, kinetic: float) -> None:
        """The initial (total, kinetic) energy."""
        self.energy_initial = total
        self._kinetic_max = kinetic

    def due(self, step: int) -> bool:
        """True when the guard applies and ``step`` is a checking step."""
        return self.applies and step % self.interval == 0

    def check(self, total: float, kinetic: float, time: float) -> str | None:
        """The stop message when the energy ``total`` (kinetic part ``kinetic``) at ``time``
        [T] gained too much, else None."""
        self._kinetic_max = max(self._kinetic_max, kinetic)
        gain = total - self.energy_initial
        scale = max(self._kinetic_max, self.size_scale, 1e-300)
        self.max_gain = max(self.max_gain, gain / scale)
        if gain > self.tolerance * scale:
            return (f"energy gain {gain:.4g} (internal units) = {gain / scale:.3g} x the energy "
                    f"scale at t = {time:.6g}: above the tolerance {self.tolerance:g} on a "
                    "scene whose energy may only decrease")
        return None
