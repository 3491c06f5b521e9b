"""The package installs under one namespace and exposes its console entry point."""

import importlib


def test_subpackages_import_under_the_clearbench_namespace():
    for name in ("ref_solver", "scenarios", "adapters", "harness"):
        module = importlib.import_module(f"clearbench.{name}")
        assert module.__name__ == f"clearbench.{name}"
