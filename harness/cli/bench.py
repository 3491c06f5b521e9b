"""``clearbench bench NAME``: benchmarks that print figures (and write figures), never assert.

Each benchmark is a function registered in :data:`BENCHMARKS`; ``clearbench bench --list``
shows them.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from clearbench.harness.cli import bench_against
from clearbench.harness.cli.main import UserError


def bench_reference(args: argparse.Namespace) -> int:
    from clearbench.harness.studies.benchmarks import reference_step_costs

    print("Reference engine, wall time of stepping (best of 3, after a warm-up that compiles)")
    print(f"{'scene':<20} {'steps':>6} {'active contacts':>16} {'us/step':>9} "
          f"{'us/contact/iteration':>21}")
    for cost in reference_step_costs():
        per_contact = cost.microseconds_per_contact_iteration
        print(f"{cost.scene:<20} {cost.steps:>6} {cost.mean_active_contacts:>16.1f} "
              f"{cost.microseconds_per_step:>9.1f} {per_contact:>21.3f}")
    return 0


def bench_clearance_ladder(args: argparse.Namespace) -> int:
    from clearbench.harness.studies.benchmarks import clearance_ladder, plot_clearance_ladder

    rungs = clearance_ladder()
    print("Frictionless clearance pendulum vs the exact ideal pendulum, 0.5 s")
    print(f"{'clearance [m]':>14} {'step [s]':>9} {'angle error [rad]':>18} "
          f"{'excess [m]':>11} {'converged':>9} {'stepping [s]':>12}")
    for r in rungs:
        print(f"{r.clearance:>14.0e} {r.time_step:>9.0e} {r.angle_error:>18.3e} "
              f"{r.excess:>11.1e} {str(r.converged):>9} {r.stepping_seconds:>12.2f}")
    out = Path(args.out or "reports/figures/clearance_ladder.png")
    out.parent.mkdir(parents=True, exist_ok=True)
    plot_clearance_ladder(rungs, out)
    print(f"figure: {out}")
    return 0


def bench_siconos_crosscheck(args: argparse.Namespace) -> int:
    from clearbench.adapters.siconos.engine import availability
    from clearbench.harness.studies.benchmarks import crosscheck_markdown, siconos_crosscheck

    available, detail = availability()
    if not available:
        raise UserError(f"the Siconos cross-check needs Siconos: {detail}")
    print(f"Reference solver against Siconos ({detail}), each scene at its own time step and "
          "horizon; differences are maxima over the run")
    print(crosscheck_markdown(siconos_crosscheck()))
    return 0


def bench_reference_physics(args: argparse.Namespace) -> int:
    from clearbench.harness.studies.benchmarks import engine_physics_table

    steps = tuple(float(x) for x in args.dt) if args.dt else (None,)
    rows = engine_physics_table("reference", "default", steps, args.tag)
    print("Reference engine against each library scene's expectations (scene units)")
    print(f"{'scene':<20} {'h':>8} {'expectation':<16} {'figure':<28} {'value':>12} "
          f"{'converged':>9}")
    for r in rows:
        print(f"{r.scene:<20} {r.time_step:>8.0e} {r.expectation:<16} {r.figure:<28} "
              f"{r.value:>12.3e} {str(r.converged):>9}")
    return 0


def bench_flores_reference(args: argparse.Namespace) -> int:
    from clearbench.adapters.base import RunSettings
    from clearbench.adapters.reference.engine import create
    from clearbench.harness.measure.expectation_figures import evaluate
    from clearbench.scenarios.library import get_scene

    scene = get_scene("flores-slider-crank")
    trajectory = create().run(scene, RunSettings(time_step=1e-5, record_every=10))
    out = Path(args.out or "reports/trajectories/flores-slider-crank_reference.npz")
    out.parent.mkdir(parents=True, exist_ok=True)
    trajectory.save(out)
    print(f"Flores-Leine-Glocker slider-crank, reference engine, h = 1e-5 s, 0.2 s: "
          f"{trajectory.steps} steps in {trajectory.stepping_seconds:.1f} s, "
          f"unconverged steps: {len(trajectory.metadata['unconverged_steps'])}")
    for result in evaluate(scene, trajectory):
        print(f"  {result.name}: " + ", ".join(f"{k} = {v:.3e}" for k, v in result.figures.items()))
    print(f"trajectory (every 10th step): {out}")
    return 0


def bench_c60(args: argparse.Namespace) -> int:
    from clearbench.harness.studies.benchmarks import c60_costs

    print("C-60 full runs with the reference engine, one core (after a warm-up that compiles);")
    print("the paper quotes 810 s per run with Siconos; the target here is 10 s per c60-trip.")
    print(f"{'scene':<9} {'preset':<8} {'steps':>6} {'run [s]':>8} {'ms/step':>8} "
          f"{'solver [s]':>10} {'contacts':>8} {'iter/step':>9} {'median res':>10} "
          f"{'max res':>8} {'unconv':>6}")
    for cost in c60_costs():
        print(f"{cost.scene:<9} {cost.preset:<8} {cost.steps:>6} {cost.stepping_seconds:>8.1f} "
              f"{cost.milliseconds_per_step:>8.2f} {cost.solver_seconds:>10.1f} "
              f"{cost.mean_active_contacts:>8.1f} {cost.mean_iterations:>9.0f} "
              f"{cost.median_residual:>10.1e} {cost.max_residual:>8.1e} "
              f"{cost.unconverged_steps:>6}")
    return 0


BENCHMARKS = {
    "flores-reference": (bench_flores_reference,
                         "keeps the reference trajectory of the Flores slider-crank (h = 1e-5 s)"),
    "reference-physics": (bench_reference_physics,
                          "the reference engine against every scene's expectations"),
    "reference": (bench_reference, "us per step and per contact-iteration of the reference"),
    "clearance-ladder": (bench_clearance_ladder,
                         "clearance pendulum -> ideal pendulum as the clearance shrinks"),
    "c60": (bench_c60, "wall time and solver statistics of full c60-trip and c60-on runs"),
    "siconos-crosscheck": (bench_siconos_crosscheck,
                           "reference solver vs Siconos 4.4 on the analytic scenes, the clearance "
                           "pendulum and the Flores slider-crank"),
}


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "bench", help="run a benchmark (prints figures, asserts nothing)",
        description="Benchmarks: " + "; ".join(f"{k}: {v[1]}" for k, v in BENCHMARKS.items()),
    )
    parser.add_argument("name", nargs="?", help="benchmark name (see --list)")
    parser.add_argument("--list", action="store_true", help="list the benchmarks")
    parser.add_argument("--out", help="where a benchmark writes its figure")
    parser.add_argument("--dt", nargs="+", help="time steps (scene units), where it applies")
    parser.add_argument("--tag", help="only scenes with this tag, where it applies")
    bench_against.add_arguments(parser)
    parser.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    if args.list or not args.name:
        for name, (_, summary) in BENCHMARKS.items():
            print(f"{name:<20} {summary}")
        return 0
    if args.name not in BENCHMARKS:
        raise UserError(f"unknown benchmark {args.name!r}; benchmarks: {', '.join(BENCHMARKS)}")
    if args.against:
        return bench_against.run_against(args)
    return BENCHMARKS[args.name][0](args)
