"""Where a compiled reference step's time goes: the stages of ``compiled.step.single_step``
timed with clocks around them (numba ``objmode``, about a microsecond each) over real steps.

    .venv/bin/python -m tools.step_stages c60-on 500 300   # 500 steps after 300 Python steps
    .venv/bin/python -m tools.step_stages c60-on 300 20 --dt 0.016   # at 16 us

The copy of ``single_step`` below is the same sequence of kernels (free velocity, candidates,
then rounds of velocity stage, projection and the closing test until no contact closes); it
prints each stage's time per step and its share, the activation rounds and solver iterations
per step, and, of the contacts that closed within a step (and so made it run another round),
their gap at the start of the step and at the end of the round that found them [the scene's
length unit]. It copies the projection's path of ``single_step`` (presets with the combined
projection).
"""

from __future__ import annotations

import argparse
import collections
import time

import numpy as np
from numba import njit, objmode

from clearbench.adapters.base import RunSettings
from clearbench.adapters.reference.build import build
from clearbench.adapters.reference.engine import create
from clearbench.adapters.reference.run import _memory
from clearbench.harness.cli.common import add_engine_options_option, engine_options
from clearbench.ref_solver.compiled.step import (
    _projection_stage,
    _velocity_stage,
    first_round_active,
    valid_slots,
)
from clearbench.ref_solver.compiled.system_arrays import compile_system, history_length
from clearbench.ref_solver.forces import remember_angles, rotation_matrices
from clearbench.ref_solver.projection_kernel import candidates
from clearbench.ref_solver.step_kernels import free_velocity
from clearbench.scenarios.library import get_scene

STAGES = ("free velocity", "candidates", "velocity stages", "projections",
          "closing tests", "whole step")
#: Closing contacts kept for the quantiles (the first ones found).
KEPT_CLOSINGS = 5000


@njit
def _now():
    with objmode(t="f8"):
        t = time.perf_counter()
    return t


@njit
def timed_steps(s, cfg, memory, t, x, p, v, omega, history, n, seconds, counts, closings):
    """``n`` steps from (t, x, p, v, omega); ``seconds`` (6,) += each stage's time [s],
    ``counts`` (3,) += (activation rounds, solver iterations, closing contacts), ``closings``
    (K, 4) rows (start gap, end gap [L], pair, slot) of the closing contacts."""
    h = cfg.time_step
    theta = cfg.theta
    for _ in range(n):
        t0 = _now()
        rotation = rotation_matrices(p)
        nu = np.empty((x.shape[0], 6))
        nu[:, :3] = v
        nu[:, 3:] = omega
        free, inverse, _ = free_velocity(
            t + theta * h, h, theta, x, p, rotation, v, omega, s.mass, s.inertia,
            s.inverse_inertia, s.gravity, s.fixed, s.force_kind, s.force_body_a,
            s.force_body_b, s.force_parameters, memory[3], s.has_springs, cfg.length_step,
            s.mass_matrix, s.inverse_mass, s.cluster_dofs, s.cluster_start)
        t1 = _now()
        seconds[0] += t1 - t0
        cand = candidates(s.geometry, x, rotation)
        active = first_round_active(s, cfg, h, x, rotation, cand, nu, free, memory[0])
        seconds[1] += _now() - t1
        rounds = 0
        while True:
            rounds += 1
            ta = _now()
            (x_new, p_new, v_new, omega_new, impulses, closed, its, _, _,
             _) = _velocity_stage(s, cfg, memory, t, h, x, p, v, omega, rotation, nu, free,
                                  inverse, cand, active, history)
            tb = _now()
            seconds[2] += tb - ta
            _projection_stage(s, cfg, t + h, x_new, p_new, active, closed)
            tc = _now()
            seconds[3] += tc - tb
            cand_new = candidates(s.geometry, x_new, rotation_matrices(p_new))
            closing = valid_slots(cand_new[4], cand_new[0] <= 0.0) & ~active
            seconds[4] += _now() - tc
            counts[1] += its
            for i in range(closing.shape[0]):
                for k in range(closing.shape[1]):
                    if closing[i, k]:
                        j = int(counts[2])
                        if j < closings.shape[0]:
                            closings[j, 0] = cand[0][i, k]
                            closings[j, 1] = cand_new[0][i, k]
                            closings[j, 2] = i
                            closings[j, 3] = k
                        counts[2] += 1
            if not closing.any() or rounds >= cfg.max_activation_rounds:
                break
            active = active | closing
        counts[0] += rounds
        previous_impulse = memory[0]
        previous_impulse[:] = 0.0
        for i in range(active.shape[0]):
            for k in range(active.shape[1]):
                if active[i, k]:
                    previous_impulse[i, k] = impulses[i, k]
        x, p, v, omega = x_new, p_new, v_new, omega_new
        t += h
        seconds[5] += _now() - t0
        remember_angles(rotation_matrices(p), s.force_kind, s.force_body_a, s.force_body_b,
                        s.force_parameters, memory[3])
    return t


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene")
    parser.add_argument("steps", type=int, help="steps timed")
    parser.add_argument("skip", type=int, help="steps taken first by the Python step")
    parser.add_argument("--dt", type=float, default=None,
                        help="time step [the scene's time unit]; default the scene's")
    add_engine_options_option(parser, "a reference option (as `clearbench run --option`)")
    args = parser.parse_args()
    scene = get_scene(args.scene)
    engine = create("default")
    options = engine_options(args)
    engine.check_options(options)
    model = build(scene, engine.run_settings(scene, RunSettings(time_step=args.dt,
                                                                options=options)))
    stepper, state = model.stepper, model.state
    for _ in range(args.skip):
        state = stepper.step(state).state
    system, settings = compile_system(stepper)
    if not settings.projection:
        parser.error(f"{args.scene}: the default preset steps it without the projection")
    history = np.zeros(history_length(settings))

    def run(memory, steps, seconds, counts, closings):
        timed_steps(system, settings, memory, float(state.t), state.x.copy(), state.p.copy(),
                    state.v.copy(), state.omega.copy(), history, steps, seconds, counts,
                    closings)

    memory = _memory(stepper, copy=True)
    run(tuple(a.copy() for a in memory), 1, np.zeros(6), np.zeros(3),
        np.zeros((1, 4)))  # compiles
    seconds, counts = np.zeros(6), np.zeros(3)
    closings = np.zeros((KEPT_CLOSINGS, 4))
    run(memory, args.steps, seconds, counts, closings)
    n = args.steps
    for label, spent in zip(STAGES, seconds, strict=True):
        print(f"{label:<16}{spent / n * 1e6:9.1f} us/step {spent / seconds[5]:6.1%}")
    print(f"activation rounds per step {counts[0] / n:.3f}, solver iterations per step "
          f"{counts[1] / n:.2f}")
    kept = closings[:int(min(counts[2], KEPT_CLOSINGS))]
    if len(kept):
        levels = [0.0, 0.1, 0.5, 0.9, 1.0]
        unit = scene.units.length
        print(f"closing contacts {int(counts[2])}; activation margin "
              f"{settings.activation_margin:.3g} {unit}")
        print(f"  gap at the step's start [{unit}], quantiles 0 10 50 90 100 %:",
              np.array2string(np.quantile(kept[:, 0], levels), precision=3))
        print(f"  gap at the round's end [{unit}]:",
              np.array2string(np.quantile(kept[:, 1], levels), precision=3))
        print("  most frequent (pair, slot):", collections.Counter(
            map(tuple, kept[:, 2:].astype(int).tolist())).most_common(5))


if __name__ == "__main__":
    main()
