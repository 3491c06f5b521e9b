"""``clearbench c60 validate``: the C-60 validation table against the published figures.

Runs the C-60 scenes it needs with the reference engine (cached per scene content in
``--cache``), prints the table and writes it as Markdown with force-displacement figures.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

from clearbench.harness.cli.main import UserError

DEFAULT_REPORT = Path("reports/c60_validation.md")
DEFAULT_FIGURES = Path("reports/figures")
DEFAULT_CACHE = Path(".cache/c60")


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "c60", help="C-60 circuit breaker: validation against the published figures",
        description="C-60 circuit-breaker tools. `clearbench c60 validate` runs the C-60 "
        "scenes with the reference engine and compares FC-1, the functional conditions, the "
        "trip and the bench tests of Section 5 with the paper's figures.",
    )
    commands = parser.add_subparsers(dest="c60_command", metavar="C60_COMMAND")
    commands.required = True
    validate = commands.add_parser(
        "validate", help="run the C-60 scenes and write the validation table",
        description="Run (or read from the cache) the C-60 scenes, print the validation "
        "table, write it as Markdown and the force-displacement figures as PNG. A full run "
        "takes tens of minutes of stepping on one core; cached runs are reused when the "
        "scene, the preset and the physics code (scenes, solver, adapters) are unchanged.",
    )
    validate.add_argument("--out", type=Path, default=DEFAULT_REPORT,
                          help=f"Markdown report (default {DEFAULT_REPORT})")
    validate.add_argument("--figures", type=Path, default=DEFAULT_FIGURES,
                          help=f"directory of the PNG figures (default {DEFAULT_FIGURES})")
    validate.add_argument("--cache", type=Path, default=DEFAULT_CACHE,
                          help=f"directory of cached trajectories (default {DEFAULT_CACHE})")
    validate.add_argument("--preset", default="default", help="reference engine preset")
    validate.add_argument("--no-speed-check", action="store_true",
                          help="skip the half-speed reruns of the bench tests")
    validate.add_argument("--no-sensitivity", action="store_true",
                          help="skip the sensitivity runs (design arm, alternative preload)")
    validate.set_defaults(handler=run_validate)


def run_validate(args: argparse.Namespace) -> int:
    from clearbench.adapters.reference.engine import PRESETS
    from clearbench.harness.c60.validation import (
        validate,
        write_figures,
        write_json,
        write_markdown,
    )

    if args.preset not in PRESETS:
        raise UserError(f"unknown preset {args.preset!r}; presets: {', '.join(PRESETS)}")
    report = validate(cache=args.cache, preset=args.preset,
                      speed_check=not args.no_speed_check,
                      sensitivity=not args.no_sensitivity)
    print(f"{'quantity':<78} {'ours':>9} {'sim.':>7} {'meas.':>7} {'diff':>8}")
    for row in report.rows:
        difference = row.difference()
        text = "" if math.isnan(difference) else f"{100 * difference:+.1f}%"
        print(f"{row.quantity[:78]:<78} {row.ours:>9.4f} {row.paper_simulated:>7.3f} "
              f"{row.paper_measured:>7.3f} {text:>8}")
    for finding in report.findings:
        print(f"- {finding}")
    figures = write_figures(report, args.figures)
    write_markdown(report, args.out, figures, args.preset)
    write_json(report, args.out.with_suffix(".json"), figures, args.preset)
    print(f"report: {args.out} (and {args.out.with_suffix('.json')} for `clearbench report`)")
    for path in figures.values():
        print(f"figure: {path}")
    return 0
