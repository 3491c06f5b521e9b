"""The compiled kernels of the reference step against the Python/numpy paths they replace.

Bounds are relative to each problem's scale: the two paths do the same arithmetic in another
order (BLAS against loops), so they agree to a few ulps per operation, amplified at most by the
conditioning of what they solve.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from clearbench.adapters.base import RunSettings
from clearbench.adapters.reference.build import build_system, initial_state
from clearbench.adapters.reference.engine import create
from clearbench.ref_solver import ContactProblem, SolverOptions, natural_map_residual
from clearbench.ref_solver.dense_kernels import lu_solve, roundoff_floor_dense
from clearbench.ref_solver.fc3d_newton import solve_newton
from clearbench.ref_solver.fc3d_residual import roundoff_floor
from clearbench.ref_solver.projection import solve_projection
from clearbench.ref_solver.projection_kernel import active_set_multipliers
from clearbench.ref_solver.step_kernels import cluster_inverse
from clearbench.ref_solver.stepper import MoreauJeanStepper
from clearbench.scenarios.library import get_scene

EPS = np.finfo(float).eps


def _problem(seed, nc=12, n_bilateral=0, rank=None):
    """Random problem; with ``rank`` W = H H^T / rank has that rank (redundant contacts)."""
    rng = np.random.default_rng(seed)
    m = n_bilateral + 3 * nc
    if rank is None:
        A = rng.normal(size=(m, m))
        W = A @ A.T / m + 0.2 * np.eye(m)
    else:
        H = rng.normal(size=(m, rank))
        W = H @ H.T / rank
    return ContactProblem(W, rng.normal(size=m), rng.uniform(0.1, 0.8, nc), n_bilateral)


NEWTON = SolverOptions(method="newton", tolerance=1e-10, max_iterations=200,
                       roundoff_floor=True)


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("n_bilateral", [0, 4])
def test_compiled_newton_follows_the_python_driver_on_regular_problems(seed, n_bilateral):
    problem = _problem(seed, n_bilateral=n_bilateral)
    compiled = solve_newton(problem, NEWTON, compiled=True)
    python = solve_newton(problem, NEWTON, compiled=False)
    assert compiled.converged and python.converged
    assert compiled.iterations == python.iterations
    # cond(W) <= 1 + 5 / 0.2 here, and both stop at a residual <= 1e-10 of the scale of r
    scale = max(np.abs(python.r).max(), 1.0)
    np.testing.assert_allclose(compiled.r, python.r, rtol=0, atol=1e-7 * scale)
    np.testing.assert_allclose(compiled.u, problem.W @ compiled.r + problem.q,
                               atol=1e3 * EPS * scale * np.abs(problem.W).max())


@pytest.mark.parametrize("seed", range(5))
def test_compiled_newton_follows_the_python_driver_on_redundant_problems(seed):
    # 36 rows of rank 12, as redundant bearing rings: r is not unique, u = W r + q is
    problem = _problem(seed, rank=12)
    compiled = solve_newton(problem, NEWTON, compiled=True)
    python = solve_newton(problem, NEWTON, compiled=False)
    assert compiled.converged == python.converged
    if python.converged:
        scale = max(np.abs(python.u).max(), np.abs(problem.q).max())
        np.testing.assert_allclose(compiled.u, python.u, rtol=0, atol=1e-6 * scale)


def test_compiled_newton_reports_a_cap_as_the_python_driver_does():
    problem = _problem(3)
    options = SolverOptions(method="newton", tolerance=1e-30, max_iterations=2)
    compiled = solve_newton(problem, options, compiled=True)
    python = solve_newton(problem, options, compiled=False)
    assert not compiled.converged and compiled.status is python.status
    assert compiled.iterations == python.iterations == 2
    assert compiled.message.split(",")[0] == python.message.split(",")[0]
    assert len(compiled.history) == len(python.history) == 2


@pytest.mark.parametrize("seed", range(4))
def test_lu_solve_matches_numpy(seed):
    rng = np.random.default_rng(seed)
    A = rng.normal(size=(30, 30))
    b = rng.normal(size=30)
    x = np.empty(30)
    assert lu_solve(A.copy(), b, x)
    reference = np.linalg.solve(A, b)
    condition = np.linalg.cond(A)
    np.testing.assert_allclose(x, reference, atol=100 * condition * EPS * np.abs(reference).max())


def test_lu_solve_refuses_a_zero_pivot():
    assert not lu_solve(np.zeros((3, 3)), np.ones(3), np.empty(3))


def test_roundoff_floor_dense_matches_the_numpy_bound():
    problem = _problem(1)
    r = np.random.default_rng(0).normal(size=problem.size)
    u = problem.W @ r + problem.q
    for use_max in (True, False):
        expected = roundoff_floor(np.abs(problem.W), r, u, problem.q, problem.mu, use_max)
        assert roundoff_floor_dense(problem.W, r, u, problem.q, problem.mu, use_max) == \
            pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize("seed", range(8))
def test_active_set_multipliers_match_the_numpy_active_set(seed):
    rng = np.random.default_rng(seed)
    m, rank, n_equal = 14, 9, 3  # redundant rows, as two bearing rings
    H = rng.normal(size=(m, rank))
    W = H @ H.T
    b = rng.normal(size=m) * 1e-3
    tolerance = 1e-12
    reference = solve_projection(W, b, n_equal, tolerance)
    delta, converged = active_set_multipliers(W, b, n_equal, tolerance, 50)
    assert converged == reference.converged
    # the correction H^T delta (and so W delta) is unique even where delta is not
    scale = np.abs(b).max()
    np.testing.assert_allclose(W @ delta + b, reference.w, atol=1e-9 * scale)


def test_cluster_inverse_inverts_each_block_and_zeroes_fixed_bodies():
    rng = np.random.default_rng(2)
    matrix = np.zeros((18, 18))
    for block in (slice(0, 12), slice(12, 18)):
        A = rng.normal(size=(block.stop - block.start,) * 2)
        matrix[block, block] = A @ A.T + np.eye(block.stop - block.start)
    dofs = np.arange(18, dtype=np.int64)
    out = cluster_inverse(matrix, dofs, np.array([0, 12, 18], dtype=np.int64),
                          np.array([False, False, True]))
    np.testing.assert_allclose(out[:12, :12], np.linalg.inv(matrix[:12, :12]), rtol=1e-12,
                               atol=1e-14)
    assert not out[12:].any() and not out[:, 12:].any()


@pytest.mark.parametrize("scene_name", ["clearance-pendulum", "slider-crank"])
def test_compiled_projection_follows_the_numpy_projection(scene_name):
    scene = get_scene(scene_name)
    settings = create().run_settings(scene, RunSettings())
    runs = {}
    for compiled in (True, False):
        stepper = MoreauJeanStepper(build_system(scene), settings)
        stepper.compiled_projection = compiled
        state = initial_state(scene)
        positions = []
        for _ in range(40):
            state = stepper.step(state).state
            positions.append(state.x.copy())
        runs[compiled] = np.array(positions)
    # same arithmetic in another order: round-off, not amplified within 40 steps
    scale = max(np.abs(runs[False]).max(), 1e-3)
    np.testing.assert_allclose(runs[True], runs[False], rtol=0, atol=1e-12 * scale)


@pytest.mark.parametrize("seed", range(5))
def test_least_norm_newton_solves_redundant_problems(seed):
    # 36 rows of rank 12: the singular W of redundant bearing rings
    problem = _problem(seed, rank=12)
    options = dataclasses.replace(NEWTON, newton_direction="least_norm")
    result = solve_newton(problem, options)
    assert result.converged, result.message
    assert natural_map_residual(problem.W, problem.q, problem.mu, result.r) == \
        pytest.approx(result.residual, rel=1e-6, abs=1e-15)


def test_newton_direction_is_validated():
    with pytest.raises(ValueError, match="newton_direction"):
        SolverOptions(method="newton", newton_direction="steepest")
