"""Nanoseconds per ``pair_contacts`` call, measured from inside a numba loop.

Run: ``NUMBA_NUM_THREADS=1 .venv/bin/python benchmarks/bench_geometry.py``

Each case calls the compiled kernel ``calls`` times in a compiled loop, moving shape B by a
tiny amount every call (so nothing is hoisted out of the loop) and summing the gaps (so nothing
is removed); the best of ``repeats`` loops is reported. Prints numbers, asserts nothing.
"""

from __future__ import annotations

import math
import time

import numpy as np
from numba import njit

from clearbench.kernels.quaternion import quat_from_axis_angle, quat_to_matrix
from clearbench.scenarios import geometry as G


@njit  # not cached: numba cache keys ignore edits of the kernels it calls
def _loop(calls, kind_a, params_a, position_a, rotation_a, kind_b, params_b, position_b,
          rotation_b, jitter):
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


def cases():
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


def main(calls: int = 200_000, repeats: int = 5) -> None:
    print(f"{'case':60s} {'ns/call':>9s}")
    for name, a, b, jitter in cases():
        _loop(10, *a, *b, jitter)  # compile
        best = math.inf
        for _ in range(repeats):
            start = time.perf_counter()
            _loop(calls, *a, *b, jitter)
            best = min(best, time.perf_counter() - start)
        print(f"{name:60s} {best / calls * 1e9:9.1f}")


if __name__ == "__main__":
    main()
