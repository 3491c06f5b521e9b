"""The Siconos engine: Debian's python3-siconos, run as a worker process fed with JSON."""

from clearbench.adapters.siconos.engine import SiconosEngine, availability, create

__all__ = ["SiconosEngine", "availability", "create"]
