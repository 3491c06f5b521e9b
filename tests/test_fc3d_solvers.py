"""NSGS and Newton on whole problems: statuses, warm start, sparse input, non-symmetric W; MLCP."""

import dataclasses

import numpy as np
import pytest
import scipy.sparse as sp

from clearbench.ref_solver import (
    ContactProblem,
    SolverOptions,
    SolverStatus,
    natural_map_residual,
    solve_contact_problem,
    solve_mlcp,
)
from clearbench.ref_solver.fc3d_nsgs import bilateral_operator_of


def _random_problem(seed, nc=20, n_bilateral=0, asymmetry=0.0):
    rng = np.random.default_rng(seed)
    m = n_bilateral + 3 * nc
    A = rng.normal(size=(m, m))
    W = A @ A.T / m + 0.2 * np.eye(m) + asymmetry * rng.normal(size=(m, m)) / np.sqrt(m)
    return ContactProblem(W, rng.normal(size=m), rng.uniform(0.1, 0.8, nc), n_bilateral)


ALL_SOLVERS = [("nsgs", "ac"), ("nsgs", "fb"), ("nsgs", "projection"), ("newton", "ac")]


@pytest.mark.parametrize("method,local", ALL_SOLVERS)
@pytest.mark.parametrize("n_bilateral", [0, 4])
def test_solvers_converge_on_random_problems(method, local, n_bilateral):
    problem = _random_problem(1, n_bilateral=n_bilateral)
    options = SolverOptions(method=method, local_solver=local, tolerance=1e-10,
                            max_iterations=5000)
    result = solve_contact_problem(problem, options)
    assert result.converged and result.status is SolverStatus.CONVERGED, result.message
    assert result.residual <= 1e-10
    # the reported residual is the one an independent evaluation gives (same formula: round-off)
    assert natural_map_residual(problem.W, problem.q, problem.mu, result.r, n_bilateral) == \
        pytest.approx(result.residual_max, rel=1e-6, abs=1e-15)
    np.testing.assert_allclose(result.u, problem.W @ result.r + problem.q, atol=1e-12)


@pytest.mark.parametrize("method,local", [("nsgs", "ac"), ("newton", "ac")])
def test_non_symmetric_W(method, local):
    # |W - W^T| ~ 0.1 |W|, more than Capsules' 1e-2
    problem = _random_problem(2, asymmetry=0.3)
    W = problem.W
    assert np.abs(W - W.T).max() > 0.05 * np.abs(W).max()
    result = solve_contact_problem(problem, SolverOptions(method=method, local_solver=local,
                                                          tolerance=1e-10))
    assert result.converged, result.message


@pytest.mark.parametrize("method", ["nsgs", "newton"])
def test_iteration_cap_returns_a_status_without_raising(method):
    problem = _random_problem(3, nc=40)
    result = solve_contact_problem(
        problem, SolverOptions(method=method, tolerance=1e-15, max_iterations=2))
    assert not result.converged
    assert result.status is SolverStatus.MAX_ITERATIONS
    assert result.iterations == 2
    assert "residual" in result.message
    assert np.all(np.isfinite(result.r))


def test_tolerance_applies_to_the_requested_normalisation():
    problem = _random_problem(4)
    for normalisation in ("q", "max"):
        result = solve_contact_problem(problem, SolverOptions(tolerance=1e-6,
                                                              normalisation=normalisation))
        expected = result.residual_q if normalisation == "q" else result.residual_max
        assert result.residual == expected <= 1e-6
    assert result.residual_max <= result.residual_q  # max(|q|,|r|,|u|) >= |q|


def test_warm_start_from_a_solution_needs_one_sweep():
    problem = _random_problem(5)
    options = SolverOptions(tolerance=1e-10)
    first = solve_contact_problem(problem, options)
    again = solve_contact_problem(problem, options, r0=first.r)
    assert first.iterations > 1
    assert again.converged and again.iterations == 1


def test_bilateral_operator_is_computed_once_per_problem():
    problem = _random_problem(7, nc=5, n_bilateral=3)
    operator = bilateral_operator_of(problem)
    for method in ("nsgs", "newton"):
        assert solve_contact_problem(problem, SolverOptions(method=method)).converged
    assert bilateral_operator_of(problem) is operator  # shared by every solve of the problem
    problem.forget_derived()
    recomputed = bilateral_operator_of(problem)
    assert recomputed is not operator
    np.testing.assert_array_equal(recomputed, operator)  # same computation: bitwise equal
    # W_bb >= 0.2 I (well conditioned): the operator is its inverse to round-off
    np.testing.assert_allclose(operator @ problem.W[:3, :3], np.eye(3), atol=1e-10)


