"""Runs: their specification, engine choice, isolated worker processes, and the results store."""
