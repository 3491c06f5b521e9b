"""Building a reference run: the scene's array form, the stepper, the initial state and the
compiled kernels of the loop that steps it (numba compiles on first use in a process, or loads
its cache: compilation counts as building, never as stepping)."""

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


def build(scene: Scene, config: StepperSettings, python_step: bool = True) -> ReferenceModel:
    """``scene`` as a :class:`ReferenceModel` stepped with ``config``; with ``python_step``
    the Python step's kernels compiled (:func:`warm_python_step`). A run of the compiled loop
    does not call them (it compiles its own: ``adapters.reference.run.choose_step_loop``)."""
    system = build_system(scene)
    model = ReferenceModel(system, MoreauJeanStepper(system, config), initial_state(scene))
    if python_step:
        warm_python_step(model)
    return model


def warm_python_step(model: ReferenceModel) -> None:
    """Compile (or load) every kernel of the Python step (:meth:`MoreauJeanStepper.step`) for
    ``model``: :func:`warm_up`, then one untimed step of a copy of its initial state by a
    stepper of its own (the model's stepper and state are untouched)."""
    warm_up()
    MoreauJeanStepper(model.system, model.stepper.settings).step(model.state.copy())


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
