"""``clearbench campaign``: tolerance studies (Monte Carlo over scene parameters) on Dask.

- ``clearbench campaign run FILE|NAME``: run every sample not yet in the store (resumable);
- ``clearbench campaign report FILE|NAME [--with FILE|NAME ...]``: statistics, histograms,
  convergence and sensitivities as Markdown, HTML, JSON and CSV;
- ``clearbench campaign status FILE|NAME``: how many samples are recorded, by status.

A campaign with ``method = "metamodel"`` runs its design in batches until its metamodel's
targets are met or its budget ends (``--given CSV`` takes design runs from a campaign's CSV),
and its report compares it with a sampling campaign (``--against NAME``).
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from clearbench.harness.cli.commands import command_help
from clearbench.harness.cli.common import (
    UserError,
    add_engine_option,
    add_store_option,
    open_store,
)
from clearbench.harness.run.runner import MANY_RUNS_PER_WORKER
from clearbench.harness.studies.campaign.adaptive import (
    design_table,
    load_state,
    run_metamodel_campaign,
    state_path,
)
from clearbench.harness.studies.campaign.definition import (
    SHIPPED,
    CampaignError,
    load_campaign,
    with_overrides,
)
from clearbench.harness.studies.campaign.execution import plan_samples, run_campaign
from clearbench.harness.studies.campaign.metamodel_report import write_metamodel_report
from clearbench.harness.studies.campaign.report import write_campaign_report

#: Where reports go by default.
DEFAULT_OUT = "reports/campaigns"


def register(subparsers) -> None:
    """Add the ``campaign`` command and its sub-commands."""
    parser = subparsers.add_parser(
        "campaign", help=command_help("campaign"),
        description="A tolerance campaign draws scene parameters (e.g. the C-60's joint "
        "clearances) from their laws, runs one isolated run per sample into the results "
        "store, and summarises the outputs with capability indices. Shipped campaigns: "
        + ", ".join(SHIPPED) + ".")
    commands = parser.add_subparsers(dest="campaign_command", metavar="SUBCOMMAND")
    commands.required = True

    run = commands.add_parser("run", help="run the samples not yet in the store")
    _add_definition_options(run)
    run.add_argument("--scheduler", default=os.environ.get("CLEARBENCH_DASK_SCHEDULER"),
                     metavar="ADDRESS", help="a running Dask scheduler (tcp://host:8786); "
                     "default: a LocalCluster on this machine ($CLEARBENCH_DASK_SCHEDULER)")
    run.add_argument("--workers", type=int, default=None,
                     help="LocalCluster worker processes (default: usable cores)")
    run.add_argument("--runs-per-worker", type=int, default=MANY_RUNS_PER_WORKER, metavar="N",
                     help="samples a worker's run process serves before it is replaced (default "
                     f"{MANY_RUNS_PER_WORKER}; 1: a fresh process per sample; a crashed or "
                     "timed-out one always is)")
    run.add_argument("--no-progress", action="store_true", help="no progress bar")
    _add_given_option(run)
    run.set_defaults(handler=_run)

    report = commands.add_parser("report", help="write the campaign's report section")
    _add_definition_options(report)
    report.add_argument("--with", dest="companions", action="append", default=[],
                        metavar="FILE|NAME", help="another campaign of the same study (another "
                        "design), drawn in the convergence figures (repeatable)")
    report.add_argument("--out", default=DEFAULT_OUT, metavar="DIR",
                        help=f"output folder (default {DEFAULT_OUT})")
    report.add_argument("--against", default=None, metavar="NAME",
                        help="metamodel campaigns: a sampling campaign whose report is in the "
                        "output folder, shown side by side")
    report.add_argument("--given", default=[], action="append", metavar="CSV",
                        help="runs the store lacks, taken from a campaign's CSV (written by "
                        "'campaign report', maybe by another revision of the code) for the "
                        "samples it holds with the same inputs; repeatable for the --with "
                        "campaigns (a metamodel campaign takes one)")
    report.set_defaults(handler=_report)

    status = commands.add_parser("status", help="recorded samples by status")
    _add_definition_options(status)
    status.set_defaults(handler=_status)


def _add_definition_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("campaign", metavar="FILE|NAME",
                        help="campaign TOML file, or a shipped campaign: " + ", ".join(SHIPPED))
    parser.add_argument("--samples", type=int, default=None,
                        help="number of samples (overrides the file)")
    add_engine_option(parser, many=False, flags=("--engine", "-e"),
                      help="engine (overrides the file)")
    add_store_option(parser)


def _add_given_option(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--given", default=None, metavar="CSV",
                        help="metamodel campaigns: design runs taken from a campaign's CSV "
                        "(written by 'campaign report', maybe by another revision of the "
                        "code) for the samples it holds with the same inputs")


def _given(args: argparse.Namespace):
    """The ``--given`` CSV as a DataFrame (None without one); a metamodel campaign's report
    takes at most one."""
    given = getattr(args, "given", None)
    if isinstance(given, list):
        if len(given) > 1:
            raise UserError(f"--given {given[1]}: a metamodel campaign takes one CSV")
        given = given[0] if given else None
    return None if not given else _read_given(given)


def _read_given(text: str):
    import pandas as pd  # lazily, as the results store does

    try:
        table = pd.read_csv(Path(text))
    except (OSError, ValueError) as error:
        raise UserError(f"--given {text}: {error}") from None
    missing = {"sample", "status", "message"} - set(table.columns)
    if missing:
        raise UserError(f"--given {text}: not a campaign CSV (no column "
                        f"{sorted(missing)[0]!r})")
    return table


def _definition(args: argparse.Namespace, text: str | None = None):
    try:
        definition = load_campaign(text or args.campaign)
        return with_overrides(definition, samples=args.samples, engine=args.engine)
    except CampaignError as error:
        raise UserError(f"{text or args.campaign}: {error}") from None


def _run(args: argparse.Namespace) -> int:
    definition = _definition(args)
    if args.workers is not None and args.workers < 1:
        raise UserError(f"--workers {args.workers}: must be >= 1")
    if args.runs_per_worker < 1:
        raise UserError(f"--runs-per-worker {args.runs_per_worker}: must be >= 1")
    workers = args.workers or max(1, len(os.sched_getaffinity(0)))
    store = open_store(args)
    progress = not args.no_progress and sys.stderr.isatty()
    given = _given(args)
    try:
        if definition.method == "metamodel":
            state = run_metamodel_campaign(definition, store, scheduler=args.scheduler,
                                           workers=workers, progress=progress, given=given,
                                           runs_per_worker=args.runs_per_worker)
            short = state["stages"][-1]["short"]
            print(f"{definition.name}: stopped ({state['stop']}) after {state['runs']} runs "
                  f"of {definition.samples}" + (": " + "; ".join(short) if short else "")
                  + f"; state in {state_path(store, definition)}")
            return 0
        outcome = run_campaign(definition, store, scheduler=args.scheduler, workers=workers,
                               progress=progress, runs_per_worker=args.runs_per_worker)
    except CampaignError as error:
        raise UserError(f"{args.campaign}: {error}") from None
    print(f"{definition.name}: {outcome.planned} samples planned, {outcome.already} already in "
          f"{store.directory}, {outcome.recorded} run now {outcome.statuses or ''}")
    return 0


def _report(args: argparse.Namespace) -> int:
    definition = _definition(args)
    companions = tuple(_definition(args, text) for text in args.companions)
    # runs given from CSVs need no store of runs: an empty one is made (the campaign's log,
    # for the throughput, is read from it)
    store = open_store(args, create=bool(args.given))
    if definition.method == "metamodel":
        return _metamodel_report(args, definition, store)
    given = {text: _read_given(text) for text in args.given}
    try:
        summary = write_campaign_report(definition, store, Path(args.out), companions, given)
    except CampaignError as error:
        raise UserError(f"{args.campaign}: {error}") from None
    print(f"{definition.name}: {summary['statuses']}; report in {args.out}/"
          f"{definition.name}.md and .html")
    return 0


def _metamodel_report(args: argparse.Namespace, definition, store) -> int:
    state = load_state(store, definition)
    if not state.get("stages"):
        raise UserError(f"{args.campaign}: no metamodel state in {store.directory}: run "
                        f"'clearbench campaign run {args.campaign}' first")
    try:
        table = design_table(definition, store, state["stages"][-1]["size"], _given(args))
        write_metamodel_report(definition, state, Path(args.out), args.against, table)
    except (CampaignError, FileNotFoundError) as error:
        raise UserError(f"{args.campaign}: {error}") from None
    print(f"{definition.name}: {state['stop']} after {state['runs']} runs; report in "
          f"{args.out}/{definition.name}.md and .html")
    return 0


def _status(args: argparse.Namespace) -> int:
    definition = _definition(args)
    store = open_store(args, create=False)
    try:
        samples = plan_samples(definition)
    except CampaignError as error:
        raise UserError(f"{args.campaign}: {error}") from None
    counts: dict[str, int] = {}
    for sample in samples:
        row = store.get(sample.spec.key)
        status = row["status"] if row else "pending"
        counts[status] = counts.get(status, 0) + 1
    print(f"{definition.name}: {len(samples)} samples: "
          + ", ".join(f"{k} {v}" for k, v in sorted(counts.items())))
    return 0
