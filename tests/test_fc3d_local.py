"""Residual, cone projection and one-contact solvers on hand-made problems with known answers."""

import math

import numpy as np
import pytest

from clearbench.ref_solver import ContactProblem, SolverOptions, natural_map_residual
from clearbench.ref_solver import solve_contact_problem as solve
from clearbench.ref_solver.fc3d_local import (
    AC,
    FB,
    LOCAL_OK,
    PROJECTION,
    local_residual,
    make_local_workspace,
    solve_local,
)
from clearbench.ref_solver.fc3d_residual import project_on_cone

# Round-off bound for problems whose entries are O(1): a few hundred ulps.
ROUND_OFF = 1e-13


def _in_cone(x, mu, slack=1e-12):
    return math.hypot(x[1], x[2]) <= mu * x[0] + slack


@pytest.mark.parametrize("mu", [0.0, 0.3, 1.0, 2.5])
def test_cone_projection_is_the_euclidean_projection(mu):
    rng = np.random.default_rng(1)
    for x in rng.normal(size=(200, 3)):
        p = np.array(project_on_cone(x[0], x[1], x[2], mu))
        assert _in_cone(p, mu)
        # Moreau decomposition: x - p in the polar cone and orthogonal to p (round-off bound)
        d = x - p
        assert abs(d @ p) <= ROUND_OFF * (1.0 + x @ x)
        assert mu * math.hypot(d[1], d[2]) <= -d[0] + 1e-12
        p2 = np.array(project_on_cone(p[0], p[1], p[2], mu))
        np.testing.assert_allclose(p2, p, atol=ROUND_OFF)


# One contact, W = I: the three regimes with their exact answers.
TAKE_OFF = dict(q=[1.0, 0.3, -0.2], mu=0.5, r=[0.0, 0.0, 0.0])
STICK = dict(q=[-2.0, 0.2, 0.0], mu=0.5, r=[2.0, -0.2, 0.0])  # |r_T| = 0.2 <= 0.5 * 2
SLIDE = dict(q=[-1.0, 2.0, 0.0], mu=0.5, r=[1.0, -0.5, 0.0])  # u_T = (1.5, 0), r_T = -mu r_N e


@pytest.mark.parametrize("case", [TAKE_OFF, STICK, SLIDE], ids=["take-off", "stick", "slide"])
def test_residual_vanishes_at_known_solutions_and_not_elsewhere(case):
    W = np.eye(3)
    mu = np.array([case["mu"]])
    r = np.array(case["r"])
    assert natural_map_residual(W, case["q"], mu, r) <= ROUND_OFF
    assert natural_map_residual(W, case["q"], mu, r, normalisation="q") <= ROUND_OFF
    assert natural_map_residual(W, case["q"], mu, r + [0.1, 0.0, 0.0]) > 1e-3


def test_residual_value_and_both_normalisations_by_hand():
    # W = I, q = (-2, 0, 0), r = 0: u = q, û = q, r - û = (2, 0, 0) in K, F = (-2, 0, 0).
    W, q, mu, r = np.eye(3), np.array([-2.0, 0.0, 0.0]), np.array([0.3]), np.zeros(3)
    assert natural_map_residual(W, q, mu, r, normalisation="q") == pytest.approx(1.0, rel=1e-15)
    # max(|q| = 2, |r| = 0, |u| = 2) = 2 as well
    assert natural_map_residual(W, q, mu, r, normalisation="max") == pytest.approx(1.0, rel=1e-15)
    # r = (4, 0, 0): u = (2, 0, 0), r - û = (2, 0, 0), F = (2, 0, 0); max(2, 4, 2) = 4
    r = np.array([4.0, 0.0, 0.0])
    assert natural_map_residual(W, q, mu, r, normalisation="q") == pytest.approx(1.0, rel=1e-15)
    assert natural_map_residual(W, q, mu, r, normalisation="max") == pytest.approx(0.5, rel=1e-15)


def test_residual_with_zero_q_is_unnormalised():
    W, q, mu = np.eye(3), np.zeros(3), np.array([0.3])
    assert natural_map_residual(W, q, mu, np.zeros(3), normalisation="q") == 0.0
    assert natural_map_residual(W, q, mu, np.zeros(3), normalisation="max") == 0.0
    # r = (1,0,0): u = r, û = r, r - û = 0, F = r: |F| = 1, |q| = 0 -> returned as is
    assert natural_map_residual(W, q, mu, np.array([1.0, 0, 0]), normalisation="q") == 1.0


def test_bilateral_rows_contribute_their_velocity():
    W = np.eye(4)
    q = np.array([0.5, 1.0, 0.0, 0.0])
    r = np.zeros(4)
    # bilateral F = u_b = 0.5; contact: take-off, F = 0. |q| = sqrt(1.25)
    value = natural_map_residual(W, q, [0.3], r, n_bilateral=1, normalisation="q")
    assert value == pytest.approx(0.5 / math.sqrt(1.25), rel=1e-15)


