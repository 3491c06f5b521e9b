"""The measured tolerances catch deliberate physics changes and let round-off through.

A baseline is measured for suite entries of the reference solver (each run as given and under
round-off perturbations of its initial state; the slow version also under the numba and
OpenBLAS environment perturbations), then the same entries are run with one physical
parameter changed through the scene factory's keyword parameters (as ``--set KEY=VALUE``):
each change must come out as a regression naming the figure it moves; a run perturbed at
round-off with a seed the baseline never saw must come out clean.
"""

from __future__ import annotations

import pytest

from clearbench.harness.studies.regress import compare, measure_baseline, run_suite
from clearbench.harness.studies.regress.measure import variant_spec
from clearbench.harness.studies.regress.perturbations import GENERIC_PERTURBATIONS, Variant
from clearbench.harness.studies.regress.suite import entry_spec

#: The sliding box to its stop (0.68 s at mu 0.3): its stop distance is v0^2 / (2 mu g).
SLIDING_BOX = {"id": "sliding-box", "scene": "sliding-box", "engine": "reference",
               "horizon": 0.8}
#: The bounce: apex heights e^(2k) h0 and the energy left after each impact.
BOUNCING_BALL = {"id": "bouncing-ball-e0.5", "scene": "bouncing-ball-e0.5",
                 "engine": "reference", "horizon": 1.0}
#: The clearance pendulum's first impacts: the journal reaches the bore, at one clearance.
CLEARANCE_PENDULUM = {"id": "clearance-pendulum", "scene": "clearance-pendulum",
                      "engine": "reference", "horizon": 0.1}

ROUNDOFF_ONLY = [p for p in GENERIC_PERTURBATIONS if p["kind"] == "roundoff"]


def _measured(entries: list[dict], perturbations: list[dict]) -> dict:
    by_id = {e["id"]: e for e in entries}
    specs = {ident: entry_spec(e, ident) for ident, e in by_id.items()}
    return {"results": measure_baseline(by_id, specs, perturbations)["results"]}


def _changed(entry: dict, **parameters) -> dict:
    return {**entry, "parameters": {**entry.get("parameters", {}), **parameters}}


def _run(entries: list[dict], seed: int = 0) -> dict:
    return run_suite({e["id"]: variant_spec(e, e["id"], Variant(f"seed-{seed}", seed=seed))
                      for e in entries})


def _figures(lines: list[str], ident: str) -> set[str]:
    return {line.split(": ", 1)[1].split(" ", 1)[0] for line in lines
            if line.startswith(f"{ident}: ")}


def test_a_friction_one_percent_off_is_caught_and_round_off_is_not():
    baseline = _measured([SLIDING_BOX], ROUNDOFF_ONLY)
    checks = baseline["results"]["sliding-box"]["checks"]
    assert checks["stop.stop_distance"]["kind"] == "exact"
    outcome = compare(baseline, _run([_changed(SLIDING_BOX, friction=0.303)]))
    # mu 1 % higher: the stop distance v0^2 / (2 mu g) = 0.680 m shrinks by 6.7 mm, six
    # orders of magnitude above the check's floor of 1e-8 x the scene's size.
    assert "stop.stop_distance" in _figures(outcome.regressions, "sliding-box")
    clean = compare(baseline, _run([SLIDING_BOX], seed=101))
    assert clean.regressions == []


@pytest.mark.slow
def test_restitution_friction_and_clearance_changes_are_caught_under_every_perturbation():
    entries = [SLIDING_BOX, BOUNCING_BALL, CLEARANCE_PENDULUM]
    baseline = _measured(entries, GENERIC_PERTURBATIONS)
    changed = [_changed(SLIDING_BOX, friction=0.303),
               _changed(BOUNCING_BALL, restitution=0.55),
               _changed(CLEARANCE_PENDULUM, radial_clearance=1.1e-4)]
    lines = compare(baseline, _run(changed)).regressions
    # mu +1 %: stop distance -1 % (6.7 mm of 0.68 m).
    assert "stop.stop_distance" in _figures(lines, "sliding-box")
    # e 0.5 -> 0.55: the energy left after the first impact e^2 goes from 25 % to 30 %.
    assert "energy_drift" in _figures(lines, "bouncing-ball-e0.5")
    # Radial clearance 0.1 -> 0.11 mm: the journal's eccentricity at its first impacts grows
    # by 10 um, against a floor of 1e-8 x 1 m.
    assert "clearance_eccentricity_max" in _figures(lines, "clearance-pendulum")
    for seed in (101, 102):
        assert compare(baseline, _run(entries, seed=seed)).regressions == []
