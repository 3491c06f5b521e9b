"""The MuJoCo engine: a scene rebuilt in MuJoCo, stepped with guards, read out."""

from clearbench.adapters.mujoco.engine import MujocoEngine, availability, create

__all__ = ["MujocoEngine", "availability", "create"]
