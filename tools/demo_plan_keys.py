"""The run keys and measurement keys of `clearbench demo`'s plan, and how many a previous list
already holds: which runs an edit makes the demo run again, without running one.

    .venv/bin/python -m tools.demo_plan_keys keys-before.json
    (edit a file)
    .venv/bin/python -m tools.demo_plan_keys keys-after.json keys-before.json

The plan is the demo's with its defaults (every available engine, the comparison scenes and
ladder, the fine reference runs, the C-60 demo plan). A run whose key the store holds is
reused (`clearbench demo` prints "N runs done, M reused from the store (K measured again)");
one whose measurement key changed is measured again from its stored trajectory.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from clearbench.harness.cli.c60 import c60_plan_specs
from clearbench.harness.cli.common import engine_modules
from clearbench.harness.cli.compare import COMPARE_LADDER, add_compare_options, compare_scenes
from clearbench.harness.run.engine_choice import resolve_engine
from clearbench.harness.studies.stability import available_engines
from clearbench.harness.studies.sweep import (
    FINE_FACTOR,
    REFERENCE_ENGINE,
    parse_ladder,
    plan_sweep,
)


def demo_keys() -> dict[str, str]:
    """Run key -> measurement key of every run of the demo's plan."""
    parser = argparse.ArgumentParser()
    add_compare_options(parser)
    args = parser.parse_args([])
    modules = engine_modules(args)
    plan = plan_sweep(compare_scenes(), available_engines(modules), parse_ladder(COMPARE_LADDER),
                      timeout=args.timeout, reference=resolve_engine(REFERENCE_ENGINE, modules),
                      fine_factor=FINE_FACTOR, campaign="compare")
    specs = (*plan.all_specs, *c60_plan_specs(args.c60, None, modules))
    # A revision before measurement keys (ddb0acf) measured every run it ran: its run key.
    return {spec.key: getattr(spec, "measure_key", spec.key) for spec in specs}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", type=Path, help="JSON file the keys are written to")
    parser.add_argument("previous", type=Path, nargs="?", help="keys written before an edit")
    args = parser.parse_args()
    keys = demo_keys()
    args.out.write_text(json.dumps(keys, sort_keys=True), encoding="utf-8")
    line = f"{len(keys)} runs in the demo plan"
    if args.previous:
        before = json.loads(args.previous.read_text(encoding="utf-8"))
        reused = [key for key in keys if key in before]
        again = sum(keys[key] != before[key] for key in reused)
        line += (f": {len(keys) - len(reused)} to run, {len(reused)} reused from the store "
                 f"({again} measured again)")
    print(line)


if __name__ == "__main__":
    main()
