"""Why the reference leaves a step's contact problem (or its projection) unconverged.

    .venv/bin/python -m tools.unconverged_steps c60-trip

Runs SCENE in the reference engine with the Python step (the same stepper the compiled loop
mirrors), and for every step whose contact solve or projection did not converge prints:

- the step, its time, the activation rounds and the contacts active;
- each contact problem the step solved (one per activation round): its size (bilateral rows,
  contacts), the singular values of its Delassus operator W (largest, smallest, the numerical
  rank at 1e-10 of the largest: a rank below the row count is redundant contacts), the free
  velocity's norm;
- every attempt of the hybrid chain on it (method, Newton direction, start, iterations, status,
  residual against the tolerance), so the reason is read off the attempts, not guessed;
- the projection's violation and iterations when the projection failed.

``--save FILE.npz`` keeps the unconverged problems (W, q, mu, n_bilateral, the warm start) to
solve them again elsewhere. ``--dt`` is in the scene's time unit (C-60: ms). The steps found
are compared with nothing: run the compiled loop (``clearbench run``) for its own list.
"""

from __future__ import annotations

import argparse

import numpy as np

import clearbench.ref_solver.stepper as stepper_module
from clearbench.adapters.base import RunSettings
from clearbench.adapters.recording import step_count
from clearbench.adapters.reference.build import build
from clearbench.adapters.reference.engine import create
from clearbench.scenarios.library import get_scene

#: Relative threshold of the numerical rank of W: singular values below 1e-10 of the largest
#: are round-off for a Delassus operator assembled in double precision from O(1)-scaled rows.
RANK_THRESHOLD = 1e-10


def _start_label(start, r0, first_r) -> str:
    if start is None:
        return "zero"
    if start is r0:
        return "warm"
    if first_r is not None and start is first_r:
        return "after NSGS"
    return "other"


class _Recorder:
    """Wraps the stepper module's ``solve_contact_problem`` and the stepper's ``_solve``: the
    attempts of each one-step problem of the current step, grouped by problem."""

    def __init__(self, stepper):
        self.problems = []
        self._original_solve = stepper_module.solve_contact_problem
        self._original_step_solve = stepper._solve
        self._attempts = None
        self._r0 = None
        self._first_r = None
        stepper_module.solve_contact_problem = self._solve_contact_problem
        stepper._solve = self._step_solve

    def restore(self, stepper) -> None:
        stepper_module.solve_contact_problem = self._original_solve
        stepper._solve = self._original_step_solve

    def _step_solve(self, problem, r0):
        self._attempts, self._r0, self._first_r = [], r0, None
        result = self._original_step_solve(problem, r0)
        self.problems.append((problem, None if r0 is None else r0.copy(), self._attempts,
                              result))
        return result

    def _solve_contact_problem(self, problem, options, r0=None):
        result = self._original_solve(problem, options, r0=r0)
        if self._attempts is not None:
            label = options.method if options.method != "newton" else (
                f"newton ({options.newton_direction})")
            self._attempts.append((label, options.max_iterations,
                                   _start_label(r0, self._r0, self._first_r), result))
            if options.method == "nsgs" and self._first_r is None:
                self._first_r = result.r
        return result


def _describe(problem, attempts, result, tolerance) -> list[str]:
    W = problem.W.toarray() if hasattr(problem.W, "toarray") else np.asarray(problem.W)
    singular = np.linalg.svd(W, compute_uv=False)
    rank = int(np.count_nonzero(singular > RANK_THRESHOLD * singular[0]))
    lines = [f"  problem: {problem.n_bilateral} bilateral rows, {problem.mu.size} contacts "
             f"({W.shape[0]} rows), W singular values {singular[0]:.3e} .. {singular[-1]:.3e}, "
             f"rank {rank} of {W.shape[0]}, |q| {np.linalg.norm(problem.q):.3e}; kept: "
             f"{'converged' if result.converged else 'UNCONVERGED'}, residual "
             f"{result.residual:.3e} (tolerance {tolerance:.0e})"]
    for label, cap, start, attempt in attempts:
        status = getattr(attempt.status, "name", attempt.status)
        lines.append(f"    {label:<24} cap {cap:>6}, from {start:<10}: {attempt.iterations:>6} "
                     f"iterations, {status}, residual {attempt.residual:.3e}")
    return lines


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene")
    parser.add_argument("--dt", type=float, default=None,
                        help="time step [the scene's time unit]; default the scene's")
    parser.add_argument("--save", default=None, help="write the unconverged problems here")
    args = parser.parse_args()
    scene = get_scene(args.scene)
    settings = create("default").run_settings(scene, RunSettings(time_step=args.dt))
    model = build(scene, settings)
    stepper, state = model.stepper, model.state
    tolerance = settings.solver.tolerance
    steps = step_count(scene.horizon, settings.time_step)
    recorder = _Recorder(stepper)
    saved = {}
    found = []
    try:
        for index in range(steps):
            recorder.problems = []
            result = stepper.step(state)
            state = result.state
            statistics = result.statistics
            if statistics.solver_converged and statistics.projection_converged:
                continue
            found.append(index)
            print(f"step {index} (t = {float(state.t):.6g} {scene.units.time}): "
                  f"{statistics.activation_rounds} activation rounds, "
                  f"{statistics.active_contacts} contacts active, solver "
                  f"{'converged' if statistics.solver_converged else 'UNCONVERGED'}, "
                  f"projection {'converged' if statistics.projection_converged else 'FAILED'} "
                  f"(violation {statistics.projection_violation:.3e}, "
                  f"{statistics.projection_iterations} iterations)")
            for number, (problem, r0, attempts, kept) in enumerate(recorder.problems):
                print("\n".join(_describe(problem, attempts, kept, tolerance)))
                if not kept.converged:
                    W = problem.W.toarray() if hasattr(problem.W, "toarray") else problem.W
                    key = f"step{index}_problem{number}"
                    saved.update({f"{key}_W": np.asarray(W), f"{key}_q": problem.q,
                                  f"{key}_mu": problem.mu,
                                  f"{key}_n_bilateral": np.array(problem.n_bilateral),
                                  f"{key}_r0": np.zeros(0) if r0 is None else r0})
    finally:
        recorder.restore(stepper)
    print(f"{len(found)} unconverged steps of {steps}: {found}")
    if args.save and saved:
        np.savez_compressed(args.save, **saved)
        print(f"problems written to {args.save}")


if __name__ == "__main__":
    main()
