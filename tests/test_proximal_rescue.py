"""The hybrid chain's proximal-point rescue (ref_solver/fc3d_proximal.py,
``StepperSettings.proximal_rescue``) on a problem the chain leaves unconverged.

The fixture is the contact problem of ``c60-trip``'s step 16240 at 1 us (its last activation
round; written by ``python -m tools.unconverged_steps c60-trip --save FILE``): 1 bilateral row
and 17 contacts (52 rows), a Delassus operator of numerical rank 43 (the bearing rings'
redundant contacts), the warm start the step had. Every attempt of the chain ends above the
tolerance 1e-12 (the best, Newton from the warm start, at 4.9e-8 after its 200 iterations).
"""

from __future__ import annotations

from dataclasses import replace

import pytest

from clearbench.adapters.base import RunSettings
from clearbench.adapters.options import OptionError
from clearbench.adapters.reference.engine import create
from clearbench.ref_solver.fc3d_residual import natural_map_residual
from clearbench.scenarios.library import get_scene

from .unconverged_problem import compiled_solve, load_problem, reference_stepper

#: The chain's tolerance on the relative natural-map residual (the reference's default).
TOLERANCE = 1e-12
#: The relative proximal weight measured on c60-trip's four unconverged problems (2-4 outer
#: iterations each): ``docs/reference-solver-speed.md``.
WEIGHT = 1e-8


@pytest.fixture(scope="module")
def problem():
    return load_problem()


def _stepper(weight: float):
    """A reference stepper with the default preset and ``proximal_rescue`` = ``weight``."""
    return reference_stepper(proximal_rescue=weight)


@pytest.mark.parametrize("weight", [0.0, WEIGHT])
def test_the_python_chain_converges_with_the_rescue_only(problem, weight):
    contact_problem, r0 = problem
    result = _stepper(weight)._solve(contact_problem, r0)
    # The residual is evaluated again here, independently of the solver's own test.
    residual = natural_map_residual(contact_problem.W, contact_problem.q, contact_problem.mu,
                                    result.r, contact_problem.n_bilateral)
    if weight == 0.0:
        assert not result.converged and residual > TOLERANCE
    else:
        assert result.converged and result.method == "proximal newton"
        assert residual <= TOLERANCE


@pytest.mark.parametrize("weight", [0.0, WEIGHT])
def test_the_compiled_chain_converges_with_the_rescue_only(problem, weight):
    contact_problem, r0 = problem
    r, _, residual, converged = compiled_solve(_stepper(weight), contact_problem, r0)
    independent = natural_map_residual(contact_problem.W, contact_problem.q,
                                       contact_problem.mu, r, contact_problem.n_bilateral)
    assert converged == (weight > 0.0)
    assert (independent <= TOLERANCE) == (weight > 0.0)


def test_a_negative_weight_is_refused_naming_the_option():
    with pytest.raises(OptionError, match="proximal_rescue"):
        create("default").run_settings(get_scene("pendulum"), RunSettings(
            options={"proximal_rescue": -1.0}))


def test_the_default_rescues_with_the_measured_weight_and_zero_turns_it_off():
    scene = get_scene("pendulum")
    settings = create("default").run_settings(scene, RunSettings())
    assert settings.proximal_rescue == WEIGHT
    off = create("default").run_settings(scene, RunSettings(options={"proximal_rescue": 0}))
    assert off.proximal_rescue == 0.0
    assert replace(settings, proximal_rescue=0.0).proximal_rescue == 0.0
