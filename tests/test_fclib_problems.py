"""Readers of FCLIB / Siconos files, and our solvers on every shipped FCLIB problem.

Every acceptance here is on |F| / |q| (the normalisation of the FCLIB comparison paper), at
1e-8, unless a problem is documented as hard in harness/data/fclib/RESULTS.md.
"""

import numpy as np
import pytest
import scipy.sparse as sp

from clearbench.harness.fclib.problems import (
    UnsupportedProblemError,
    condense_global,
    load_problem,
    shipped_problem_dir,
    shipped_problem_files,
)
from clearbench.ref_solver import SolverOptions, SolverStatus, solve_contact_problem

DATA = shipped_problem_dir()
TOL = 1e-8

# Problems with their sizes as read (contacts), and whether our NSGS-AC reaches TOL on |F|/|q|
# within 20000 sweeps. The two that do not are documented in RESULTS.md; for them the test
# asserts the residual NSGS actually reaches (measured 1.46e-5 and 1.79e-4 after 20000 sweeps,
# the same plateau as Siconos's NSGS-AC) with a factor 2 margin for round-off in the long run.
PROBLEMS = {
    "Box_Stacks-i0122-82-5.hdf5": (82, None),
    "BoxesStack1-i100000-32.hdf5.dat": (52, 3e-5),
    "Capsules-i125-1213.hdf5": (286, None),
    "CubeH8.hdf5": (1, None),
    "LMGC_100_PR_PerioBox-i00361-60-03000.hdf5": (60, None),
    "LMGC_GlobalFrictionContactProblem00046.hdf5": (9, None),
    "OneObject-i1028-138.hdf5.dat": (23, None),
    "Spheres-i099-356-679.hdf5": (356, None),
    "local_problem_test.hdf5": (48, 4e-4),
}


def test_all_shipped_files_are_listed_with_license_and_attribution():
    names = {path.name for path in shipped_problem_files()}
    assert names == set(PROBLEMS) | {"Chute-ndof-768-nc-4-3.hdf5"}
    assert (DATA / "LICENSE").is_file() and "Apache" in (DATA / "LICENSE").read_text()
    assert "siconos" in (DATA / "README.md").read_text().lower()


def test_rolling_friction_problem_is_reported_unsupported():
    with pytest.raises(UnsupportedProblemError, match="rolling"):
        load_problem(DATA / "Chute-ndof-768-nc-4-3.hdf5")


@pytest.mark.parametrize("name", sorted(PROBLEMS))
def test_readers_give_consistent_problems(name):
    loaded = load_problem(DATA / name)
    problem = loaded.problem
    assert problem.n_contacts == PROBLEMS[name][0]
    assert problem.size == 3 * problem.n_contacts
    assert np.all(problem.mu >= 0.0)
    W = problem.W_dense()
    # Delassus operators are positive semidefinite: symmetric part >= -round-off * |W|
    eigenvalues = np.linalg.eigvalsh(0.5 * (W + W.T))
    assert eigenvalues.min() >= -1e-10 * np.abs(eigenvalues).max()


def test_condensation_of_a_global_problem_by_hand():
    rng = np.random.default_rng(0)
    M = np.diag(rng.uniform(1.0, 2.0, 6))
    M[0, 1] = M[1, 0] = 0.1
    H = rng.normal(size=(6, 3))
    f, w = rng.normal(size=6), rng.normal(size=3)
    W, q = condense_global(sp.csr_matrix(M), sp.csr_matrix(H), f, w)
    Minv = np.linalg.inv(M)
    np.testing.assert_allclose(W.toarray(), H.T @ Minv @ H, rtol=1e-12)
    np.testing.assert_allclose(q, H.T @ Minv @ f + w, rtol=1e-12)


def test_siconos_text_reader_on_a_dense_file(tmp_path):
    W = np.arange(36.0).reshape(6, 6) + 10.0 * np.eye(6)
    q = np.arange(6.0) - 3.0
    mu = np.array([0.3, 0.5])
    values = " ".join(str(v) for v in W.ravel(order="F"))  # Siconos dense: column-major
    text = f"3\n2\n0\n6\n6\n{values}\n{' '.join(map(str, q))}\n{' '.join(map(str, mu))}\n"
    (tmp_path / "p.dat").write_text(text)
    problem = load_problem(tmp_path / "p.dat").problem
    np.testing.assert_array_equal(problem.W_dense(), W)
    np.testing.assert_array_equal(problem.q, q)
    np.testing.assert_array_equal(problem.mu, mu)


@pytest.mark.parametrize("name", sorted(PROBLEMS))
def test_nsgs_with_exact_local_solver_on_shipped_problems(name):
    problem = load_problem(DATA / name).problem
    hard_bound = PROBLEMS[name][1]
    result = solve_contact_problem(problem, SolverOptions(
        method="nsgs", local_solver="ac", tolerance=TOL, normalisation="q",
        max_iterations=20_000))
    assert np.all(np.isfinite(result.r))
    if hard_bound is None:
        assert result.converged, result.message
        assert result.residual_q <= TOL
    else:
        assert result.status is SolverStatus.MAX_ITERATIONS
        assert result.residual_q <= hard_bound


@pytest.mark.parametrize("name", sorted(PROBLEMS))
def test_newton_solves_every_shipped_problem(name):
    # including the two NSGS cannot solve
    problem = load_problem(DATA / name).problem
    result = solve_contact_problem(problem, SolverOptions(
        method="newton", tolerance=TOL, normalisation="q", max_iterations=500))
    assert result.converged, result.message
    assert result.residual_q <= TOL


def test_single_projection_variant_stalls_on_capsules():
    # FCLIB's README: plain projected Gauss-Seidel stalls on Capsules; measured 3.6e-3 after
    # 100000 sweeps and ~4e-3 after 2000, far above 1e-8 where the exact local solver gets.
    problem = load_problem(DATA / "Capsules-i125-1213.hdf5").problem
    result = solve_contact_problem(problem, SolverOptions(
        local_solver="projection", tolerance=TOL, normalisation="q", max_iterations=2000))
    assert not result.converged
    assert result.residual_q > 1e-4


@pytest.mark.slow
@pytest.mark.parametrize("name", ["BoxesStack1-i100000-32.hdf5.dat", "local_problem_test.hdf5"])
def test_nsgs_plateau_on_the_hard_problems(name):
    # 100000 sweeps: measured 1.27e-6 and 7.0e-6 (Siconos NSGS-AC: the same figures)
    problem = load_problem(DATA / name).problem
    result = solve_contact_problem(problem, SolverOptions(
        tolerance=TOL, normalisation="q", max_iterations=100_000))
    assert not result.converged
    assert result.residual_q < {"BoxesStack1-i100000-32.hdf5.dat": 3e-6,
                                "local_problem_test.hdf5": 2e-5}[name]
