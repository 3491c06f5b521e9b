"""The Exudyn engine: a scene rebuilt in Exudyn's multibody code (index-3 joints, penalty
contact connectors), stepped with guards, read out."""

from clearbench.adapters import installed_package, lazy_engine

__all__ = ["ExudynEngine", "availability", "create"]

create, __getattr__ = lazy_engine(__name__, "ExudynEngine")


def availability() -> tuple[bool, str]:
    """(True, version) when the ``exudyn`` package is installed, else (False, why); never
    raises, imports nothing."""
    return installed_package("exudyn")
