"""Speed of the compiled kernels, called directly (they measure and report, they assert nothing).

- :func:`fc3d_sweep_costs` (``clearbench bench fc3d-sweep``): microseconds of one NSGS sweep
  per contact on the shipped FCLIB problems, with the residual checked after the last sweep
  only and after every sweep (the solver's default), for each local solver;
- :func:`pair_contacts_costs` (``clearbench bench geometry``): nanoseconds per
  :func:`~clearbench.scenarios.geometry.pair_contacts` call, measured from inside a numba loop
  (run with ``NUMBA_NUM_THREADS=1``).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
from numba import njit

from clearbench.harness.fclib.problems import (
    UnsupportedProblemError,
    load_problem,
    shipped_problem_files,
)
from clearbench.kernels.quaternion import quat_from_axis_angle, quat_to_matrix
from clearbench.ref_solver import ContactProblem, SolverOptions, solve_contact_problem
from clearbench.scenarios import geometry as G

#: Local solvers of the NSGS sweep benchmark.
LOCAL_SOLVERS = ("ac", "fb", "projection")


@dataclass(frozen=True)
class SweepCost:
    """Cost of one NSGS sweep on one problem with one local solver [us per contact]."""

    problem: str
    contacts: int
    nonzeros_per_row: float     # of W
    local_solver: str
    sweep_only: float           # residual evaluated after the last sweep only
    with_check: float           # residual evaluated after every sweep


def time_sweeps(problem: ContactProblem, sweeps: int, check_interval: int, local: str,
                repeat: int) -> float:
    """Fastest wall time [s] per sweep of up to ``sweeps`` NSGS sweeps from zero, the whole
    call timed (tiny problems include the Python call overhead).

    The tolerance is out of reach, so exactly ``sweeps`` sweeps are done, unless a problem is
    solved exactly (residual 0) and stops early: the time is divided by the sweeps done.
    """
    options = SolverOptions(tolerance=1e-300, max_iterations=sweeps, local_solver=local,
                            residual_check_interval=check_interval)
    best = np.inf
    for _ in range(repeat):
        start = time.perf_counter()
        result = solve_contact_problem(problem, options)
        best = min(best, (time.perf_counter() - start) / result.iterations)
    return best


def fc3d_sweep_costs(sweeps: int = 200, repeat: int = 5) -> list[SweepCost]:
    """Per shipped FCLIB problem and local solver: the fastest of ``repeat`` runs of ``sweeps``
    sweeps, per sweep and per contact [us] (the target is <= 5 us per contact per sweep)."""
    warm = load_problem(shipped_problem_files()[0]).problem
    for local in LOCAL_SOLVERS:  # compile the kernels before timing
        time_sweeps(warm, 2, 1, local, 1)
    rows = []
    for path in shipped_problem_files():
        try:
            problem = load_problem(path).problem
        except UnsupportedProblemError:
            continue
        scale = 1e6 / problem.n_contacts
        for local in LOCAL_SOLVERS:
            only = time_sweeps(problem, sweeps, sweeps, local, repeat)
            check = time_sweeps(problem, sweeps, 1, local, repeat)
            rows.append(SweepCost(path.name, problem.n_contacts,
                                  problem.W_csr().nnz / problem.size, local, only * scale,
                                  check * scale))
    return rows


@njit  # not cached: numba cache keys ignore edits of the kernels it calls
def _pair_contacts_loop(calls, kind_a, params_a, position_a, rotation_a, kind_b, params_b,
                        position_b, rotation_b, jitter):
    """Call pair_contacts ``calls`` times, moving shape B by a tiny amount every call (so that
    nothing is hoisted out of the loop) and summing the gaps (so that nothing is removed)."""
    gap = np.empty(G.MAX_CONTACTS_PER_PAIR)
    point_a = np.empty((G.MAX_CONTACTS_PER_PAIR, 3))
    point_b = np.empty((G.MAX_CONTACTS_PER_PAIR, 3))
    frame = np.empty((G.MAX_CONTACTS_PER_PAIR, 3, 3))
    moved = position_b.copy()
    total = 0.0
    for i in range(calls):
        moved[0] = position_b[0] + jitter * (i & 1023)
        count = G.pair_contacts(kind_a, params_a, position_a, rotation_a, kind_b, params_b,
                                moved, rotation_b, gap, point_a, point_b, frame)
        for k in range(count):
            total += gap[k]
    return total


def _rotation(axis, angle):
    return quat_to_matrix(quat_from_axis_angle(np.asarray(axis, float), angle))


def _parameters(*values):
    packed = np.zeros(G.PARAMETER_COUNT)
    packed[: len(values)] = values
    return packed


def pair_contacts_cases():
    """(name, shape A, shape B, jitter [L]) of each case; a shape is (kind, parameters,
    position, rotation matrix)."""
    identity = np.eye(3)
    tilt = _rotation((1.0, 0.3, 0.0), math.radians(0.5))
    yield ("circle-cylinder, bearing (e = 0.6 c, tilt 0.5 deg)",
           (G.CIRCLE, _parameters(10.0), np.array([0.03, 0.045, 2.0]), tilt),
           (G.CYLINDER, _parameters(9.9, 5.0), np.zeros(3), identity), 1e-9)
    yield ("circle-cylinder, centred journal, tilt 5 deg (quartic path)",
           (G.CIRCLE, _parameters(10.0), np.array([1e-6, 0.0, 2.0]),
            _rotation((1.0, 0.3, 0.0), math.radians(5.0))),
           (G.CYLINDER, _parameters(9.9, 5.0), np.zeros(3), identity), 1e-12)
    yield ("arc-cylinder, bearing half ring",
           (G.ARC, _parameters(10.0, 0.0, math.pi), np.array([0.03, 0.045, 2.0]), tilt),
           (G.CYLINDER, _parameters(9.9, 5.0), np.zeros(3), identity), 1e-9)
    yield ("box-plane (8 corners)",
           (G.PLANE, _parameters(), np.zeros(3), identity),
           (G.BOX, _parameters(0.5, 0.3, 0.2), np.array([0.0, 0.0, 0.2]),
            _rotation((1.0, 2.0, 3.0), 0.3)), 1e-9)
    yield ("plane-box swapped order (box on A)",
           (G.BOX, _parameters(0.5, 0.3, 0.2), np.array([0.0, 0.0, 0.2]),
            _rotation((1.0, 2.0, 3.0), 0.3)),
           (G.PLANE, _parameters(), np.zeros(3), identity), 1e-9)
    yield ("box-box resting stack (4 clipped points)",
           (G.BOX, _parameters(1.0, 1.0, 0.5), np.zeros(3), identity),
           (G.BOX, _parameters(0.3, 0.2, 0.1), np.array([0.1, 0.2, 0.6]),
            _rotation((0.0, 0.0, 1.0), 0.5)), 1e-9)
    yield ("sphere-plane",
           (G.PLANE, _parameters(), np.zeros(3), identity),
           (G.SPHERE, _parameters(0.5), np.array([0.0, 0.0, 0.5]), identity), 1e-9)
    yield ("arc-plane (flange ring)",
           (G.PLANE, _parameters(), np.zeros(3), identity),
           (G.ARC, _parameters(2.0, 0.0, math.pi), np.array([0.0, 0.0, 0.0]),
            _rotation((1.0, 0.0, 0.0), math.pi / 2)), 1e-9)


def pair_contacts_costs(calls: int = 200_000, repeats: int = 5) -> list[tuple[str, float]]:
    """(case, nanoseconds per call) of each case of :func:`pair_contacts_cases`: the best of
    ``repeats`` compiled loops of ``calls`` calls."""
    rows = []
    for name, a, b, jitter in pair_contacts_cases():
        _pair_contacts_loop(10, *a, *b, jitter)  # compile
        best = math.inf
        for _ in range(repeats):
            start = time.perf_counter()
            _pair_contacts_loop(calls, *a, *b, jitter)
            best = min(best, time.perf_counter() - start)
        rows.append((name, best / calls * 1e9))
    return rows
