"""The reference's two iteration caps set by option: the hybrid chain's two last attempts (NSGS
from zero and from its first NSGS's end) run for ``StepperSettings.hybrid_last_sweeps`` sweeps,
in both step loops; the projection's Gauss–Newton stops at ``max_projection_iterations``.

On the C-60 problem that every other attempt of the chain leaves unconverged (the fixture of
``tests/unconverged_problem.py``: ``c60-trip``'s step 16240 at 1 us, rank 43 of 52 rows; the
proximal rescue turned off so that the chain reaches its last attempts), neither cap converges
it, and the run pays the cap: that is the measured reason of the default of 100
(docs/reference-solver-speed.md, "Choosing the contact solve on recorded problems").
"""

from __future__ import annotations

import pytest

from clearbench.adapters.base import RunSettings
from clearbench.adapters.options import OptionError
from clearbench.adapters.reference.engine import create
from clearbench.harness.measure import series
from clearbench.ref_solver.compiled.system_arrays import compile_system
from clearbench.ref_solver.fc3d_residual import natural_map_residual
from clearbench.ref_solver.stepper import StepperSettings
from clearbench.scenarios.library import get_scene

from .unconverged_problem import compiled_solve, load_problem, reference_stepper

#: The reference's default tolerance on the relative natural-map residual.
TOLERANCE = 1e-12


@pytest.fixture(scope="module")
def problem():
    return load_problem()


def _stepper(last_sweeps: int | None, **options):
    options = {"proximal_rescue": 0.0, **options}
    if last_sweeps is not None:
        options["hybrid_last_sweeps"] = last_sweeps
    return reference_stepper(**options)


CAPS = pytest.mark.parametrize("name", ["hybrid_last_sweeps", "max_projection_iterations"])


@CAPS
def test_the_default_is_100_and_the_option_sets_it(name):
    assert getattr(_stepper(None).settings, name) == 100
    assert getattr(_stepper(None, **{name: 10_000}).settings, name) == 10_000
    # The compiled loop's settings carry the same caps.
    assert getattr(compile_system(_stepper(None, **{name: 7}))[1], name) == 7


@CAPS
@pytest.mark.parametrize("value", [0, -5, 2.5])
def test_a_bad_cap_is_refused_naming_the_option(name, value):
    with pytest.raises(OptionError, match=name):
        create("default").run_settings(get_scene("pendulum"), RunSettings(
            options={name: value}))
    with pytest.raises(ValueError, match=name):
        StepperSettings(time_step=1e-3, **{name: value})


def test_both_loops_run_the_last_attempts_to_the_cap(problem):
    """With the cap at 100 against 10,000 the chain costs 2 x 9,900 sweeps fewer at most and
    leaves the problem unconverged either way (checked by the residual evaluated again);
    both step loops agree on the iterations."""
    contact_problem, r0 = problem
    iterations = {}
    for cap in (100, 10_000):
        stepper = _stepper(cap)
        python = stepper._solve(contact_problem, r0)
        r, compiled_iterations, _, converged = compiled_solve(stepper, contact_problem, r0)
        assert not python.converged and not converged
        for result in (python.r, r):
            residual = natural_map_residual(contact_problem.W, contact_problem.q,
                                            contact_problem.mu, result,
                                            contact_problem.n_bilateral)
            assert residual > TOLERANCE
        assert python.iterations == compiled_iterations
        iterations[cap] = compiled_iterations
    # Both NSGS attempts run to their cap here (neither converges): the difference is theirs.
    assert iterations[10_000] - iterations[100] == 2 * (10_000 - 100)


def test_the_projection_cap_lets_lever_7_99_converge_at_the_coarsest_step():
    """``c60-trip`` of ``lever-7.99`` at 16 us (the coarsest step of the C-60's ladder), past
    10.1 ms: there the velocity stage leaves a violation of hundredths of a mm and the
    projection's Gauss-Newton, reducing it by 3-50 % per iteration while its active set
    changes, needs tens of iterations before its convergence turns quadratic
    (docs/reference-solver.md, "The projection's bound": with the kernel before the plunger's
    bearing was read against the finite plunger, step 633 reached the former cap of 30 at
    3.3e-4 mm). At the default cap every projection of the run converges and every pair stays
    within 1e-6 mm, the scene's no-penetration limit (1e-13 mm measured); with a cap of 20
    projections there fail (from step 636 on this kernel; a cap of 30 now suffices), none
    before 9.6 ms. About 20 s (two runs of 638 steps)."""
    scene = get_scene("c60-trip", variant="lever-7.99")
    unconverged = {}
    for cap in (None, 20):
        options = {} if cap is None else {"max_projection_iterations": cap}
        trajectory = create().run(scene, RunSettings(time_step=0.016, horizon=10.2,
                                                     record_every=1, options=options))
        unconverged[cap] = list(trajectory.metadata["unconverged_projections"])
        if cap is None:
            assert series.penetration(scene, trajectory).max() <= 1e-6
    assert unconverged[None] == []
    # The cap is what converges them: a lower one fails at the hard place (step 600 = 9.6 ms).
    assert unconverged[20], "a cap of 20 converges every projection: the test shows nothing"
    assert min(unconverged[20]) > 600, unconverged[20]
