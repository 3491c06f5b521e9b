"""Building a reference run: the scene's array form, the stepper, the initial state and the
compiled kernels (numba compiles on first use in a process, or loads its cache: compilation
counts as building, never as stepping)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from clearbench.ref_solver import ContactProblem, solve_contact_problem
from clearbench.ref_solver.contact_problem import SolverOptions
from clearbench.ref_solver.scene_system import build_system, initial_state
from clearbench.ref_solver.stepper import MoreauJeanStepper, StepperSettings
from clearbench.ref_solver.system import MultibodySystem, State
from clearbench.scenarios.library import get_scene
from clearbench.scenarios.scene import Scene

#: Small library scenes whose first steps take every code path of the stepper (contacts,
#: Newton fall-back, projection, joints, drivers, springs).
WARM_UP_SCENES = ("clearance-pendulum", "slider-crank", "stiff-spring", "box-grid")


@dataclass
class ReferenceModel:
    """A scene ready to step: its array form, the stepper and the state at t = 0."""

    system: MultibodySystem
    stepper: MoreauJeanStepper
    state: State


def build(scene: Scene, config: StepperSettings) -> ReferenceModel:
    """``scene`` as a :class:`ReferenceModel` stepped with ``config``, every kernel compiled
    (one untimed step of a copy of the initial state)."""
    system = build_system(scene)
    stepper = MoreauJeanStepper(system, config)
    state = initial_state(scene)
    warm_up()
    MoreauJeanStepper(system, config).step(state.copy())
    return ReferenceModel(system, stepper, state)


_WARM = False


def warm_up() -> None:
    """Run every code path of the stepper once in this process, on small scenes, untimed."""
    global _WARM
    if _WARM:
        return
    _WARM = True
    for method in ("nsgs", "newton"):
        solve_contact_problem(ContactProblem(np.eye(3), np.array([-1.0, 0.5, 0.0]), [0.3]),
                              SolverOptions(method=method))
    for name in WARM_UP_SCENES:
        scene = get_scene(name)
        stepper = MoreauJeanStepper(build_system(scene), StepperSettings(scene.time_step))
        state = initial_state(scene)
        for _ in range(5):
            state = stepper.step(state).state
