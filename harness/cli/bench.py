"""``clearbench bench NAME``: the benchmarks. Each prints its figures (some also write a figure
or a trajectory) and asserts nothing; ``clearbench bench --list`` lists them.

Each benchmark is an entry of :data:`BENCHMARKS`: a summary, the options of its own sub-parser,
and a function that measures (with :mod:`clearbench.harness.studies.benchmarks`) and prints.
"""

from __future__ import annotations

import argparse
import importlib
import math
import statistics
import sys
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from clearbench.adapters import siconos
from clearbench.harness.cli import bench_against
from clearbench.harness.cli.common import (
    UserError,
    add_engine_module_option,
    add_engine_option,
    add_engine_options_option,
    engine_modules,
    engine_options,
)
from clearbench.harness.run.engine_choice import RunInputError, resolve_engine
from clearbench.harness.run.spec import DEFAULT_TIMEOUT
from clearbench.harness.studies.benchmarks import (
    clearance_ladder,
    contact_cost,
    engine_costs,
    kernel_speed,
    physics,
    physics_table,
    siconos_crosscheck,
    speed,
)
from clearbench.scenarios.library import scene_names


def _no_options(parser: argparse.ArgumentParser) -> None:
    """A benchmark without options."""


@dataclass(frozen=True)
class Benchmark:
    """One ``clearbench bench`` entry: what it measures, its options, and its run."""

    summary: str
    run: Callable[[argparse.Namespace], int]
    add_options: Callable[[argparse.ArgumentParser], None] = _no_options
    description: str = ""  # of its --help (default: the summary)


# ---------------------------------------------------------------------------- speed
def bench_reference(args: argparse.Namespace) -> int:
    if args.against:
        return bench_against.run_against(args)
    bench_against.refuse_without_baseline(args)
    print("Reference engine, wall time of stepping (best of 3, after a warm-up that compiles)")
    print(f"{'scene':<20} {'steps':>6} {'active contacts':>16} {'us/step':>9} "
          f"{'us/contact/iteration':>21}")
    for cost in speed.reference_step_costs():
        per_contact = cost.microseconds_per_contact_iteration
        print(f"{cost.scene:<20} {cost.steps:>6} {cost.mean_active_contacts:>16.1f} "
              f"{cost.microseconds_per_step:>9.1f} {per_contact:>21.3f}")
    return 0


def bench_c60(args: argparse.Namespace) -> int:
    if args.against:
        return bench_against.run_against(args)
    bench_against.refuse_without_baseline(args)
    print("C-60 full runs with the reference engine, one core (after a warm-up that compiles);")
    print("the paper quotes 810 s per run with Siconos; the target here is 10 s per c60-trip.")
    print(f"{'scene':<9} {'preset':<8} {'steps':>6} {'run [s]':>8} {'ms/step':>8} "
          f"{'solver [s]':>10} {'contacts':>8} {'iter/step':>9} {'median res':>10} "
          f"{'max res':>8} {'unconv':>6}")
    for cost in speed.c60_costs():
        print(f"{cost.scene:<9} {cost.preset:<8} {cost.steps:>6} {cost.stepping_seconds:>8.1f} "
              f"{cost.milliseconds_per_step:>8.2f} {cost.solver_seconds:>10.1f} "
              f"{cost.mean_active_contacts:>8.1f} {cost.mean_iterations:>9.0f} "
              f"{cost.median_residual:>10.1e} {cost.max_residual:>8.1e} "
              f"{cost.unconverged_steps:>6}")
    return 0


