"""Where the reference's semismooth Newton spends its iterations on a run's own problems.

    .venv/bin/python -m tools.newton_profile c60-on --dt 0.001 --skip 300 --steps 300

Runs SCENE in the reference engine with the Python step (``--skip`` steps, then ``--steps``
steps recorded), keeps the inputs of every call of the dense Newton kernel
(:func:`fc3d_newton_dense.newton_dense_kernel`: the hybrid chain's Newton attempts, problems of
at most ``fc3d_newton_parts.DENSE_LIMIT`` rows), then solves each again with a copy of the
kernel that counts, and prints:

- the calls, iterations, line-search halvings and NSGS rescues per exit status;
- the heavy tail: the calls of at least ``--long`` iterations, with their share of the
  iterations and of the halvings;
- the successful line searches by the number of halvings they took (0: the full Newton step),
  and the iterations that accepted no step (every ``MAX_HALVINGS`` halving refused, or no
  direction; an NSGS rescue follows);
- the replay's wall time of the kernel itself per iteration [us].

The counting copy is the kernel's own source with three counters added; it checks that it
returns what the recorded call returned (status, iterations, impulses to the bit), so a count
that does not describe the real solve is an error, not a figure. ``--dt`` is in the scene's time
unit (C-60: ms).
"""

from __future__ import annotations

import argparse
import inspect
import time

import numpy as np
from numba import njit

import clearbench.ref_solver.fc3d_newton_dense as newton_dense
from clearbench.adapters.base import RunSettings
from clearbench.adapters.reference.build import build
from clearbench.adapters.reference.engine import create
from clearbench.scenarios.library import get_scene

#: Status names of :func:`fc3d_newton_dense.newton_dense_kernel`'s codes.
STATUS = ("converged", "iteration cap", "hopeless", "non-finite", "no descent",
          "round-off floor")
#: (anchor in the kernel's source, the anchor with a counter after it): the counters of
#: ``counts`` (0 iterations, 1 halvings, 2 rescues) and ``accepted`` (successful line searches
#: by halvings).
_COUNTERS = tuple((anchor, anchor + added) for anchor, added in (
    ("        iteration += 1\n", "        counts[0] += 1\n"),
    ("                step *= 0.5\n", "                counts[1] += 1\n"),
    ("            rescues += 1\n", "            counts[2] += 1\n"),
    ("                    step_ok = True\n", "                    accepted[_] += 1\n"),
))


def edited_kernel(replacements, parameters: str = ""):
    """The Newton kernel compiled again from its own source with each (anchor, text) of
    ``replacements`` replaced (each anchor must occur exactly once) and ``parameters`` (e.g.
    ``"counts, accepted, "``) put before its arguments."""
    source = inspect.getsource(newton_dense.newton_dense_kernel.py_func)
    source = source.replace("@njit(cache=True)\n", "").replace(
        "def newton_dense_kernel(", "def edited_newton_dense_kernel(" + parameters)
    for anchor, text in replacements:
        if source.count(anchor) != 1:
            raise RuntimeError(f"the Newton kernel changed: {anchor.strip()!r} is not found once")
        source = source.replace(anchor, text)
    namespace = dict(vars(newton_dense))
    exec(source, namespace)  # noqa: S102 - the package's own kernel source, edited
    return njit(namespace["edited_newton_dense_kernel"])


def counting_kernel():
    """The Newton kernel compiled again with counters: ``f(counts (3,), accepted
    (MAX_HALVINGS + 1,), *the kernel's arguments)``."""
    return edited_kernel(_COUNTERS, "counts, accepted, ")


def fresh(args):
    """The arguments with their arrays copied (a kernel call writes into some)."""
    return [a.copy() if isinstance(a, np.ndarray) else a for a in args]


def add_recording_arguments(parser: argparse.ArgumentParser) -> None:
    """SCENE, --dt, --skip, --steps: the arguments of :func:`record_calls`."""
    parser.add_argument("scene")
    parser.add_argument("--dt", type=float, default=None,
                        help="time step [the scene's time unit]; default the scene's")
    parser.add_argument("--skip", type=int, default=0, help="steps taken before recording")
    parser.add_argument("--steps", type=int, default=300, help="steps recorded")


