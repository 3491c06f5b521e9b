"""Where two stored runs of one scene part: the largest difference of any body position between
their recorded states, up to each of some times.

    .venv/bin/python -m tools.trajectory_difference STORE_A KEY_A STORE_B KEY_B \
        [--at 5.7 5.9 6.5 7 8 10 15 20]

Prints the first recorded time at which the two differ by more than 1e-12, 1e-9, 1e-6, 1e-3,
1e-2 and 1e-1 of the scene's length unit, and, at the recorded state nearest each ``--at`` time
[the scene's time unit], their difference there and the largest one up to there. The runs must
have the same recorded times.
"""

from __future__ import annotations

import argparse

import numpy as np

from clearbench.harness.run.store import ResultsStore


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("store_a")
    parser.add_argument("key_a")
    parser.add_argument("store_b")
    parser.add_argument("key_b")
    parser.add_argument("--at", type=float, nargs="*", default=[])
    args = parser.parse_args()
    a = ResultsStore(args.store_a).load_trajectory(args.key_a)
    b = ResultsStore(args.store_b).load_trajectory(args.key_b)
    if a is None or b is None:
        parser.error("no trajectory under one of the keys")
    if a.times.shape != b.times.shape or not np.array_equal(a.times, b.times):
        parser.error("the two runs are not recorded at the same times")
    difference = np.abs(a.positions - b.positions).max(axis=(1, 2))
    apart = np.maximum.accumulate(difference)
    for threshold in (1e-12, 1e-9, 1e-6, 1e-3, 1e-2, 1e-1):
        beyond = np.nonzero(apart > threshold)[0]
        when = f"{a.times[beyond[0]]:.6g}" if beyond.size else "never"
        print(f"apart by more than {threshold:g} from t = {when}")
    for t in args.at:
        i = int(np.argmin(np.abs(a.times - t)))
        print(f"t = {a.times[i]:.6g}: difference {difference[i]:.3g}, largest up to there "
              f"{apart[i]:.3g}")


if __name__ == "__main__":
    main()
