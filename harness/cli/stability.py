"""``clearbench stability``: the stiff and extreme suite, each engine's verdict per case."""

from __future__ import annotations

import argparse

from clearbench.harness.cli.commands import command_help
from clearbench.harness.cli.common import (
    UserError,
    add_engine_option,
    add_runner_options,
    engine_modules,
    make_runner,
    open_store,
)
from clearbench.harness.measure.headline import METRIC_LABELS, format_value
from clearbench.harness.measure.units import unit_text
from clearbench.harness.measure.verdicts import run_verdict, verdict_text
from clearbench.harness.studies.stability import (
    available_engines,
    plan_stability,
    stability_rows,
)
from clearbench.harness.studies.sweep import resolve_engines
from clearbench.scenarios.tags import STIFF


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "stability", help=command_help("stability"),
        description=f"Run every scene tagged {STIFF!r} (tight clearances, mass ratio 1e4, stiff "
        "springs, 10x steps, tunnelling impacts, mu = 2, e = 1, 100+ contacts, millimetre parts "
        "in SI units) in each engine at the case's own step, and print each engine's verdict "
        "(pass / physics failed / diverged / crashed / timed out / unsupported) with the metrics "
        "of the case.",
    )
    add_engine_option(parser, many=True,
                      help="engines (default: every available engine, default preset)")
    parser.add_argument("--scenes", nargs="+", default=None, metavar="SCENE",
                        help=f"only these cases (default: every scene tagged {STIFF!r})")
    add_runner_options(parser, timeout=300.0)
    parser.set_defaults(handler=run_stability)


def run_stability(args: argparse.Namespace) -> int:
    modules = engine_modules(args)
    engines = (resolve_engines(args.engines, modules) if args.engines
               else available_engines(modules))
    if not engines:
        raise UserError("no engine is available here (see `clearbench list`)")
    specs = plan_stability(engines, args.scenes, timeout=args.timeout)
    store = open_store(args)
    runner = make_runner(args, store, len(specs))
    outcome = runner.run_all(specs, rerun=args.rerun)
    print(f"{len(outcome.ran)} runs done, {len(outcome.skipped)} already in {store.directory}")
    rows = stability_rows(store.dataframe(), specs)
    scenes = {spec.scene.name: spec.scene for spec in specs}
    case = None
    for row in rows:
        if row["case"] != case:
            case = row["case"]
            print(f"\n{case}: {row['summary']}")
        verdict = verdict_text(run_verdict(row["status"], row["expectations_passed"],
                                           row["verdict_figures"]))
        scene = scenes.get(row["case"])
        figures = ", ".join(
            f"{METRIC_LABELS.get(n, (n,))[0]} {format_value(v, unit_text(n, scene, short=True))}"
            for n, v in row["metrics"].items())
        print(f"  {row['engine']:<24} {verdict}")
        if row["reason"] and row["status"] != "ok":
            print(f"  {'':<24} {row['reason']}")
        if figures:
            print(f"  {'':<24} {figures}")
    return 0
