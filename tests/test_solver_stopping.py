"""When the one-step solvers stop short of the tolerance: the round-off floor and the stall window.

``SolverOptions.roundoff_floor`` accepts a residual that is below the bound on its own
rounding error; ``SolverOptions.stall_window`` stops a solve whose rate of progress cannot
reach the tolerance within its cap. Both are off by default and on in the reference stepper.
"""

import dataclasses
import math

import numpy as np
import pytest

from clearbench.ref_solver import (
    ContactProblem,
    SolverOptions,
    SolverStatus,
    natural_map_residual,
    solve_contact_problem,
)
from clearbench.ref_solver.contact_problem import Normalisation
from clearbench.ref_solver.fc3d_residual import hopeless, roundoff_floor


def _sticking_problem(seed: int, condition: float):
    """A problem (m = 4 bilateral rows + 3 nc contact rows) with a known solution r* at which
    every contact sticks (r* inside its cone, u = 0): q = -W r* rounded once from an exactly
    rounded dot product, so r* solves the problem up to that rounding of q."""
    rng = np.random.default_rng(seed)
    nc, nb = int(rng.integers(2, 20)), 4
    m = nb + 3 * nc
    basis, _ = np.linalg.qr(rng.normal(size=(m, m)))
    W = basis @ np.diag(np.geomspace(1.0, 1.0 / condition, m)) @ basis.T
    W = 0.5 * (W + W.T) * 10.0 ** rng.uniform(-3, 3)  # any unit of velocity per impulse
    mu = rng.uniform(0.1, 0.8, nc)
    r = rng.normal(size=m) * 10.0 ** rng.uniform(-3, 3)
    for i in range(nc):
        k = nb + 3 * i
        r[k] = abs(r[k]) + 1e-3
        r[k + 1:k + 3] *= 0.9 * mu[i] * r[k] / max(np.hypot(r[k + 1], r[k + 2]), 1e-300)
    q = -np.array([math.fsum(W[row] * r) for row in range(m)])
    return ContactProblem(W, q, mu, nb), r


@pytest.mark.parametrize("condition", [1e2, 1e8, 1e14])
def test_the_exact_solution_passes_the_roundoff_floor(condition):
    # The property the floor must have: at the exact solution, whose residual is zero in exact
    # arithmetic, the computed residual never exceeds the floor (it is a worst-case bound).
    for seed in range(200):
        problem, exact = _sticking_problem(seed, condition)
        u = problem.W @ exact + problem.q
        for normalisation in Normalisation:
            computed = natural_map_residual(problem.W, problem.q, problem.mu, exact,
                                            problem.n_bilateral, normalisation)
            floor = roundoff_floor(np.abs(problem.W), exact, u, problem.q, problem.mu,
                                   normalisation is Normalisation.MAX)
            assert computed <= floor, (seed, computed, floor)
            # ... and it is a rounding bound, not a loose tolerance: (m + 1) eps (1 + mu) times
            # |W| |r| / |r| at most, i.e. below 1e-12 for these m <= 61 and |W| <= 1e3 |r|/|u|
            assert floor < 1e-11


@pytest.mark.parametrize("method", ["nsgs", "newton"])
def test_an_unreachable_tolerance_is_met_at_round_off_only_when_asked(method):
    # NSGS tests the floor when its sweeps run out (Newton at every iteration): the cap
    # leaves it time to reach round-off on this well-conditioned problem
    problem, _ = _sticking_problem(7, 10.0)
    impossible = SolverOptions(method=method, tolerance=1e-300, max_iterations=3000)
    plain = solve_contact_problem(problem, impossible)
    assert not plain.converged  # NSGS: MAX_ITERATIONS; Newton: STALLED (its line search)
    floored = solve_contact_problem(problem, dataclasses.replace(impossible,
                                                                 roundoff_floor=True))
    assert floored.converged and floored.status is SolverStatus.CONVERGED
    assert "round-off" in floored.message
    floor = roundoff_floor(np.abs(problem.W), floored.r, floored.u, problem.q, problem.mu,
                           True)
    assert 1e-300 < floored.residual <= floor


