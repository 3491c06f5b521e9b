"""One toy run as the shared step loop drives it (:mod:`clearbench.adapters.stepping`): a step
of the model, its state and contact forces read out (the scene's own units)."""

from __future__ import annotations

import numpy as np

from clearbench.adapters.stepping import (
    BodyState,
    ContactForces,
    SolverStep,
    StepRunner,
)
from clearbench.scenarios.energy import mechanical_energy, rigid_spring_points


class Runner(StepRunner):
    """Steps, read-out and the toy's own guard of one run."""

    def __init__(self, scene, built, config, steps: int, record_every: int):
        super().__init__(scene, built, config, steps, record_every)
        nc = len(scene.all_contacts)
        self._contacts = ContactForces(np.zeros(nc), np.zeros((nc, 3)), 0)

    def advance(self, step: int) -> None:
        self._contacts = ContactForces(*self.built.step())
        self.time = step * self.dt
        return None

    def solver_step(self, step: int) -> SolverStep:
        return SolverStep(1, True)   # an explicit step: one pass, nothing to converge

    def check(self, step: int) -> str | None:
        if not np.all(np.isfinite(self.built.x)):
            return f"non-finite state at step {step}"
        return None

    def read_state(self) -> BodyState:
        model = self.built
        origins, orientations, velocities, angular_velocities = model.sample()
        return BodyState(origins, orientations, velocities, angular_velocities,
                         model.x.copy(), model.rotations())

    def energy(self, state: BodyState) -> tuple[float, float]:
        energy = mechanical_energy(self.scene, state.centres_of_mass, state.velocities,
                                   state.angular_velocities,
                                   rigid_spring_points(self.scene, state.positions,
                                                       state.rotations))
        return float(energy.total), float(energy.kinetic)

    def contact_forces(self) -> ContactForces:
        return self._contacts