def _engines_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--engine", action="append", dest="engines", metavar="ENGINE[PRESET]",
                        help="a contender (repeatable; default every preset of every "
                        "available engine)")
    parser.add_argument("--scene", action="append", dest="scenes",
                        help="a library scene (repeatable; default every library scene)")
    parser.add_argument("--steps", type=int, default=200,
                        help="steps of each measured run, at the scene's time step (at most "
                        "its horizon; default 200)")
    parser.add_argument("--python-loop", action="store_true",
                        help="also run reference[default] with step_loop=python (the Python "
                        "step) beside the compiled loop")
    parser.add_argument("--against", metavar="REV",
                        help="instead of the engines: reference[default] on the baseline git "
                        "revision REV and on this one, alternately in one session, and the "
                        "speed-up per scene")
    parser.add_argument("--repeat", type=int, default=2,
                        help="--against: runs of each scene on each side (best one kept)")
    parser.add_argument("--timeout", type=float, default=DEFAULT_TIMEOUT, metavar="SECONDS",
                        help="wall-clock limit of each run of a contender (its warm-up and its "
                        f"measured run; default {DEFAULT_TIMEOUT:g})")
    add_engine_module_option(parser)


def _contenders(args: argparse.Namespace) -> list[engine_costs.Contender]:
    """The contenders of ``bench engines``, checked before any run (exit 2 naming the bad
    label); reference[default] first, the ratios' denominator."""
    if args.engines:
        contenders = []
        for label in args.engines:
            try:
                choice = resolve_engine(label, engine_modules(args), field="--engine")
            except RunInputError as error:
                raise UserError(str(error)) from None
            contenders.append(engine_costs.Contender(choice.name, choice.preset))
    else:
        contenders = engine_costs.available_contenders()
    reference = engine_costs.Contender("reference", "default")
    contenders = [reference] + [c for c in contenders if c != reference]
    if args.python_loop:
        contenders.insert(1, engine_costs.Contender("reference", "default",
                                                    {"step_loop": "python"}))
    return contenders


def bench_engines(args: argparse.Namespace) -> int:
    scenes = args.scenes or scene_names()
    missing = sorted(set(scenes) - set(scene_names()))
    if missing:
        raise UserError(f"--scene: unknown scene(s) {missing}; see `clearbench list`")
    if args.steps < 1:
        raise UserError(f"--steps must be >= 1, got {args.steps}")
    if not args.timeout > 0:
        raise UserError(f"--timeout must be > 0 [s], got {args.timeout}")
    if args.against:
        ignored = [flag for flag, given in (
            ("--engine", args.engines), ("--python-loop", args.python_loop),
            ("--engine-module", args.engine_module),
            ("--timeout", args.timeout != DEFAULT_TIMEOUT)) if given]
        if ignored:
            raise UserError(f"--against times reference[default] on two revisions; "
                            f"{', '.join(ignored)} do not apply to it")
        return bench_against.run_engines_against(args, scenes)
    contenders = _contenders(args)
    reference = contenders[0].label
    print(f"Stepping cost per step [us] (stepping_seconds / steps of one run of at most "
          f"{args.steps} steps, after an untimed warm-up run), and its ratio to {reference}; "
          "the contenders in turn on each scene, in one worker process, "
          f"each run limited to {args.timeout:g} s; it/step: the contact solver's iterations "
          "per step over the run ('-' where the engine reports none, as Drake, or nothing "
          "was solved)")
    print(f"{'scene':<27} {'engine[preset]':<36} {'steps':>6} {'us/step':>10} "
          f"{'x ref':>8} {'it/step':>8}  status")
    base: dict[str, float] = {}

    def report(cost: engine_costs.EngineCost) -> None:
        if cost.contender == reference:
            base[cost.scene] = cost.seconds_per_step
        ratio = cost.seconds_per_step / base.get(cost.scene, float("nan"))
        iterations = (f"{cost.iterations_per_step:.1f}"
                      if math.isfinite(cost.iterations_per_step) else "-")
        print(f"{cost.scene:<27} {cost.contender:<36} {cost.steps:>6} "
              f"{1e6 * cost.seconds_per_step:>10.1f} {ratio:>8.3g} {iterations:>8}  "
              f"{cost.status}"
              + (f": {cost.message[:60]}" if cost.message else ""), flush=True)

    costs = engine_costs.measure(scenes, contenders, args.steps, report, args.timeout,
                                 engine_modules(args))
    ratios = engine_costs.ratios_to(costs, reference)
    print(f"\nPer contender, over the scenes both ran: median and largest ratio to {reference}")
    for contender in contenders[1:]:
        values = [r for (_, label), r in ratios.items() if label == contender.label
                  and r == r]
        if values:
            print(f"  {contender.label:<36} median {statistics.median(values):.3g}, "
                  f"range {min(values):.3g}-{max(values):.3g} over {len(values)} scenes")
    return 0


