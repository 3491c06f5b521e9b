"""``clearbench fclib``: our contact solvers on FCLIB problems, side by side with Siconos."""

from __future__ import annotations

import csv
import math
from pathlib import Path

from clearbench.adapters.siconos.run import siconos_availability
from clearbench.harness.cli.commands import command_help
from clearbench.harness.cli.common import UserError
from clearbench.harness.fclib.compare import (
    ALL_SOLVERS,
    CompareSettings,
    RunRow,
    compare_problem,
    default_solvers,
    plot_performance_profile,
    warm_up_jit,
)
from clearbench.harness.fclib.problems import (
    UnsupportedProblemError,
    load_problem,
    shipped_problem_files,
)


def register(subparsers) -> None:
    """Add the ``fclib`` sub-command."""
    parser = subparsers.add_parser(
        "fclib",
        help=command_help("fclib"),
        description=(
            "Solve FCLIB / Siconos frictional contact problems with our solvers and, when "
            "Debian's python3-siconos is installed, with Siconos NSGS-AC and NSN-AC. Every "
            "answer is judged by our natural-map residual in both normalisations."
        ),
    )
    parser.add_argument("files", nargs="*", metavar="FILE",
                        help="problem files (.hdf5 FCLIB or .dat Siconos); default: all shipped")
    parser.add_argument("--solver", action="append", choices=ALL_SOLVERS, dest="solvers",
                        help="solver to run (repeatable); default: nsgs-ac, newton-ac and, if "
                             "available, siconos-nsgs-ac, siconos-nsn-ac")
    parser.add_argument("--tol", type=float, default=1e-8, help="tolerance (default 1e-8)")
    parser.add_argument("--normalisation", choices=("max", "q"), default="max",
                        help="residual that the tolerance applies to: |F|/max(|q|,|r|,|u|) "
                             "(default, Siconos's own stopping measure) or |F|/|q|")
    parser.add_argument("--max-sweeps", type=int, default=20_000,
                        help="NSGS sweep cap, ours and Siconos's (default 20000)")
    parser.add_argument("--max-newton", type=int, default=500,
                        help="Newton iteration cap, ours and Siconos's (default 500)")
    parser.add_argument("--repeat", type=int, default=3,
                        help="solves per (problem, solver), at least; the fastest time is kept "
                             "(default 3)")
    parser.add_argument("--min-time", type=float, default=0.2,
                        help="repeat faster solves (ours and Siconos's, up to 1000 times) until "
                             "they total this many seconds (default 0.2)")
    parser.add_argument("--timeout", type=float, default=300.0,
                        help="wall-clock limit of one Siconos worker, seconds (default 300)")
    parser.add_argument("--no-siconos", action="store_true", help="do not run Siconos")
    parser.add_argument("--out", type=Path, help="write all runs to this CSV file")
    parser.add_argument("--profile", type=Path,
                        help="write a Dolan-More performance profile PNG (needs >= 2 solvers)")
    parser.set_defaults(handler=run)


def _format_row(row: RunRow) -> str:
    time_ms = f"{1e3 * row.wall_time:10.3f}" if math.isfinite(row.wall_time) else f"{'-':>10s}"
    ratio = f"{row.time_ratio:7.2f}" if math.isfinite(row.time_ratio) else f"{'-':>7s}"
    return (f"  {row.solver:16s} {row.iterations:8d} {time_ms} {row.residual_q:10.2e} "
            f"{row.residual_max:10.2e} {row.status:15s} {'yes' if row.solved else 'NO':6s} {ratio}")


def run(args) -> int:
    files = [Path(f) for f in args.files] or shipped_problem_files()
    for path in files:
        if not path.is_file():
            raise UserError(f"no such problem file: {path}")
    if args.tol <= 0.0 or args.max_sweeps < 1 or args.max_newton < 1 or args.repeat < 1:
        raise UserError("--tol, --max-sweeps, --max-newton and --repeat must be positive")
    if not args.min_time >= 0.0:
        raise UserError("--min-time must be >= 0")
    available, message = siconos_availability()
    with_siconos = available and not args.no_siconos
    solvers = list(dict.fromkeys(args.solvers or default_solvers(with_siconos)))
    if not with_siconos:
        dropped = [s for s in solvers if s.startswith("siconos-")]
        solvers = [s for s in solvers if not s.startswith("siconos-")]
        if not args.no_siconos:
            print(f"{message}: Siconos columns skipped" + (f" ({', '.join(dropped)})"
                                                          if dropped else ""))
    if not solvers:
        raise UserError("no solver left to run")
    settings = CompareSettings(tolerance=args.tol, normalisation=args.normalisation,
                               max_sweeps=args.max_sweeps, max_newton=args.max_newton,
                               repeat=args.repeat, timeout=args.timeout,
                               min_time=args.min_time)
    warm_up_jit()
    norm_text = "|F|/|q|" if args.normalisation == "q" else "|F|/max(|q|,|r|,|u|)"
    print(f"tolerance {args.tol:g} on {norm_text}; times: fastest of >= {args.repeat} solves "
          f"(repeated up to {args.min_time:g} s in total), output allocation included on both "
          "sides; ratio = our time / Siconos counterpart time (NSGS vs NSGS-AC, Newton vs "
          "NSN-AC)")
    header = (f"  {'solver':16s} {'iters':>8s} {'time [ms]':>10s} {'|F|/|q|':>10s} "
              f"{'|F|/max':>10s} {'status':15s} {'solved':6s} {'ratio':>7s}")
    all_rows: list[RunRow] = []
    for path in files:
        try:
            loaded = load_problem(path)
        except UnsupportedProblemError as error:
            print(f"\n{path.name}: skipped: {error}")
            continue
        except (OSError, ValueError) as error:
            raise UserError(f"cannot read {path}: {error}") from error
        problem = loaded.problem
        print(f"\n{loaded.name} ({loaded.kind}, {problem.n_contacts} contacts, "
              f"{problem.W_csr().nnz} nonzeros in W)")
        print(header)
        rows = compare_problem(loaded, solvers, settings)
        for row in rows:
            print(_format_row(row))
        all_rows.extend(rows)
    if args.out and all_rows:
        args.out.parent.mkdir(parents=True, exist_ok=True)
        with args.out.open("w", newline="") as handle:
            writer = csv.DictWriter(handle, fieldnames=list(all_rows[0].as_dict()))
            writer.writeheader()
            writer.writerows(row.as_dict() for row in all_rows)
        print(f"\nruns written to {args.out}")
    if args.profile:
        if len(solvers) < 2:
            raise UserError("--profile needs at least two solvers")
        args.profile.parent.mkdir(parents=True, exist_ok=True)
        plot_performance_profile(all_rows, args.profile,
                                 title=f"FCLIB problems, tol {args.tol:g} on {norm_text}")
        print(f"performance profile written to {args.profile}")
    return 0
