"""The MuJoCo engine: a scene rebuilt in MuJoCo, stepped with guards, read out."""

from clearbench.adapters import installed_package, lazy_engine

__all__ = ["MujocoEngine", "availability", "create"]

create, __getattr__ = lazy_engine(__name__, "MujocoEngine")


def availability() -> tuple[bool, str]:
    """(True, version) when the ``mujoco`` package is installed, else (False, why); never
    raises, imports nothing."""
    return installed_package("mujoco")
