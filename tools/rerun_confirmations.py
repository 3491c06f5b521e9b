"""Run again, with this checkout's code, the confirmation runs a metamodel campaign's report
holds, at the report's own inputs, and print each committed value beside this run's.

    .venv/bin/python -m tools.rerun_confirmations reports/campaigns/c60-paper-metamodel.json \\
        [--workers 2] [--store DIR]

Shows whether a change of a confirmation run between two reports comes from the code (other
values at the same inputs) or from the inputs (the design point the rare-event search found).
"""

from __future__ import annotations

import argparse
import json
import tempfile

import numpy as np

from clearbench.harness.run.store import ResultsStore
from clearbench.harness.studies.campaign.definition import load_campaign
from clearbench.harness.studies.campaign.execution import plan_points, run_samples
from clearbench.harness.studies.campaign.results import campaign_table

#: Sample index of the first rerun (away from design samples and confirmation runs).
RERUN_START = 20_000_000


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("report", help="a metamodel campaign's report JSON")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--store", default=None, help="results store (default: a temporary one)")
    args = parser.parse_args()
    with open(args.report, encoding="utf-8") as handle:
        summary = json.load(handle)
    definition = load_campaign(summary["definition"]["name"])
    runs = [(event["name"], side["side"], run) for event in summary["rare_events"] or []
            for side in event["sides"] for run in side.get("confirmation", [])]
    if not runs:
        print(f"{args.report}: no confirmation runs")
        return
    samples = plan_points(definition, np.array([run["inputs"] for _, _, run in runs]),
                          RERUN_START)
    with tempfile.TemporaryDirectory() as scratch:
        store = ResultsStore(args.store or scratch)
        run_samples(definition, samples, store, workers=args.workers)
        table = campaign_table(definition, store, samples)
    print(f"{'output':<8}{'side':<7}{'t':>5}{'report':>12}{'this code':>12}  status")
    for (name, side, run), (_, row) in zip(runs, table.iterrows(), strict=True):
        print(f"{name:<8}{side:<7}{run['t']:>5.2f}{run['observed']:>12.6f}{row[name]:>12.6f}"
              f"  {row['status']}")


if __name__ == "__main__":
    main()
