"""The Siconos engine: Debian's python3-siconos, run as a worker process fed with JSON."""

from clearbench.adapters.siconos.engine import OPTION_NAMES, PRESETS, availability, create

__all__ = ["OPTION_NAMES", "PRESETS", "availability", "create"]