def _newton_first_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--horizon", type=float, default=1.5, metavar="MS",
                        help="simulated duration of c60-on [ms] (default 1.5)")


def bench_newton_first(args: argparse.Namespace) -> int:
    for run in speed.newton_first_runs(args.horizon):
        print(f"newton first {'on ' if run.newton_first else 'off'}: stepping "
              f"{run.stepping_seconds:.1f} s, solver {run.solver_seconds:.1f} s, iterations "
              f"per step mean {run.mean_iterations:.1f}, p90 {run.p90_iterations:.0f}, "
              f"unconverged {run.unconverged_steps}", flush=True)
    return 0


def _fc3d_sweep_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--sweeps", type=int, default=200, help="sweeps per solve (default 200)")
    parser.add_argument("--repeat", type=int, default=5,
                        help="solves per case, the fastest is kept (default 5)")


def bench_fc3d_sweep(args: argparse.Namespace) -> int:
    print(f"{'problem':44s} {'contacts':>8s} {'nnz(W)/row':>10s} {'local':>10s} "
          f"{'sweep only':>11s} {'with check':>11s}   [us per contact per sweep]")
    for row in kernel_speed.fc3d_sweep_costs(args.sweeps, args.repeat):
        print(f"{row.problem:44s} {row.contacts:8d} {row.nonzeros_per_row:10.1f} "
              f"{row.local_solver:>10s} {row.sweep_only:11.3f} {row.with_check:11.3f}")
    return 0


def bench_geometry(args: argparse.Namespace) -> int:
    print(f"{'case':60s} {'ns/call':>9s}")
    for name, nanoseconds in kernel_speed.pair_contacts_costs():
        print(f"{name:60s} {nanoseconds:9.1f}")
    return 0