@pytest.mark.parametrize("kind", [AC, FB])
@pytest.mark.parametrize("case", [TAKE_OFF, STICK, SLIDE], ids=["take-off", "stick", "slide"])
def test_local_solver_finds_the_known_answer(kind, case):
    vec, mat = make_local_workspace()
    r = np.zeros(3)
    code = solve_local(kind, np.eye(3), np.array(case["q"]), case["mu"], r, 1e-14, 30, vec, mat)
    assert code == LOCAL_OK
    np.testing.assert_allclose(r, case["r"], atol=1e-12)  # exact answers are O(1)


def _random_block(rng, symmetric):
    A = rng.normal(size=(3, 3))
    W = A @ A.T + 0.5 * np.eye(3)
    if not symmetric:
        W = W + 0.3 * rng.normal(size=(3, 3))  # |W - W^T| ~ 0.3 |W|: still positive definite
        W += 2.0 * np.eye(3)
    return W


@pytest.mark.parametrize("kind", [AC, FB])
@pytest.mark.parametrize("symmetric", [True, False])
def test_local_solver_on_random_blocks_reaches_round_off(kind, symmetric):
    rng = np.random.default_rng(7 + kind + 2 * symmetric)
    vec, mat = make_local_workspace()
    for _ in range(300):
        W = _random_block(rng, symmetric)
        q = rng.normal(size=3)
        mu = rng.uniform(0.05, 1.5)
        r = np.zeros(3)
        code = solve_local(kind, W, q, mu, r, 1e-13, 30, vec, mat)
        u = W @ r + q
        # the local tolerance is the requested one, 1e-13 of max(|q|, |r|, |u|)
        assert code == LOCAL_OK
        assert local_residual(r, u, q, mu) <= 1e-13


def test_projection_kind_takes_exactly_one_step():
    vec, mat = make_local_workspace()
    r = np.zeros(3)
    q = np.array([-1.0, 2.0, 0.0])
    solve_local(PROJECTION, 2.0 * np.eye(3), q, 0.5, r, 1e-14, 30, vec, mat)
    # rho = 1 / W_NN = 0.5: r - rho (u + [mu |u_T|, 0, 0]) = -0.5 * (-1 + 1, 2, 0) = (0, -1, 0)
    expected = np.array(project_on_cone(0.0, -1.0, 0.0, 0.5))
    np.testing.assert_allclose(r, expected, atol=ROUND_OFF)


def _known_solution_problem(rng, n_bilateral, with_states=True):
    """A problem built backwards from a chosen solution (one contact of each regime)."""
    nc = 3
    m = n_bilateral + 3 * nc
    A = rng.normal(size=(m, m))
    W = A @ A.T / m + 2.0 * np.eye(m)  # well conditioned: the solution is unique for small mu
    mu = np.array([0.3, 0.3, 0.3])
    r = np.zeros(m)
    u = np.zeros(m)
    r[:n_bilateral] = rng.normal(size=n_bilateral)
    k = n_bilateral
    r[k:k + 3] = [0.0, 0.0, 0.0]  # take-off
    u[k:k + 3] = [0.7, -0.2, 0.4]
    k += 3
    r[k:k + 3] = [1.0, 0.1, -0.1]  # stick, |r_T| = 0.14 < 0.3
    k += 3
    r[k:k + 3] = [2.0, 0.6 * 0.6, 0.6 * 0.8]  # slide, |r_T| = 0.6 = mu r_N
    u[k:k + 3] = [0.0, -0.6 * 1.5, -0.8 * 1.5]  # u_T opposite to r_T
    q = u - W @ r
    return ContactProblem(W, q, mu, n_bilateral=n_bilateral), r, u


@pytest.mark.parametrize("method,local", [("nsgs", "ac"), ("nsgs", "fb"), ("newton", "ac")])
@pytest.mark.parametrize("n_bilateral", [0, 2])
def test_solvers_recover_a_known_solution_with_bilateral_rows(method, local, n_bilateral):
    problem, r_star, u_star = _known_solution_problem(np.random.default_rng(3), n_bilateral)
    result = solve(problem, SolverOptions(method=method, local_solver=local, tolerance=1e-13,
                                          max_iterations=5000))
    assert result.converged, result.message
    # the residual bound 1e-13 (relative to |r| ~ 2) bounds the error of r through W^-1 ~ 0.5
    np.testing.assert_allclose(result.r, r_star, atol=1e-11)
    np.testing.assert_allclose(result.u, u_star, atol=1e-11)
    assert np.all(np.abs(result.u[:n_bilateral]) <= 1e-11)
