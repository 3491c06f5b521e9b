"""The Drake engine: a scene rebuilt as a discrete MultibodyPlant, stepped with guards, read
out."""

from clearbench.adapters import installed_package, lazy_engine

__all__ = ["DrakeEngine", "availability", "create"]

create, __getattr__ = lazy_engine(__name__, "DrakeEngine")


def availability() -> tuple[bool, str]:
    """(True, version) when Drake's ``pydrake`` is installed (distribution ``drake``), else
    (False, why); never raises, imports nothing."""
    return installed_package("pydrake", "drake")