# ---------------------------------------------------------------------------- physics
def _physics_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--dt", nargs="+", help="time steps (scene units; default: each scene's)")
    parser.add_argument("--tag", help="only scenes with this tag")


def bench_reference_physics(args: argparse.Namespace) -> int:
    steps = tuple(float(x) for x in args.dt) if args.dt else (None,)
    rows = physics.engine_physics_table("reference", "default", steps, args.tag)
    print("Reference engine against each library scene's expectations (scene units)")
    print(f"{'scene':<20} {'h':>8} {'expectation':<16} {'figure':<28} {'value':>12} "
          f"{'converged':>9}")
    for r in rows:
        print(f"{r.scene:<20} {r.time_step:>8.0e} {r.expectation:<16} {r.figure:<28} "
              f"{r.value:>12.3e} {str(r.converged):>9}")
    return 0


def _impact_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("scenes", nargs="*", metavar="SCENE",
                        help="bouncing-ball scenes (default: bouncing-ball-e0.5, -e0.9)")


def bench_impact_localisation(args: argparse.Namespace) -> int:
    scenes = args.scenes or ("bouncing-ball-e0.5", "bouncing-ball-e0.9")
    for row in physics.impact_localisation(scenes):
        errors = " ".join(f"{e:+.2e}" for e in row.apex_relative_errors)
        print(f"{row.scene:20s} h={row.time_step:g} s "
              f"{'localised' if row.localised else 'classic  '} apex 1-4: {errors}  after "
              f"t_inf {row.height_after_rest:.1e} m  penetration {row.penetration_max:.1e} m  "
              f"split steps {row.split_steps}", flush=True)
    return 0


def _out_option(default: str) -> Callable[[argparse.ArgumentParser], None]:
    def add(parser: argparse.ArgumentParser) -> None:
        parser.add_argument("--out", default=default, help=f"output file (default {default})")

    return add


def bench_flores_reference(args: argparse.Namespace) -> int:
    trajectory, results = physics.flores_reference()
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    trajectory.save(out)
    print(f"Flores-Leine-Glocker slider-crank, reference engine, h = 1e-5 s, 0.2 s: "
          f"{trajectory.steps} steps in {trajectory.stepping_seconds:.1f} s, "
          f"unconverged steps: {trajectory.unconverged_count}")
    for result in results:
        print(f"  {result.name}: " + ", ".join(f"{k} = {v:.3e}" for k, v in result.figures.items()))
    print(f"trajectory (every 10th step): {out}")
    return 0


def bench_scale_invariance(args: argparse.Namespace) -> int:
    rows = physics.scale_invariance()
    print("t [s]   SI vs mm-g-ms [m]   SI vs SI with the bob 1e-15 m away [m]")
    for t, units, perturbed in rows:
        print(f"{t:5.2f}   {units:17.2e}   {perturbed:17.2e}")
    return 0


def bench_clearance_ladder(args: argparse.Namespace) -> int:
    rungs = clearance_ladder.clearance_ladder()
    print("Frictionless clearance pendulum vs the exact ideal pendulum, 0.5 s")
    print(f"{'clearance [m]':>14} {'step [s]':>9} {'angle error [rad]':>18} "
          f"{'excess [m]':>11} {'converged':>9} {'stepping [s]':>12}")
    for r in rungs:
        print(f"{r.clearance:>14.0e} {r.time_step:>9.0e} {r.angle_error:>18.3e} "
              f"{r.excess:>11.1e} {str(r.converged):>9} {r.stepping_seconds:>12.2f}")
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    clearance_ladder.plot_clearance_ladder(rungs, out)
    print(f"figure: {out}")
    return 0


# ---------------------------------------------------------------------------- other engines
def _table_options(parser: argparse.ArgumentParser) -> None:
    """Options shared by ``physics-table`` and ``mujoco-table``."""
    parser.add_argument("--dt", action="append", type=float, dest="time_steps",
                        help="time step [s] (repeatable; default: 1e-3 and 1e-4)")
    parser.add_argument("--scene", action="append", dest="scenes",
                        help="scene name (repeatable; default: the analytic scenes and "
                        "clearance-pendulum)")
    parser.add_argument("--horizon", type=float,
                        help="simulated duration [scene time unit] (default: each scene's)")
    parser.add_argument("--reference", action="store_true",
                        help="add the reference solver (default preset) as a column")
    parser.add_argument("--compact", action="store_true",
                        help="one table for all scenes (a row per scene and figure)")
    _engine_option(parser)


def _engine_option(parser: argparse.ArgumentParser) -> None:
    add_engine_options_option(parser, "engine option over every preset of the table "
                              "(repeatable; checked by each engine before any run)")


def _physics_table_options(parser: argparse.ArgumentParser) -> None:
    add_engine_option(parser, many=True, flags=("--engine", "-e"),
                      help="engine and preset, e.g. 'pybullet[tuned]' (a column per engine and "
                      "time step)")
    _table_options(parser)


def _mujoco_table_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--preset", action="append", dest="presets",
                        help="MuJoCo preset (repeatable; default: default and tuned)")
    _table_options(parser)
    parser.add_argument("--no-mujoco", action="store_true",
                        help="leave out the MuJoCo columns (with --reference: the reference "
                        "column alone)")


def _engines(labels: list[str], options: dict) -> dict:
    """``ENGINE[PRESET]`` labels -> created engines, each checked (known, available, preset,
    the names and values of ``options``) before any run; UserError (exit 2) naming the bad
    value."""
    if not labels:
        raise UserError("nothing to run: give --engine ENGINE[PRESET] (or --reference)")
    engines = {}
    for label in labels:
        try:
            choice = resolve_engine(label, options=options, field="--engine")
        except RunInputError as error:
            raise UserError(str(error)) from None
        engine = importlib.import_module(choice.module).create(choice.preset)
        engines[label if label == "reference" else choice.label] = engine
    return engines


