"""Measurement of a run: per-sample series, expectation figures, per-run figures, verdicts."""
