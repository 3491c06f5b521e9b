"""``python -m tools.c60_cad``: reduce the C-60 STEP surfaces to primitives, or check them.

An offline tool of the repository (not installed with clearbench). Without options it
re-extracts the primitives of every STEP file named by the C-60
data sheet and writes ``scenarios/c60/data/primitives.json``. With ``--check`` it compares a
fresh extraction with the committed file instead and exits with status 1 on any difference
beyond the tolerance (``--tolerance``, default
:data:`clearbench.scenarios.c60.primitives.CHECK_TOLERANCE`, absolute, in mm / rad). Both need
the optional extra ``cad`` (cadquery-ocp); without it the command fails with a clear message.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

from clearbench.scenarios.c60.primitives import (
    CHECK_TOLERANCE,
    PRIMITIVES_PATH,
    compare_documents,
    dump_document,
)
from tools.c60_cad import extract as c60_cad


class UserError(Exception):
    """Bad input or a missing optional library: one line on stderr, exit status 2."""

#: Differences printed by ``--check`` before the count of the rest.
MAX_PRINTED_DIFFERENCES = 40


def build_parser() -> argparse.ArgumentParser:
    """The tool's argument parser."""
    parser = argparse.ArgumentParser(
        prog="python -m tools.c60_cad",
        description=(
            "Re-extract the primitives of the C-60 STEP files named by the data sheet and write "
            "scenarios/c60/data/primitives.json, or with --check compare them with that file "
            "and exit with status 1 on a difference beyond the tolerance. Needs the optional "
            "extra 'cad' (cadquery-ocp)."
        ),
    )
    parser.add_argument("--check", action="store_true",
                        help="compare with the committed file instead of writing it")
    parser.add_argument("--output", type=Path, default=PRIMITIVES_PATH,
                        help="the primitives file to write or check (default: the shipped one)")
    parser.add_argument("--tolerance", type=float, default=CHECK_TOLERANCE,
                        help="absolute tolerance of --check, mm or rad (default %(default)g)")
    return parser


def run(args) -> int:
    """Extract, then write or check; returns the exit status."""
    if args.tolerance < 0:
        raise UserError(f"--tolerance must be >= 0, got {args.tolerance}")
    started = time.perf_counter()
    try:
        document = c60_cad.extract()
    except c60_cad.CadLibraryMissing as error:
        raise UserError(str(error)) from error
    elapsed = time.perf_counter() - started
    files = document["files"]
    primitives = sum(len(entry["primitives"]) for entry in files)
    unreduced = sum(len(entry["unreduced"]) for entry in files)
    residual, where = max(
        ((item["residual_mm"], entry["path"]) for entry in files for item in entry["primitives"]
         if item["kind"] in ("cylinder", "ring")),
        default=(0.0, "-"),
    )
    print(f"extracted {len(files)} files: {primitives} primitives, {unreduced} unreduced, "
          f"in {elapsed:.1f} s; worst cylinder residual {residual:.3g} mm ({where})")
    if args.check:
        if not args.output.is_file():
            raise UserError(f"no primitives file to check at {args.output}")
        committed = json.loads(args.output.read_text(encoding="utf-8"))
        differences = compare_documents(committed, document, args.tolerance)
        if differences:
            for line in differences[:MAX_PRINTED_DIFFERENCES]:
                print(f"  {line}", file=sys.stderr)
            if len(differences) > MAX_PRINTED_DIFFERENCES:
                print(f"  ... and {len(differences) - MAX_PRINTED_DIFFERENCES} more",
                      file=sys.stderr)
            print(f"{args.output}: {len(differences)} differences beyond {args.tolerance:g}",
                  file=sys.stderr)
            return 1
        print(f"{args.output}: matches (tolerance {args.tolerance:g} mm / rad)")
        return 0
    args.output.parent.mkdir(parents=True, exist_ok=True)
    args.output.write_text(dump_document(document), encoding="utf-8")
    print(f"wrote {args.output}")
    return 0


def main(argv: list[str] | None = None) -> int:
    """Entry point; returns the exit status (2 on bad input or a missing CAD library)."""
    args = build_parser().parse_args(argv)
    try:
        return run(args)
    except UserError as error:
        print(f"python -m tools.c60_cad: error: {error}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
