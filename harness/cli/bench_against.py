"""``clearbench bench c60|reference|engines --against REV``: a baseline revision and this one
side by side, measured alternately in one session (:mod:`clearbench.harness.studies.against`)."""

from __future__ import annotations

import argparse
import statistics

from clearbench.harness.cli.common import UserError
from clearbench.harness.studies.against import Case, resolve, side_by_side
from clearbench.scenarios.library import get_scene

#: Cases of each benchmark that supports ``--against``: (scene, factory parameters, horizon
#: [scene time unit; None: the scene's]); every preset of ``--presets`` runs each.
CASES = {
    "c60": (("c60-trip", {}, None), ("c60-on", {}, None)),
    "reference": (("clearance-pendulum", {}, 1.0), ("box-grid", {"count": 30}, 0.2)),
}
DEFAULT_PRESETS = {"c60": ("default", "newton"), "reference": ("default",)}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The options of ``--against`` on the parser of a benchmark that supports it."""
    parser.add_argument("--against", metavar="REV",
                        help="c60, reference: also run the baseline git revision REV, "
                        "alternately with this one in one session, and print the ratio")
    parser.add_argument("--repeat", type=int, default=2,
                        help="--against: runs of each case on each side (best one kept)")
    parser.add_argument("--horizon", type=float,
                        help="--against: simulated time of each run (scene units; default the "
                        "benchmark's)")
    parser.add_argument("--presets", nargs="+", help="--against: reference presets")
    parser.add_argument("--dt", nargs="+", type=float, metavar="DT",
                        help="--against: run each case at each of these time steps (scene "
                        "time unit, e.g. ms for the C-60; default the scene's)")
    parser.add_argument("--scenes", nargs="+", help="--against: only these scenes")


def refuse_without_baseline(args: argparse.Namespace) -> None:
    """A UserError naming the first ``--against``-only flag given without ``--against`` (it
    would otherwise be ignored)."""
    for flag in ("dt", "presets", "scenes", "horizon"):
        if getattr(args, flag, None) is not None:
            raise UserError(f"--{flag} {getattr(args, flag)} applies only with --against REV")


def _checked_baseline(args: argparse.Namespace) -> str:
    """The full commit of ``--against`` (a UserError when git does not know it, or when
    ``--repeat`` is below 1), before any run."""
    try:
        commit = resolve(args.against)
    except ValueError as error:
        raise UserError(str(error)) from error
    if args.repeat < 1:
        raise UserError(f"--repeat must be >= 1, got {args.repeat}")
    for step in getattr(args, "dt", None) or ():
        if not step > 0.0:
            raise UserError(f"--dt must be > 0 (a time step in the scene's time unit), got {step}")
    return commit


def _checked_scenes(args: argparse.Namespace) -> None:
    """A UserError naming the first ``--scenes`` name that is not a case of ``bench c60`` or
    ``bench reference``, before any run (the filter would drop it without a word)."""
    known = [scene for scene, _, _ in CASES[args.benchmark]]
    for scene in args.scenes or ():
        if scene not in known:
            raise UserError(f"--scenes {scene!r} is not a case of bench {args.benchmark} "
                            f"--against (its cases: {', '.join(known)}; 'bench engines "
                            f"--against REV --scene NAME' takes any library scene)")


def run_against(args: argparse.Namespace) -> int:
    commit = _checked_baseline(args)
    _checked_scenes(args)
    presets = args.presets or DEFAULT_PRESETS[args.benchmark]
    cases = [Case(scene, preset, args.horizon or horizon, parameters, step)
             for preset in presets for scene, parameters, horizon in CASES[args.benchmark]
             if not args.scenes or scene in args.scenes for step in args.dt or (None,)]
    print(f"Reference engine, baseline {args.against} ({commit[:10]}) and this revision, "
          f"alternately in one session, {args.repeat} run(s) of each on each side, best kept "
          "(stepping wall time after a warm-up that compiles)")
    print(f"{'scene':<19} {'preset':<8} {'dt':>7} {'steps':>6} {'base [s]':>9} {'this [s]':>9} "
          f"{'speed-up':>8} {'base us/st':>10} {'this us/st':>10} {'unconv b/t':>11} "
          f"{'iter/step b/t':>14}")

    def report(pair) -> None:
        step = "scene's" if pair.case.time_step is None else f"{pair.case.time_step:g}"
        if pair.error:
            print(f"{pair.case.scene:<19} {pair.case.preset:<8} {step:>7} {pair.error}",
                  flush=True)
            return
        b, c = pair.best_baseline, pair.best_current
        steps = c["steps"]
        print(f"{pair.case.scene:<19} {pair.case.preset:<8} {step:>7} {steps:>6} "
              f"{b['stepping_seconds']:>9.2f} {c['stepping_seconds']:>9.2f} "
              f"{pair.speedup:>8.2f} {1e6 * b['stepping_seconds'] / b['steps']:>10.1f} "
              f"{1e6 * c['stepping_seconds'] / steps:>10.1f} "
              f"{b['unconverged_steps']:>5}/{c['unconverged_steps']:<5} "
              f"{b['mean_iterations']:>6.0f}/{c['mean_iterations']:<7.0f}", flush=True)

    side_by_side(cases, args.against, args.repeat, report)
    return 0


def run_engines_against(args: argparse.Namespace, scenes: list[str]) -> int:
    """``bench engines --against REV``: the reference[default]'s stepping cost per step on each
    of ``scenes`` (at most ``args.steps`` steps at the scene's time step), on the baseline
    revision and on this one, alternately in one session."""
    commit = _checked_baseline(args)
    cases = []
    for name in scenes:
        scene = get_scene(name)
        cases.append(Case(name, "default", min(scene.horizon, args.steps * scene.time_step)))
    print(f"reference[default], baseline {args.against} ({commit[:10]}) and this revision, "
          f"alternately in one session: stepping cost per step [us] of runs of at most "
          f"{args.steps} steps (best of {args.repeat} on each side, after an untimed 20-step "
          "warm-up), and the speed-up (baseline / this)")
    print(f"{'scene':<27} {'steps':>6} {'base us/st':>11} {'this us/st':>11} {'speed-up':>8} "
          f"{'unconv b/t':>11}")
    speedups = []

    def report(pair) -> None:
        if pair.error:
            print(f"{pair.case.scene:<27} {pair.error[:90]}", flush=True)
            return
        b, c = pair.best_baseline, pair.best_current
        speedups.append(pair.speedup)
        print(f"{pair.case.scene:<27} {c['steps']:>6} "
              f"{1e6 * b['stepping_seconds'] / b['steps']:>11.1f} "
              f"{1e6 * c['stepping_seconds'] / c['steps']:>11.1f} {pair.speedup:>8.2f} "
              f"{b['unconverged_steps']:>5}/{c['unconverged_steps']:<5}", flush=True)

    side_by_side(cases, args.against, args.repeat, report)
    if speedups:
        print(f"\nspeed-up over {len(speedups)} scenes: median "
              f"{statistics.median(speedups):.3g}, range {min(speedups):.3g}-"
              f"{max(speedups):.3g}")
    return 0
