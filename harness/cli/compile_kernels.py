"""``clearbench compile``: fill numba's cache of this checkout in parallel workers."""

from __future__ import annotations

import argparse
import os
import time

from clearbench.harness.cli.commands import command_help
from clearbench.harness.cli.errors import UserError
from clearbench.harness.run.numba_cache import STEP_LOOPS, fill_cache, reference_specs
from clearbench.harness.run.runner import default_jobs
from clearbench.harness.run.spec import RunInputError
from clearbench.scenarios.library import scene_names


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "compile", help=command_help("compile"),
        description="Compile the numba kernels of the reference solver (both step loops: "
        f"{', '.join(STEP_LOOPS)}) and of the measuring code into numba's cache of this "
        "checkout, by two-step runs of every registered scene in parallel workers. Runs made "
        "afterwards (tests, sweeps, campaigns) load the kernels instead of compiling them; "
        "from an empty cache this takes minutes of CPU.",
    )
    parser.add_argument("--jobs", "-j", type=int, default=None,
                        help=f"parallel worker processes (default: usable cores, here "
                        f"{default_jobs()})")
    parser.add_argument("--scenes", nargs="+", default=None, metavar="SCENE",
                        help="registered scenes (default: every one)")
    parser.set_defaults(handler=run_compile)


def run_compile(args: argparse.Namespace) -> int:
    jobs = default_jobs() if args.jobs is None else args.jobs
    if jobs < 1:
        raise UserError(f"--jobs {jobs}: must be >= 1")
    start = time.monotonic()
    try:
        specs = reference_specs(args.scenes or scene_names())
    except RunInputError as error:
        raise UserError(str(error)) from None
    cache = os.environ.get("NUMBA_CACHE_DIR", "numba's default cache directory")
    print(f"compiling into {cache}: {len(specs)} two-step runs, {jobs} workers", flush=True)
    outcome = fill_cache(specs, jobs=jobs)
    failed = [record for record in outcome.records if record.status != "ok"]
    for record in failed:
        options = record.options.strip("{}").replace('"', "")
        print(f"  {record.scene_name} ({options}): {record.status}: {record.message}")
    print(f"{len(outcome.records) - len(failed)} of {len(specs)} runs ok "
          f"({time.monotonic() - start:.0f} s)")
    return 1 if failed else 0
