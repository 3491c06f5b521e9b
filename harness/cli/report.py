"""``clearbench report``: the HTML page and Markdown summary from a results store."""

from __future__ import annotations

import argparse

from clearbench.harness.cli.commands import command_help
from clearbench.harness.cli.common import (
    add_engine_module_option,
    add_store_option,
    engine_modules,
    open_store,
)
from clearbench.harness.report.page import C60_VALIDATION, write_report


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
    add_engine_module_option(parser)
    parser.set_defaults(handler=run_report)


def run_report(args: argparse.Namespace) -> int:
    store = open_store(args, create=False)
    paths = write_report(store, args.out, args.c60_validation,
                         engine_modules=engine_modules(args))
    print(f"report: {paths['html']}")
    print(f"summary: {paths['markdown']}")
    return 0
