"""``clearbench report``: the HTML page and Markdown summary from a results store."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from clearbench.harness.cli.commands import command_help
from clearbench.harness.cli.common import (
    UserError,
    add_engine_module_option,
    add_store_option,
    engine_modules,
    open_store,
)
from clearbench.harness.report.page import C60_VALIDATION, write_report
from clearbench.harness.report.readme_table import RESULTS, update_readme, write_results


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "report", help=command_help("report"),
        description="Read a results store and write a self-contained HTML page (figures "
        "embedded) and a Markdown summary: overview matrix scene x engine, the stiff suite, "
        "per scene a metrics table, work–precision plot and drift over time, and the "
        "approximations each engine states.",
    )
    add_store_option(parser)
    parser.add_argument("--out", default="reports/out", metavar="DIR",
                        help="output directory (default reports/out)")
    parser.add_argument("--c60-validation", default=str(C60_VALIDATION), metavar="JSON",
                        help="JSON of `clearbench c60 validate` to include as the C-60 section "
                        f"(default {C60_VALIDATION}; left out when the file does not exist)")
    parser.add_argument("--readme", nargs="?", const="README.md", default=None,
                        metavar="README",
                        help="also keep the report's conclusions as reports/results.json and "
                        "rewrite README's generated results table from them (default "
                        "README.md)")
    parser.add_argument("--from-results", default=None, metavar="JSON",
                        help="with --readme: rewrite the table from this results.json (the "
                        "committed reports/results.json) without reading a store")
    add_engine_module_option(parser)
    parser.set_defaults(handler=run_report)


def _readme(readme: Path, results: dict) -> None:
    try:
        changed = update_readme(readme, results)
    except (OSError, ValueError) as error:
        raise UserError(f"--readme {readme}: {error}") from None
    print(f"readme: {readme} {'rewritten' if changed else 'unchanged'}")


def run_report(args: argparse.Namespace) -> int:
    if args.from_results is not None:
        if args.readme is None:
            raise UserError("--from-results: give --readme too (it only rewrites the README)")
        try:
            results = json.loads(Path(args.from_results).read_text(encoding="utf-8"))
        except (OSError, ValueError) as error:
            raise UserError(f"--from-results {args.from_results}: {error}") from None
        _readme(Path(args.readme), results)
        return 0
    store = open_store(args, create=False)
    paths = write_report(store, args.out, args.c60_validation,
                         engine_modules=engine_modules(args))
    print(f"report: {paths['html']}")
    print(f"summary: {paths['markdown']}")
    if args.readme is not None:
        results = json.loads(paths["results"].read_text(encoding="utf-8"))
        write_results(results, RESULTS)
        print(f"results: {RESULTS}")
        _readme(Path(args.readme), results)
    return 0
