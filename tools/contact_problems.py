"""A run's one-step contact problems, kept and solved again with this checkout's hybrid chain.

    .venv/bin/python -m tools.contact_problems record c60-on --dt 0.004 --save on_4us.npz
    .venv/bin/python -m tools.contact_problems replay on_4us.npz

``record`` steps SCENE in the reference engine with the Python step (the default preset and
the engine options of ``--option KEY=VALUE``, kept in the file and used again by ``replay``;
``--skip`` steps first, then ``--steps`` steps, default the whole horizon) and keeps every
one-step problem the stepper's ``_solve`` receives, one per activation round: the dense
Delassus operator W (m, m), the free velocity q (m,), mu (nc,), the bilateral rows, the warm
start, and what the chain returned (impulses, iterations, residual, converged). It prints the
iterations' distribution over the problems: the heavy tail is what makes a step size costly.

``replay`` solves every kept problem again, in order, with the compiled chain of this checkout
(:func:`ref_solver.compiled.contact_solve.solve`, the settings of the recorded run, the
chain's "Newton first" memory carried from problem to problem as in a run), and prints the
iterations against the recorded ones, the problems left unconverged, how many results are the
recorded ones to the bit, the largest difference of velocity |W (r - r_recorded)| relative to
|q| (a solve that ends elsewhere on a rank-deficient problem's solution set moves r, not u),
and the replay's wall time. Recorded with one revision and replayed with another, it measures a
solver change on the same problems, apart from the trajectory the change would also move.

``--dt`` is in the scene's time unit (C-60: ms). The file is numpy's ``.npz``: the problems'
arrays concatenated, with their sizes (FCLIB's local format has no bilateral rows, which the
C-60's problems have).
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np

from clearbench.adapters.base import RunSettings
from clearbench.adapters.reference.build import build
from clearbench.adapters.reference.engine import create
from clearbench.harness.cli.common import add_engine_options_option, engine_options
from clearbench.ref_solver.compiled.contact_solve import NO_NEWTON_FIRST, solve
from clearbench.ref_solver.compiled.system_arrays import compile_system, history_length
from clearbench.scenarios.library import get_scene

#: Iteration counts of a problem at least this large are its run's heavy tail (the whole chain
#: tried: two NSGS attempts to their 10,000-sweep cap are 20,000).
HEAVY = 1000


def _model(scene_name: str, time_step: float | None, options: dict | None = None):
    scene = get_scene(scene_name)
    settings = RunSettings(time_step=time_step, options=dict(options or {}))
    return build(scene, create("default").run_settings(scene, settings))


def recorded_options(data) -> dict:
    """The engine options a recording was made with (none in files written before they were
    kept)."""
    if "options" not in data:
        return {}
    return json.loads(str(data["options"]))


def record(scene_name: str, time_step: float | None, skip: int, steps: int | None,
           options: dict | None = None) -> dict:
    """Every one-step problem of the run (module docstring), as the arrays of the file."""
    model = _model(scene_name, time_step, options)
    stepper, state = model.stepper, model.state
    for _ in range(skip):
        state = stepper.step(state).state
    if steps is None:
        steps = int(round(get_scene(scene_name).horizon / stepper.settings.time_step)) - skip
    kept = []
    original = stepper._solve
    step = [0]

    def recording(problem, r0):
        W = problem.W.toarray() if hasattr(problem.W, "toarray") else np.array(problem.W)
        result = original(problem, r0)
        kept.append((step[0], W, problem.q.copy(), problem.mu.copy(), problem.n_bilateral,
                     np.zeros(problem.q.size) if r0 is None else np.array(r0, dtype=float),
                     result.r.copy(), result.iterations, result.residual, result.converged))
        return result

    stepper._solve = recording
    for k in range(steps):
        step[0] = skip + k + 1
        state = stepper.step(state).state
    sizes = np.array([entry[2].size for entry in kept], dtype=np.int64)
    return {
        "scene": np.array(scene_name), "time_step": np.array(stepper.settings.time_step),
        "options": np.array(json.dumps(options or {}, sort_keys=True)),
        "step": np.array([entry[0] for entry in kept], dtype=np.int64),
        "rows": sizes,
        "W": np.concatenate([entry[1].ravel() for entry in kept]) if kept else np.zeros(0),
        "q": np.concatenate([entry[2] for entry in kept]) if kept else np.zeros(0),
        "mu": np.concatenate([entry[3] for entry in kept]) if kept else np.zeros(0),
        "n_bilateral": np.array([entry[4] for entry in kept], dtype=np.int64),
        "r0": np.concatenate([entry[5] for entry in kept]) if kept else np.zeros(0),
        "r": np.concatenate([entry[6] for entry in kept]) if kept else np.zeros(0),
        "iterations": np.array([entry[7] for entry in kept], dtype=np.int64),
        "residual": np.array([entry[8] for entry in kept]),
        "converged": np.array([entry[9] for entry in kept], dtype=bool),
    }


def problems(data) -> list[tuple]:
    """[(step, W, q, mu, n_bilateral, r0, r)] of a recorded file's arrays."""
    out = []
    at_row = at_w = at_mu = 0
    for k, m in enumerate(data["rows"]):
        nb = int(data["n_bilateral"][k])
        nc = (int(m) - nb) // 3
        rows = slice(at_row, at_row + m)
        out.append((int(data["step"][k]), data["W"][at_w:at_w + m * m].reshape(m, m),
                    data["q"][rows], data["mu"][at_mu:at_mu + nc], nb, data["r0"][rows],
                    data["r"][rows]))
        at_row, at_w, at_mu = at_row + m, at_w + m * m, at_mu + nc
    return out


