"""Offline tools of the repository (tested in CI, not installed)."""