def record_calls(scene_name: str, time_step: float | None, skip: int, steps: int) -> list:
    """[(arguments, status, iterations, impulses)] of every dense Newton call of ``steps``
    Python steps after ``skip``."""
    calls = []
    original = newton_dense.newton_dense_kernel

    def recording(*args):
        copies = fresh(args)
        out = original(*args)
        calls.append((copies, int(out[0]), int(out[1]), args[4].copy()))
        return out

    scene = get_scene(scene_name)
    model = build(scene, create("default").run_settings(scene, RunSettings(time_step=time_step)))
    stepper, state = model.stepper, model.state
    for _ in range(skip):
        state = stepper.step(state).state
    newton_dense.newton_dense_kernel = recording
    try:
        calls.clear()
        for _ in range(steps):
            state = stepper.step(state).state
    finally:
        newton_dense.newton_dense_kernel = original
    return calls


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_recording_arguments(parser)
    parser.add_argument("--long", type=int, default=50,
                        help="a call of at least this many iterations is in the heavy tail")
    args = parser.parse_args()
    calls = record_calls(args.scene, args.dt, args.skip, args.steps)
    if not calls:
        print("no dense Newton call in the recorded steps")
        return
    kernel = counting_kernel()
    halvings_cap = newton_dense.MAX_HALVINGS
    accepted = np.zeros(halvings_cap + 1)
    rows = []
    for arguments, status, iterations, impulses in calls:
        counts = np.zeros(3)
        copies = fresh(arguments)
        out = kernel(counts, accepted, *copies)
        if int(out[0]) != status or int(out[1]) != iterations or not np.array_equal(
                copies[4], impulses):
            raise RuntimeError("the counting kernel does not reproduce a recorded call")
        rows.append((status, iterations, counts[1], counts[2], arguments[0].shape[0]))
    table = np.array(rows, dtype=float)
    started = time.perf_counter()
    for arguments, *_ in calls:
        newton_dense.newton_dense_kernel(*fresh(arguments))
    seconds = time.perf_counter() - started
    total_iterations = table[:, 1].sum()
    step = "the scene's step" if args.dt is None else f"step {args.dt}"
    print(f"{args.scene}, {step}, steps {args.skip}..{args.skip + args.steps}: "
          f"{len(calls)} dense Newton calls, rows {int(table[:, 4].min())}-"
          f"{int(table[:, 4].max())} (median {np.median(table[:, 4]):.0f})")
    print(f"{'status':16s} {'calls':>6s} {'iterations':>11s} {'halvings':>9s} {'rescues':>8s}")
    for code in sorted(set(table[:, 0].astype(int))):
        sel = table[:, 0] == code
        print(f"{STATUS[code]:16s} {int(sel.sum()):6d} {int(table[sel, 1].sum()):11d} "
              f"{int(table[sel, 2].sum()):9d} {int(table[sel, 3].sum()):8d}")
    tail = table[:, 1] >= args.long
    total_halvings = max(table[:, 2].sum(), 1.0)
    print(f"heavy tail (>= {args.long} iterations): {int(tail.sum())} of {len(calls)} calls, "
          f"{table[tail, 1].sum() / total_iterations:.0%} of the iterations, "
          f"{table[tail, 2].sum() / total_halvings:.0%} of the halvings")
    print("successful line searches by halvings (0 = full step): "
          + " ".join(str(int(a)) for a in accepted[:halvings_cap]))
    refused = int(total_iterations - accepted.sum())
    print(f"iterations without an accepted step (every one of {halvings_cap} halvings refused, "
          f"or no direction): {refused}")
    print(f"kernel replay: {seconds * 1e3:.1f} ms, {seconds / total_iterations * 1e6:.1f} us "
          "per iteration")


if __name__ == "__main__":
    main()