def _print_physics_table(labels: list[str], args: argparse.Namespace) -> int:
    """Check the engine labels, scenes and steps of a table (exit 2 naming the bad value, before
    any run), run every cell and print the Markdown."""
    if args.reference:
        labels = [*labels, "reference"]
    options = engine_options(args)
    engines = _engines(labels, options)
    scenes = tuple(args.scenes or physics_table.DEFAULT_SCENES)
    missing = sorted(set(scenes) - set(scene_names()))
    if missing:
        raise UserError(f"unknown scene(s) {missing}; see `clearbench list`")
    time_steps = tuple(args.time_steps or (1e-3, 1e-4))
    if any(not dt > 0 for dt in time_steps):
        raise UserError(f"--dt must be > 0, got {time_steps}")
    if args.horizon is not None and not args.horizon > 0:
        raise UserError(f"--horizon must be > 0, got {args.horizon}")
    measured = physics_table.measure(
        engines, time_steps, scenes, args.horizon,
        progress=lambda text: print(f"running {text}", file=sys.stderr, flush=True),
        options=options)
    print(physics_table.markdown_compact(measured) if args.compact
          else physics_table.markdown(measured))
    return 0


def bench_physics_table(args: argparse.Namespace) -> int:
    return _print_physics_table(list(args.engines or []), args)


def bench_mujoco_table(args: argparse.Namespace) -> int:
    presets = [] if args.no_mujoco else (args.presets or ["default", "tuned"])
    if args.no_mujoco and not args.reference:
        raise UserError("nothing to run: --no-mujoco without --reference")
    return _print_physics_table([f"mujoco[{preset}]" for preset in presets], args)


def _contact_cost_options(parser: argparse.ArgumentParser) -> None:
    add_engine_option(parser, many=True, flags=("--engine", "-e"), help="engine and preset")
    parser.add_argument("--boxes", action="append", type=int,
                        help="box count (repeatable; default: 1 4 9 16 26)")
    parser.add_argument("--dt", action="append", type=float, dest="time_steps",
                        help="time step [s] (repeatable; default: 1e-3 and 1e-4)")
    parser.add_argument("--horizon", type=float, default=contact_cost.DEFAULT_HORIZON,
                        help="simulated duration [s] (default 0.05: the 1 mm drop and settling)")
    _engine_option(parser)


def bench_contact_cost(args: argparse.Namespace) -> int:
    boxes = tuple(args.boxes or contact_cost.DEFAULT_BOXES)
    if any(count < 1 for count in boxes):
        raise UserError(f"--boxes must be >= 1, got {boxes}")
    time_steps = tuple(args.time_steps or (1e-3, 1e-4))
    if any(not dt > 0 for dt in time_steps) or not args.horizon > 0:
        raise UserError(f"--dt and --horizon must be > 0, got {time_steps}, {args.horizon}")
    options = engine_options(args)
    engines = _engines(list(args.engines or []), options)
    rows = contact_cost.contact_costs(
        engines, boxes, time_steps, args.horizon,
        progress=lambda text: print(f"running {text}", file=sys.stderr, flush=True),
        options=options)
    print(f"box_grid(count) for {args.horizon:g} s: wall time and solver iterations per "
          "nominal step (and the engine's own steps where it reports them)")
    print(contact_cost.markdown(rows))
    return 0


def bench_siconos_crosscheck(args: argparse.Namespace) -> int:
    available, detail = siconos.availability()
    if not available:
        raise UserError(f"the Siconos cross-check needs Siconos: {detail}")
    print(f"Reference solver against Siconos ({detail}), each scene at its own time step and "
          "horizon; differences are maxima over the run")
    print(siconos_crosscheck.crosscheck_markdown(siconos_crosscheck.siconos_crosscheck()))
    return 0


