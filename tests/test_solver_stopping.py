"""When the one-step solvers stop short of the tolerance: the round-off floor and the stall window.

``SolverOptions.roundoff_floor`` accepts a residual that is below the bound on its own
rounding error; ``SolverOptions.stall_window`` stops a solve whose rate of progress cannot
reach the tolerance within its cap. Both are off by default and on in the reference stepper.
"""

import dataclasses
import math

import numpy as np
import pytest

from clearbench.adapters.base import RunSettings
from clearbench.adapters.reference.build import build
from clearbench.adapters.reference.engine import create
from clearbench.ref_solver import (
    ContactProblem,
    SolverOptions,
    SolverStatus,
    natural_map_residual,
    solve_contact_problem,
)
from clearbench.ref_solver.compiled import contact_solve
from clearbench.ref_solver.compiled.system_arrays import compile_system
from clearbench.ref_solver.contact_problem import Normalisation, _dense_to_csr
from clearbench.ref_solver.dense_kernels import bilateral_operator_dense
from clearbench.ref_solver.fc3d_residual import hopeless, roundoff_floor
from clearbench.scenarios.library import get_scene


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
    # NSGS tests the floor at every residual check, Newton at every iteration: the cap leaves
    # both time to reach round-off on this well-conditioned problem
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


def test_nsgs_stops_at_the_first_sweep_within_its_floor():
    # The C-60's hybrid chain at 4 us: NSGS's warm start is already at its round-off floor,
    # 2e-12 against a tolerance of 1e-12, and sweeping on to the cap (100) changed nothing but
    # the cost. With the floor tested at every check, NSGS stops at the first sweep whose
    # residual is within it: one sweep fewer is still above it.
    problem, _ = _sticking_problem(7, 10.0)
    scene = get_scene("pendulum")  # any scene: only the solver settings are read
    stepper = build(scene, create("default").run_settings(scene, RunSettings()),
                    python_step=False).stepper
    floored_options = dataclasses.replace(stepper.settings.solver, method="nsgs",
                                          tolerance=1e-300, max_iterations=3000,
                                          roundoff_floor=True)
    floored = solve_contact_problem(problem, floored_options)
    assert floored.converged and "round-off" in floored.message
    assert 1 < floored.iterations < floored_options.max_iterations
    earlier = solve_contact_problem(problem, dataclasses.replace(
        floored_options, max_iterations=floored.iterations - 1))
    assert not earlier.converged
    # The compiled loop's NSGS (ref_solver.compiled.contact_solve) stops at the same sweep
    # with the same impulses to round-off: one kernel decides for both loops, which build W's
    # CSR arrays and the bilateral block's inverse by different routines. The bound: a few
    # hundred eps of |r| for this problem of 61 rows and condition 10 (m eps cond = 1.4e-13).
    _, cfg = compile_system(stepper)
    cfg = cfg._replace(tolerance=1e-300, max_iterations=3000, roundoff_floor=True)
    W = np.ascontiguousarray(problem.W)
    nb = np.int64(problem.n_bilateral)
    r, sweeps, _, converged = contact_solve._nsgs(
        _dense_to_csr(W), problem.q, problem.mu, nb, bilateral_operator_dense(W, nb),
        np.zeros(problem.q.size), 3000, cfg, np.empty(3000))
    assert converged and sweeps == floored.iterations
    assert np.abs(r - floored.r).max() <= 1e-12 * np.abs(floored.r).max()


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
