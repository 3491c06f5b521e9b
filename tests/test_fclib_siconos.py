"""Our residual, reader and solvers against Siconos 4.4 (Debian python3-siconos) itself.

Skipped when Siconos cannot be imported by /usr/bin/python3 (install: `make siconos` as root).
"""

import numpy as np
import pytest

from clearbench.adapters.siconos import run as siconos_run
from clearbench.adapters.siconos.fc3d import (
    siconos_compute_error,
    siconos_read_text_file,
    solve_with_siconos,
)
from clearbench.harness.fclib.problems import load_problem, shipped_problem_dir
from clearbench.ref_solver import natural_map_residual

DATA = shipped_problem_dir()
LOCAL_AND_CONDENSED = [
    "Box_Stacks-i0122-82-5.hdf5",
    "BoxesStack1-i100000-32.hdf5.dat",
    "Capsules-i125-1213.hdf5",
    "LMGC_100_PR_PerioBox-i00361-60-03000.hdf5",
    "LMGC_GlobalFrictionContactProblem00046.hdf5",
    "OneObject-i1028-138.hdf5.dat",
    "Spheres-i099-356-679.hdf5",
    "local_problem_test.hdf5",
]

needs_siconos = pytest.mark.skipif(not siconos_run.siconos_available(),
                                   reason="Debian's python3-siconos is not installed")


@needs_siconos
@pytest.mark.siconos
@pytest.mark.parametrize("name", LOCAL_AND_CONDENSED)
def test_our_residual_equals_siconos_fc3d_compute_error(name):
    problem = load_problem(DATA / name).problem
    rng = np.random.default_rng(0)
    # a non-solution at the problem's scale, so that |F| carries no cancellation: then the
    # same formula in double precision on both sides agrees to 1e-12 relative (near a
    # solution, the different summation orders of W r would dominate the tiny |F|)
    scale = np.linalg.norm(problem.q) / np.sqrt(problem.size)
    r = scale * rng.normal(size=problem.size)
    theirs = siconos_compute_error(problem, r)
    ours = natural_map_residual(problem.W, problem.q, problem.mu, r, normalisation="max")
    assert ours == pytest.approx(theirs, rel=1e-12)


@needs_siconos
@pytest.mark.siconos
@pytest.mark.parametrize("name", ["OneObject-i1028-138.hdf5.dat",
                                  "BoxesStack1-i100000-32.hdf5.dat"])
def test_our_siconos_text_reader_matches_siconos(name):
    theirs = siconos_read_text_file(DATA / name)
    ours = load_problem(DATA / name).problem
    # both parse the same decimal text: bitwise equal up to the last printed digit
    np.testing.assert_allclose(ours.W_dense(), theirs["W"], rtol=1e-15, atol=0.0)
    np.testing.assert_array_equal(ours.q, theirs["q"])
    np.testing.assert_array_equal(ours.mu, theirs["mu"])


@needs_siconos
@pytest.mark.siconos
@pytest.mark.parametrize("solver", ["siconos-nsgs-ac", "siconos-nsn-ac"])
def test_siconos_solvers_answer_through_the_worker(solver):
    problem = load_problem(DATA / "Spheres-i099-356-679.hdf5").problem
    result = solve_with_siconos(problem, solver, tolerance=1e-8, max_iterations=2000)
    assert result.status == "ok" and result.converged, result.message
    assert result.storage == "sparse-block"
    ours = natural_map_residual(problem.W, problem.q, problem.mu, result.r, normalisation="max")
    assert ours == pytest.approx(result.error, rel=1e-8)  # Siconos's error is ours (max norm)
    assert ours <= 1e-8
    # wall_time adds the allocation of r and u to the fc3d_driver call, fastest of each
    assert 0.0 < result.driver_time <= result.wall_time
    assert result.solves == 1  # repeat 1 and no minimum time by default


def test_missing_siconos_is_reported_not_raised(monkeypatch):
    monkeypatch.setattr(siconos_run, "SICONOS_PYTHON", "/nonexistent/python3")
    siconos_run.siconos_availability.cache_clear()
    try:
        problem = load_problem(DATA / "OneObject-i1028-138.hdf5.dat").problem
        result = solve_with_siconos(problem, "siconos-nsgs-ac")
        assert result.status == "unavailable"
        assert "unavailable" in result.message
    finally:
        siconos_run.siconos_availability.cache_clear()