#: Benchmark name -> entry, in the order of ``clearbench bench --list``.
BENCHMARKS: dict[str, Benchmark] = {
    "flores-reference": Benchmark(
        "keeps the reference trajectory of the Flores slider-crank (h = 1e-5 s)",
        bench_flores_reference,
        _out_option("reports/trajectories/flores-slider-crank_reference.npz")),
    "reference-physics": Benchmark("the reference engine against every scene's expectations",
                                   bench_reference_physics, _physics_options),
    "impact-localisation": Benchmark(
        "bouncing-ball apex errors with impact localisation off (classic) and on",
        bench_impact_localisation, _impact_options),
    "scale-invariance": Benchmark(
        "clearance pendulum in SI vs mm-g-ms, and vs SI with the bob moved by 1e-15 m",
        bench_scale_invariance),
    "clearance-ladder": Benchmark("clearance pendulum -> ideal pendulum as the clearance shrinks",
                                  bench_clearance_ladder,
                                  _out_option("reports/figures/clearance_ladder.png")),
    "reference": Benchmark("us per step and per contact-iteration of the reference "
                           "(--against REV: a baseline revision side by side)",
                           bench_reference, bench_against.add_arguments),
    "c60": Benchmark("wall time and solver statistics of full c60-trip and c60-on runs "
                     "(--against REV: a baseline revision side by side)",
                     bench_c60, bench_against.add_arguments),
    "engines": Benchmark(
        "stepping cost per step of every engine[preset] on every library scene, side by "
        "side, with the ratio to the reference (--against REV: the reference on a baseline "
        "revision side by side)", bench_engines, _engines_options),
    "newton-first": Benchmark(
        "the hybrid solver with and without 'Newton first after a step that needed it' (c60-on)",
        bench_newton_first, _newton_first_options),
    "fc3d-sweep": Benchmark("us per contact per NSGS sweep on the shipped FCLIB problems",
                            bench_fc3d_sweep, _fc3d_sweep_options),
    "geometry": Benchmark("ns per pair_contacts call, from inside a numba loop", bench_geometry),
    "physics-table": Benchmark(
        "an engine's error against physics on the analytic scenes (per engine[preset] and dt)",
        bench_physics_table, _physics_table_options,
        "Run every analytic scene (and the clearance pendulum) in each --engine ENGINE[PRESET] "
        "at each time step, and print, per scene, the figures of the shared expectation "
        "evaluator (apex errors, creep, energy drift, clearance excess, ...) and the stepping "
        "time per step as Markdown tables; engine, preset, scene and step are checked before "
        "any run. With --reference, the reference solver runs the same cells."),
    "contact-cost": Benchmark(
        "cost per step as contacts grow (box_grid, per engine[preset] and dt)",
        bench_contact_cost, _contact_cost_options),
    "mujoco-table": Benchmark(
        "physics-table for MuJoCo's presets (default and tuned unless --preset)",
        bench_mujoco_table, _mujoco_table_options,
        "physics-table with --engine mujoco[PRESET] for each --preset: run every analytic "
        "scene (and the clearance pendulum) in MuJoCo with each preset at "
        "each time step, and print, per scene, the figures of the shared expectation evaluator "
        "(apex ratios, creep, energy drift, clearance excess, ...) as Markdown tables. With "
        "--reference, the reference solver runs the same cells."),
    "siconos-crosscheck": Benchmark(
        "reference solver vs Siconos 4.4 on the analytic scenes, the clearance pendulum and the "
        "Flores slider-crank", bench_siconos_crosscheck),
}


def register(subparsers) -> None:
    """Add ``bench``, with one sub-command per benchmark."""
    parser = subparsers.add_parser(
        "bench", help="run a benchmark (prints figures, asserts nothing)",
        description="Benchmarks: " + "; ".join(f"{k}: {v.summary}" for k, v in BENCHMARKS.items()),
    )
    parser.add_argument("--list", action="store_true", help="list the benchmarks")
    benchmarks = parser.add_subparsers(dest="benchmark", metavar="NAME")
    for name, benchmark in BENCHMARKS.items():
        sub = benchmarks.add_parser(name, help=benchmark.summary,
                                    description=benchmark.description or benchmark.summary)
        benchmark.add_options(sub)
    parser.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    """Run the named benchmark; without a name or with ``--list``, one line per benchmark."""
    if args.list or not args.benchmark:
        for name, benchmark in BENCHMARKS.items():
            print(f"{name:<20} {benchmark.summary}")
        return 0
    return BENCHMARKS[args.benchmark].run(args)
