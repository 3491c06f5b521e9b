"""The Siconos engine: Debian's python3-siconos, run as a worker process fed with JSON."""

from clearbench.adapters import lazy_engine

__all__ = ["SiconosEngine", "availability", "create"]

create, __getattr__ = lazy_engine(__name__, "SiconosEngine")


def availability() -> tuple[bool, str]:
    """Whether Debian's interpreter imports Siconos (:func:`.engine.availability`: a probe in
    that interpreter, cached); never raises."""
    from clearbench.adapters.siconos.engine import availability as probe

    return probe()
