"""Line-search variants of the reference's semismooth Newton, replayed on a run's own problems.

    .venv/bin/python -m tools.newton_variants c60-on --dt 0.004 --skip 100 --steps 300

Records a run's dense Newton calls as :mod:`tools.newton_profile` does, then solves every
recorded problem with the kernel as it is and with each variant below (the kernel's own source,
edited), and prints per variant the kernel's replay time (best of two passes) [ms], the
iterations, the largest iteration count and the problems left unconverged (status other than
converged or round-off floor):

- ``halvings-10``, ``halvings-6``: the line search gives up after 10 or 6 halvings (then an
  NSGS rescue), instead of ``MAX_HALVINGS``;
- ``incremental``: the trial velocity updated as u + t W d (W d once per iteration) instead
  of W (r + t d) + q at every halving;
- ``least-norm-after-K`` (K = 4, 8, 12): after K refused halvings, the least-norm direction
  with the full line search.

These are the variants docs/reference-solver-speed.md reports as tried and dropped.
"""

from __future__ import annotations

import argparse
import inspect
import time

import numpy as np

import clearbench.ref_solver.fc3d_newton_dense as newton_dense
from tools.newton_profile import add_recording_arguments, edited_kernel, fresh, record_calls

_HALVINGS = "for _ in range(MAX_HALVINGS):"
_TRIAL = """                for i in range(m):
                    r_try[i] = r[i] + step * d[i]
                matvec_plus(W, r_try, q, u_try)
"""
_HALVING = "                step *= 0.5\n"


def _line_search() -> str:
    """The kernel's own line-search loop, its source lines (from the halvings' loop to the
    halving)."""
    source = inspect.getsource(newton_dense.newton_dense_kernel.py_func)
    start = source.index("            " + _HALVINGS)
    end = source.index(_HALVING, start) + len(_HALVING)
    return source[start:end]


_SEARCH = _line_search()


def _least_norm_after(k: int) -> tuple:
    """The line search cut at ``k`` halvings, then the least-norm direction searched again."""
    retry = "".join("        " + line if line else line
                    for line in _SEARCH.splitlines(keepends=True))
    return ((_SEARCH, _SEARCH.replace("MAX_HALVINGS", str(k)) + """\
            if not step_ok and not least_norm:
                if least_norm_direction(W, n_bilateral, rho_b, A, B, phi, J, d):
                    step = 1.0
""" + retry),)


VARIANTS = {
    "kernel": (),
    "halvings-10": ((_HALVINGS, "for _ in range(10):"),),
    "halvings-6": ((_HALVINGS, "for _ in range(6):"),),
    "incremental": (
        ("        if step_ok:\n            step = 1.0\n",
         "        if step_ok:\n            wd = W @ d\n            step = 1.0\n"),
        (_TRIAL, """                for i in range(m):
                    r_try[i] = r[i] + step * d[i]
                    u_try[i] = u[i] + step * wd[i]
""")),
    **{f"least-norm-after-{k}": _least_norm_after(k) for k in (4, 8, 12)},
}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_recording_arguments(parser)
    args = parser.parse_args()
    calls = record_calls(args.scene, args.dt, args.skip, args.steps)
    print(f"{args.scene}: {len(calls)} dense Newton calls")
    print(f"{'variant':22s} {'replay [ms]':>11s} {'iterations':>11s} {'largest':>8s} "
          f"{'unconverged':>12s}")
    for name, replacements in VARIANTS.items():
        kernel = edited_kernel(replacements)
        outputs = [kernel(*fresh(arguments)) for arguments, *_ in calls]  # also compiles
        seconds = np.inf
        for _ in range(2):
            started = time.perf_counter()
            for arguments, *_ in calls:
                kernel(*fresh(arguments))
            seconds = min(seconds, time.perf_counter() - started)
        iterations = np.array([out[1] for out in outputs])
        unconverged = sum(int(out[0]) not in (newton_dense.CONVERGED, newton_dense.ROUNDOFF)
                          for out in outputs)
        print(f"{name:22s} {seconds * 1e3:11.1f} {int(iterations.sum()):11d} "
              f"{int(iterations.max()):8d} {unconverged:12d}")


if __name__ == "__main__":
    main()