def test_hopeless_extrapolates_the_mean_rate():
    # 1e-2 -> 1e-3 over 10 iterations: 10 more per decade, 90 to reach 1e-12
    assert not hopeless(1e-2, 1e-3, 10, 1e-12, left=90)
    assert hopeless(1e-2, 1e-3, 10, 1e-12, left=89)
    assert hopeless(1e-3, 1e-3, 10, 1e-12, left=10**9)    # no progress at all
    assert hopeless(1e-3, 2e-3, 10, 1e-12, left=10**9)    # going up
    assert not hopeless(1e-3, 1e-13, 10, 1e-12, left=0)   # already there


def _crawling_problem():
    """8 frictional contacts on one rigid body (W = H H^T of rank 6 < 24 rows), all pressed:
    the redundancy of the C-60's bearing rings, on which NSGS crawls (measured: residual
    1.0e-3 after 3000 sweeps, 1.5e-4 after 20,000)."""
    rng = np.random.default_rng(1)
    nc = 8
    H = rng.normal(size=(3 * nc, 6))
    q = rng.normal(size=3 * nc)
    q[0::3] = -np.abs(q[0::3]) - 1.0
    return ContactProblem(H @ H.T, q, np.full(nc, 0.3))


def test_stall_window_stops_a_crawling_nsgs_early_and_says_why():
    problem = _crawling_problem()
    options = SolverOptions(tolerance=1e-12, max_iterations=20_000)
    capped = solve_contact_problem(problem, options)
    assert capped.status is SolverStatus.MAX_ITERATIONS and capped.iterations == 20_000
    stopped = solve_contact_problem(problem, dataclasses.replace(options, stall_window=100))
    assert stopped.status is SolverStatus.STALLED and not stopped.converged
    assert stopped.iterations < 20_000 and "would not reach" in stopped.message
    # it stopped because the extrapolation said so: at the rate of its last 100 sweeps the
    # sweeps left would not have reached the tolerance
    history = stopped.history
    assert hopeless(history[-101], history[-1], 100, 1e-12, 20_000 - stopped.iterations)
    assert not hopeless(history[-102], history[-2], 100, 1e-12,
                        20_000 - stopped.iterations + 1)


@pytest.mark.parametrize("method", ["nsgs", "newton"])
def test_stall_window_changes_nothing_on_a_solve_that_converges(method):
    rng = np.random.default_rng(1)
    nc, m = 20, 60
    A = rng.normal(size=(m, m))
    problem = ContactProblem(A @ A.T / m + 0.2 * np.eye(m), rng.normal(size=m),
                             rng.uniform(0.1, 0.8, nc))
    plain = solve_contact_problem(problem, SolverOptions(method=method, tolerance=1e-10))
    windowed = solve_contact_problem(problem, SolverOptions(method=method, tolerance=1e-10,
                                                            stall_window=5))
    assert plain.converged and windowed.converged
    assert windowed.iterations == plain.iterations
    np.testing.assert_array_equal(windowed.r, plain.r)


def test_stall_window_is_validated():
    with pytest.raises(ValueError, match="stall_window"):
        SolverOptions(stall_window=-1)
    with pytest.raises(ValueError, match="stall_after"):
        SolverOptions(stall_after=-1)


def test_stall_after_delays_the_early_stop():
    problem = _crawling_problem()
    options = SolverOptions(tolerance=1e-12, max_iterations=20_000, stall_window=100)
    early = solve_contact_problem(problem, options)
    late = solve_contact_problem(problem, dataclasses.replace(options, stall_after=5000))
    assert early.status is late.status is SolverStatus.STALLED
    assert early.iterations < 5000 <= late.iterations


def test_reference_engine_uses_the_floor_by_default_and_counts_its_steps():
    from clearbench.adapters.base import RunSettings
    from clearbench.adapters.reference.engine import create
    from clearbench.scenarios.library import get_scene

    scene = get_scene("incline-stick")
    engine = create()
    assert engine.run_settings(scene, RunSettings()).solver.roundoff_floor
    plain = engine.run_settings(scene, RunSettings(options={"roundoff_floor": False}))
    assert not plain.solver.roundoff_floor
    with pytest.raises(ValueError, match="roundoff_floor"):
        engine.run_settings(scene, RunSettings(options={"roundoff_floor": "no"}))
    # A tolerance no residual can meet: the box's four contacts (a redundant set) converge on
    # the floor, and the run says how many steps did.
    short = RunSettings(time_step=1e-3, horizon=0.05, options={"tolerance": 1e-300})
    trajectory = engine.run(scene, short)
    assert trajectory.solver_converged.all()
    assert trajectory.metadata["roundoff_steps"] > 0
