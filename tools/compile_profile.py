"""Where the reference solver's cold compile goes: numba's compile events, per kernel.

    XDG_CACHE_HOME=$(mktemp -d) .venv/bin/python -m tools.compile_profile bouncing-ball-e0 c60-on

Runs, in this process, the two-step warm-up runs of ``clearbench compile`` (each scene with
``step_loop`` ``auto`` then ``python``) for the given scenes (default every registered one),
with a listener on numba's ``numba:compile`` events. Give it an empty cache (a fresh
``XDG_CACHE_HOME``, as above) or it measures loading, not compiling. It prints each run's wall
time [s], then, per compiled function, the compile seconds it spent itself (its callees'
compiles subtracted: ``own``), with its callees (``with callees``), and its number of
signatures; and the kernels compiled from Python (``top``: the entry points, whose times add up
to the whole compile). ``--json PATH`` also writes the figures.
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from collections import defaultdict

import clearbench  # noqa: F401  (sets NUMBA_CACHE_DIR before numba reads its configuration)
from clearbench.harness.run.messages import WorkerRequest
from clearbench.harness.run.numba_cache import reference_specs
from clearbench.harness.run.worker import measure_phase, run_phase
from clearbench.scenarios.library import scene_names


class CompileClock:
    """A ``numba:compile`` listener: seconds per compiled function, own and with callees."""

    def __init__(self) -> None:
        self.stack: list[list[float]] = []  # [start, callees' seconds] of open compiles
        self.own: dict[str, float] = defaultdict(float)
        self.inclusive: dict[str, float] = defaultdict(float)
        self.signatures: dict[str, int] = defaultdict(int)
        self.top: dict[str, float] = defaultdict(float)

    def listener(self):
        from numba.core import event

        clock = self

        class _Listener(event.Listener):
            def on_start(self, ev) -> None:
                clock.stack.append([time.perf_counter(), 0.0])

            def on_end(self, ev) -> None:
                start, callees = clock.stack.pop()
                seconds = time.perf_counter() - start
                function = ev.data["dispatcher"].py_func
                name = f"{function.__module__}.{function.__qualname__}"
                clock.own[name] += seconds - callees
                clock.inclusive[name] += seconds
                clock.signatures[name] += 1
                if clock.stack:
                    clock.stack[-1][1] += seconds
                else:
                    clock.top[name] += seconds

        return _Listener()


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("scenes", nargs="*", help="registered scenes (default: every one)")
    parser.add_argument("--rows", type=int, default=30, help="functions printed (default 30)")
    parser.add_argument("--json", help="also write the figures to this file")
    args = parser.parse_args()
    from numba.core import event

    clock = CompileClock()
    event.register("numba:compile", clock.listener())
    runs = []
    start = time.perf_counter()
    with tempfile.TemporaryDirectory() as scratch:
        for index, spec in enumerate(reference_specs(args.scenes or scene_names())):
            tick = time.perf_counter()
            request = WorkerRequest.of(spec, f"{scratch}/{index}.npz")
            ran, scene, trajectory = run_phase(request)
            measure_phase(request, scene, trajectory)
            runs.append({"scene": spec.scene.name, "step_loop": spec.options_dict["step_loop"],
                         "seconds": time.perf_counter() - tick, "status": ran.status})
            print(f"{spec.scene.name:<26} step_loop={runs[-1]['step_loop']:<7} "
                  f"{runs[-1]['seconds']:7.1f} s  {ran.status}", flush=True)
    total = time.perf_counter() - start
    names = sorted(clock.own, key=clock.own.get, reverse=True)
    print(f"\nall runs {total:.0f} s; compiling {sum(clock.top.values()):.0f} s, "
          f"{sum(clock.signatures.values())} signatures of {len(names)} functions")
    print(f"{'own [s]':>8} {'with callees [s]':>17} {'signatures':>10}  function")
    for name in names[:args.rows]:
        print(f"{clock.own[name]:8.1f} {clock.inclusive[name]:17.1f} "
              f"{clock.signatures[name]:10d}  {name}")
    print(f"\n{'top [s]':>8}  compiled from Python")
    for name, seconds in sorted(clock.top.items(), key=lambda item: -item[1]):
        if seconds >= 0.5:
            print(f"{seconds:8.1f}  {name}")
    if args.json:
        with open(args.json, "w", encoding="utf-8") as out:
            json.dump({"runs": runs, "seconds": total, "top": clock.top,
                       "functions": [{"name": n, "own": clock.own[n],
                                      "inclusive": clock.inclusive[n],
                                      "signatures": clock.signatures[n]} for n in names]},
                      out, indent=1)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
