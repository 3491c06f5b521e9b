"""Two whole commands timed in turn (A B A B ...): wall and CPU seconds, their ratio pair by pair.

    python3 tools/time_in_turn.py -n 3 --vs "python3 -c 'import numpy'" -- \\
        .venv/bin/python -c "import clearbench.adapters.reference.engine"

A speed claim on a shared, noisy machine is a ratio of two commands measured side by side: run
in turn, the two see the same drift of the machine's speed, and the ratio A/B is taken pair by
pair. Each run is timed from outside, start-up included: wall seconds from a monotonic clock
read around the child's start and reaping; CPU seconds (user + system) from the operating
system's accounting of the child and the descendants it waited for (``os.wait4``). Prints every
run, then min, median and max of each figure: quote the median; a wide spread says the machine
was noisy. Measures and never judges: the exit status is 0 whatever the commands' own exit
codes (printed, with a note if any is not 0).

The commands run without a shell, with empty standard input and their output thrown away:
write one that needs a redirection or a pipe as ``sh -c '...'`` (and, to keep its output,
``sh -c 'exec CMD >> FILE 2>&1'``). ``--vs`` is one string, split as a shell splits words.
"""

from __future__ import annotations

import argparse
import os
import shlex
import statistics
import subprocess
import sys
import time


def time_once(command: list[str]) -> tuple[float, float, int]:
    """Run ``command`` to its end: (wall [s], user + system CPU [s], exit code)."""
    start = time.monotonic()
    child = subprocess.Popen(command, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                             stderr=subprocess.DEVNULL)
    _, status, usage = os.wait4(child.pid, 0)
    wall = time.monotonic() - start
    child.returncode = os.waitstatus_to_exitcode(status)  # reaped here: Popen must not wait
    return wall, usage.ru_utime + usage.ru_stime, child.returncode


def spread(values: list[float]) -> str:
    """``min / median / max`` of ``values``, three significant digits."""
    return f"{min(values):.4g} / {statistics.median(values):.4g} / {max(values):.4g}"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("-n", "--runs", type=int, default=3, help="timed runs of each command")
    parser.add_argument("--warmup", type=int, default=0,
                        help="untimed runs of each command first (default 0)")
    parser.add_argument("--vs", metavar="COMMAND_B", help="the baseline command, one string")
    parser.add_argument("command", nargs=argparse.REMAINDER, help="-- COMMAND_A [ARG ...]")
    args = parser.parse_args(argv)
    command_a = args.command[1:] if args.command[:1] == ["--"] else args.command
    if not command_a:
        parser.error("give the command to time after --")
    if args.runs < 1:
        parser.error(f"-n/--runs must be at least 1, got {args.runs}")
    commands = {"A": command_a}
    if args.vs:
        commands["B"] = shlex.split(args.vs)
    for name, command in commands.items():
        print(f"{name}: {shlex.join(command)}")
    for _ in range(args.warmup):
        for command in commands.values():
            time_once(command)
    figures: dict[str, list[tuple[float, float, int]]] = {name: [] for name in commands}
    for run in range(1, args.runs + 1):
        for name, command in commands.items():
            wall, cpu, code = time_once(command)
            figures[name].append((wall, cpu, code))
            print(f"run {run} {name}: wall {wall:.3f} s, cpu {cpu:.3f} s, exit {code}", flush=True)
    print(f"{'':8}{'wall [s] min / median / max':>34}{'cpu [s] min / median / max':>34}")
    for name, rows in figures.items():
        print(f"{name:8}{spread([r[0] for r in rows]):>34}{spread([r[1] for r in rows]):>34}")
    if "B" in figures:
        pairs = list(zip(figures["A"], figures["B"], strict=True))
        print(f"{'A/B':8}{spread([a[0] / b[0] for a, b in pairs]):>34}"
              f"{spread([a[1] / b[1] if b[1] else float('nan') for a, b in pairs]):>34}")
    failed = [f"{name} run {i + 1}: exit {row[2]}" for name, rows in figures.items()
              for i, row in enumerate(rows) if row[2] != 0]
    if failed:
        print("note: not every run exited 0: " + "; ".join(failed))
    return 0


if __name__ == "__main__":
    sys.exit(main())
