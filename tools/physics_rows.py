"""The reference engine's expectation figures, scene by scene at full precision, and two such
tables compared: is a revision's physics unchanged?

    .venv/bin/python tools/physics_rows.py [SCENE ...] [--option KEY=VALUE ...] > this.tsv
    (cd BASE_CHECKOUT && .venv/bin/python /path/to/tools/physics_rows.py [SCENE ...]) > base.tsv
    python3 tools/physics_rows.py --compare base.tsv this.tsv

The first form runs what ``clearbench bench reference-physics`` runs (every library scene, or
the given ones, over its whole horizon at its own step, reference[default]) and prints a
tab-separated row per figure as each scene ends (scene, time step, expectation, figure, value,
every step converged, stepping seconds): a long call keeps what it has measured. It uses only
``engine_physics_table`` and ``scene_names``, so it runs in a checkout of an older revision too
(run with that checkout's Python). ``--compare`` prints every figure whose value differs
between the two tables, with the relative difference and which magnitude is larger, the
scenes and figures only one table has (a scene or an expectation figure added between the
revisions), and a summary line. A figure can differ because the solver's trajectory differs
or because the evaluator (``harness/measure``) changed between the revisions: compare the
trajectories themselves to tell which.
"""

from __future__ import annotations

import argparse
import math
import sys
import time


def measure(names: list[str], options: dict | None = None) -> None:
    """Print the rows of each scene of ``names`` (all library scenes when empty), with the
    reference's ``options`` when given (a revision that predates them is run without)."""
    from clearbench.harness.studies.benchmarks import physics
    from clearbench.scenarios.library import scene_names

    library = physics.scene_names
    for name in names or scene_names():
        start = time.perf_counter()
        physics.scene_names = lambda tag=None, only=name: [only]  # one scene per table
        try:
            rows = (physics.engine_physics_table("reference", "default", options=options)
                    if options else physics.engine_physics_table("reference", "default"))
        except Exception as error:  # a scene that fails is a row, the others go on
            print(f"{name}\tERROR\t{type(error).__name__}: {error}", flush=True)
            continue
        finally:
            physics.scene_names = library
        for r in rows:
            print(f"{r.scene}\t{r.time_step!r}\t{r.expectation}\t{r.figure}\t{r.value!r}\t"
                  f"{r.converged}\t{r.stepping_seconds:.2f}", flush=True)
        print(f"# {name} done in {time.perf_counter() - start:.0f} s", flush=True)


def read(path: str) -> dict[tuple[str, str, str, str], tuple[float, str]]:
    """(scene, time step, expectation, figure) -> (value, converged) of a table."""
    table = {}
    with open(path) as rows:
        for line in rows:
            fields = line.rstrip("\n").split("\t")
            if line.startswith("#") or len(fields) < 6:
                continue
            table[tuple(fields[:4])] = (float(fields[4]), fields[5])
    return table


def compare(base_path: str, this_path: str) -> int:
    """Print the figures that differ between two tables; return the count of differences."""
    base, this = read(base_path), read(this_path)
    differ = 0
    for key in sorted(base.keys() & this.keys()):
        (b, b_ok), (t, t_ok) = base[key], this[key]
        same = b == t or (math.isnan(b) and math.isnan(t))
        if same and b_ok == t_ok:
            continue
        differ += 1
        scale = max(abs(b), abs(t))
        relative = abs(t - b) / scale if scale > 0 else 0.0
        larger = "equal" if abs(t) == abs(b) else ("this" if abs(t) > abs(b) else "base")
        print(f"{' '.join(key[:1] + key[2:])}: base {b!r} ({b_ok}), this {t!r} ({t_ok}), "
              f"relative difference {relative:.2e}, larger magnitude: {larger}")
    base_scenes, this_scenes = {k[0] for k in base}, {k[0] for k in this}
    for label, scenes in (("base", base_scenes - this_scenes), ("this", this_scenes - base_scenes)):
        if scenes:
            print(f"scenes in {label} only: " + ", ".join(sorted(scenes)))
    for label, keys in (("base", base.keys() - this.keys()), ("this", this.keys() - base.keys())):
        figures = sorted(" ".join(k[:1] + k[2:]) for k in keys if k[0] in base_scenes & this_scenes)
        if figures:
            print(f"figures in {label} only: " + ", ".join(figures))
    common_scenes = len({k[0] for k in base.keys() & this.keys()})
    print(f"{len(base.keys() & this.keys())} figures of {common_scenes} scenes in both tables; "
          f"{differ} differ")
    return differ


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("scenes", nargs="*", metavar="SCENE")
    parser.add_argument("--compare", nargs=2, metavar=("BASE_TSV", "THIS_TSV"))
    parser.add_argument("--option", action="append", default=[], metavar="KEY=VALUE",
                        help="a reference option of every run (a scheme variant against the "
                             "default: two tables of one revision)")
    args = parser.parse_args(argv)
    if args.compare:
        compare(*args.compare)
    else:
        from clearbench.harness.cli.common import assignments

        measure(args.scenes, assignments(args.option, "--option"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