def describe(iterations: np.ndarray, label: str) -> str:
    """The iterations' total, per-problem percentiles and heavy tail."""
    if iterations.size == 0:
        return f"{label}: no problem"
    p50, p90, p99 = np.percentile(iterations, [50, 90, 99])
    heavy = iterations >= HEAVY
    share = iterations[heavy].sum() / max(iterations.sum(), 1)
    return (f"{label}: {iterations.sum()} iterations over {iterations.size} problems "
            f"(per problem: median {p50:.0f}, 90 % {p90:.0f}, 99 % {p99:.0f}, largest "
            f"{iterations.max()}); {int(heavy.sum())} problems of >= {HEAVY} iterations hold "
            f"{share:.0%} of them")


def replay(data) -> dict:
    """Solve a recording's problems again (module docstring): {"iterations" (P,),
    "converged" (P,), "equal" (problems whose impulses are the recorded ones to the bit),
    "largest_velocity_difference" (the largest |W (r - r_recorded)| / |q|), "seconds"}."""
    time_step = float(data["time_step"])
    model = _model(str(data["scene"]), time_step, recorded_options(data))
    _, cfg = compile_system(model.stepper)
    history = np.empty(history_length(cfg))
    memory = np.array([NO_NEWTON_FIRST], dtype=np.int64)
    cases = problems(data)
    iterations = np.zeros(len(cases), dtype=np.int64)
    converged = np.zeros(len(cases), dtype=bool)
    started = time.perf_counter()
    results = []
    for k, (_, W, q, mu, nb, r0, _) in enumerate(cases):
        r, its, _, ok = solve(np.ascontiguousarray(W), q, mu, np.int64(nb), r0, cfg, memory,
                              history)
        iterations[k], converged[k] = its, ok
        results.append(r)
    seconds = time.perf_counter() - started
    equal, largest = 0, 0.0
    for (_, W, q, _, _, _, recorded), r in zip(cases, results, strict=True):
        equal += int(np.array_equal(r, recorded))
        scale = max(float(np.abs(q).max()), 1e-300)
        largest = max(largest, float(np.abs(W @ (r - recorded)).max()) / scale)
    return {"iterations": iterations, "converged": converged, "equal": equal,
            "largest_velocity_difference": largest, "seconds": seconds}


def print_replay(data, replayed: dict) -> None:
    print(describe(data["iterations"], "recorded"))
    print(describe(replayed["iterations"], "this checkout"))
    print(f"unconverged: recorded {int((~data['converged']).sum())}, this checkout "
          f"{int((~replayed['converged']).sum())}; results equal to the bit "
          f"{replayed['equal']} of {data['rows'].size}; largest |W (r - r_recorded)| / |q| "
          f"{replayed['largest_velocity_difference']:.1e}; replay {replayed['seconds']:.2f} s")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    commands = parser.add_subparsers(dest="command", required=True)
    rec = commands.add_parser("record", help="keep a run's one-step problems")
    rec.add_argument("scene")
    rec.add_argument("--dt", type=float, default=None,
                     help="time step [the scene's time unit]; default the scene's")
    rec.add_argument("--skip", type=int, default=0, help="steps taken before recording")
    rec.add_argument("--steps", type=int, default=None,
                     help="steps recorded (default: to the scene's horizon)")
    rec.add_argument("--save", required=True, help="the .npz file written")
    add_engine_options_option(rec, "reference engine option of the recorded run (repeatable)")
    again = commands.add_parser("replay", help="solve a recording's problems again")
    again.add_argument("file")
    args = parser.parse_args()
    if args.command == "record":
        started = time.perf_counter()
        data = record(args.scene, args.dt, args.skip, args.steps, engine_options(args))
        np.savez_compressed(args.save, **data)
        print(f"{args.scene}, step {float(data['time_step']):g}: {data['rows'].size} problems "
              f"kept in {args.save} ({time.perf_counter() - started:.1f} s)")
        print(describe(data["iterations"], "recorded"))
    else:
        with np.load(args.file) as handle:
            data = {name: handle[name] for name in handle.files}
        print_replay(data, replay(data))


if __name__ == "__main__":
    main()
