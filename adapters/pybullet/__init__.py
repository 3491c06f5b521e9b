"""The PyBullet engine: a scene rebuilt in PyBullet (rigid bodies and Featherstone trees),
stepped with guards, read out."""

from clearbench.adapters import installed_package, lazy_engine

__all__ = ["PybulletEngine", "PRESETS", "availability", "create"]

create, __getattr__ = lazy_engine(__name__, "PybulletEngine", "PRESETS")


def availability() -> tuple[bool, str]:
    """(True, version) when the ``pybullet`` package is installed, else (False, why); never
    raises, imports nothing."""
    return installed_package("pybullet")
