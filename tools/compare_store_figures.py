"""Compare the figures of two results stores run for run: every metric and expectation figure,
the status and the verdict of the runs both hold (keyed by scene, engine, preset, time step),
timings excluded; equal means equal to 1e-12 relative (NaN equals NaN).

Usage: python tools/compare_store_figures.py A/runs.sqlite B/runs.sqlite
"""

from __future__ import annotations

import json
import math
import sqlite3
import sys

RELATIVE = 1e-12


def load(path: str) -> dict:
    """{(scene, engine, preset, time step): {figure name: value}} of a store's runs."""
    connection = sqlite3.connect(path)
    connection.row_factory = sqlite3.Row
    runs = {}
    for row in connection.execute("select * from runs"):
        key = (row["scene_name"], row["engine"], row["preset"], round(row["time_step"], 12))
        figures = {f"{e['name']}.{name}": value
                   for e in json.loads(row["expectations"] or "[]")
                   for name, value in (e.get("figures") or {}).items()}
        figures.update({f"metric.{name}": value
                        for name, value in json.loads(row["metrics"] or "{}").items()})
        figures["status"] = row["status"]
        figures["verdict"] = row["verdict"] if "verdict" in row.keys() else None
        runs[key] = figures
    return runs


def equal(x, y) -> bool:
    if x == y:
        return True
    if isinstance(x, float) and isinstance(y, float):
        if math.isnan(x) and math.isnan(y):
            return True
        return abs(x - y) <= RELATIVE * max(abs(x), abs(y))
    return False


def main(first: str, second: str) -> None:
    a, b = load(first), load(second)
    runs = sorted(set(a) & set(b))
    compared = same = 0
    differing = []
    for key in runs:
        for name in sorted(set(a[key]) & set(b[key])):
            compared += 1
            if equal(a[key][name], b[key][name]):
                same += 1
            elif "seconds" not in name and not name.endswith("_per_step"):
                differing.append((key, name, a[key][name], b[key][name]))
    print(f"runs in both: {len(runs)} of {len(a)}/{len(b)}; figures compared: {compared}; "
          f"equal: {same}; differing (timings excluded): {len(differing)}")
    for item in differing[:20]:
        print(item)
    names_a = {name for key in runs for name in a[key]}
    names_b = {name for key in runs for name in b[key]}
    print("figures only in first:", sorted(names_a - names_b)[:10])
    print("figures only in second:", sorted(names_b - names_a)[:10])


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