def test_solver_result_stays_frozen_and_replaceable():
    result = solve_contact_problem(_random_problem(8, nc=3), SolverOptions())
    with pytest.raises(dataclasses.FrozenInstanceError):
        result.iterations = 0
    changed = dataclasses.replace(result, iterations=99)
    assert changed.iterations == 99 and changed.status is result.status
    # residual checked every sweep by default: one history entry per sweep
    assert changed.history is result.history and result.history.size == result.iterations


def test_sparse_and_dense_W_give_the_same_answer():
    problem = _random_problem(6)
    sparse_problem = ContactProblem(sp.csr_matrix(problem.W), problem.q, problem.mu)
    for method in ("nsgs", "newton"):
        options = SolverOptions(method=method, tolerance=1e-12)
        dense = solve_contact_problem(problem, options)
        sparse = solve_contact_problem(sparse_problem, options)
        np.testing.assert_allclose(sparse.r, dense.r, atol=1e-10)  # both within 1e-12 relative


def test_singular_bilateral_block_uses_minimum_norm_impulses():
    # two identical bilateral rows (a redundant joint constraint): W_bb singular
    rng = np.random.default_rng(8)
    J = rng.normal(size=(4, 6))
    J[1] = J[0]
    W = J @ J.T + 1e-16 * np.eye(4)
    problem = ContactProblem(W, np.array([0.3, 0.3, -1.0, 0.2]), [], n_bilateral=4)
    result = solve_contact_problem(problem, SolverOptions(tolerance=1e-10))
    assert result.converged, result.message
    assert result.r[0] == pytest.approx(result.r[1], rel=1e-8)  # minimum-norm split


def test_problem_validation_rejects_bad_input():
    with pytest.raises(ValueError, match="size mismatch"):
        ContactProblem(np.eye(6), np.zeros(6), [0.3])
    with pytest.raises(ValueError, match="mu"):
        ContactProblem(np.eye(3), np.zeros(3), [-0.1])
    with pytest.raises(ValueError, match="NaN"):
        ContactProblem(np.eye(3), [np.nan, 0, 0], [0.1])
    with pytest.raises(ValueError, match="method"):
        SolverOptions(method="lemke")


# ---- MLCP ------------------------------------------------------------------------------------

def _mlcp_problem(seed, n=30, n_equality=6):
    rng = np.random.default_rng(seed)
    A = rng.normal(size=(n, n))
    return A @ A.T / n + 0.5 * np.eye(n), rng.normal(size=n), n_equality


def test_mlcp_solution_satisfies_the_conditions():
    A, b, ne = _mlcp_problem(1)
    result = solve_mlcp(A, b, ne, tolerance=1e-12, max_iterations=20000)
    assert result.converged, result.message
    z, w = result.z, result.w
    scale = max(np.linalg.norm(b), np.linalg.norm(z))
    # residual 1e-12 of the scale bounds each condition to a few times that
    assert np.all(np.abs(w[:ne]) <= 1e-11 * scale)
    assert np.all(z[ne:] >= 0.0)
    assert np.all(w[ne:] >= -1e-11 * scale)
    assert np.all(np.abs(z[ne:] * w[ne:]) <= 1e-11 * scale ** 2)
    assert np.any(z[ne:] > 0.0) and np.any(w[ne:] > 1e-6)  # both regimes present


def test_mlcp_pure_equality_is_a_linear_solve():
    A, b, _ = _mlcp_problem(2, n=8)
    result = solve_mlcp(A, b, 8)
    assert result.converged and result.iterations == 1
    np.testing.assert_allclose(result.z, np.linalg.solve(A, -b), rtol=1e-10)


def test_mlcp_cap_and_warm_start():
    A, b, ne = _mlcp_problem(3)
    capped = solve_mlcp(A, b, ne, tolerance=1e-14, max_iterations=1)
    assert not capped.converged and capped.status is SolverStatus.MAX_ITERATIONS
    solved = solve_mlcp(A, b, ne, tolerance=1e-10, max_iterations=20000)
    warm = solve_mlcp(A, b, ne, tolerance=1e-10, z0=solved.z)
    assert warm.converged and warm.iterations == 1


def test_frictionless_take_off_has_zero_residual():
    # mu = 0: the cone is the ray r_T = 0, r_N >= 0. A separating contact (q_N > 0) has the
    # solution r = 0, u = q, whose natural-map residual is exactly 0 (it was reported as 1
    # when (-q_N, 0, 0) was wrongly taken for a point of the degenerate cone).
    from clearbench.ref_solver import (
        ContactProblem,
        SolverOptions,
        natural_map_residual,
        solve_contact_problem,
    )

    W = np.diag([1.0, 3.5, 3.5])
    q = np.array([0.5, 0.0, 0.0])
    mu = np.array([0.0])
    assert natural_map_residual(W, q, mu, np.zeros(3)) == 0.0
    for method in ("nsgs", "newton"):
        result = solve_contact_problem(ContactProblem(W, q, mu), SolverOptions(method=method))
        assert result.converged
        assert np.array_equal(result.r, np.zeros(3))
