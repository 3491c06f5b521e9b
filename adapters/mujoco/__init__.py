"""The MuJoCo engine: a scene rebuilt in MuJoCo, stepped with guards, read out."""

from clearbench.adapters.mujoco.engine import OPTION_NAMES, PRESETS, availability, create

__all__ = ["OPTION_NAMES", "PRESETS", "availability", "create"]
