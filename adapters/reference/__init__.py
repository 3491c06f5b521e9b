"""The reference engine: our nonsmooth Moreau--Jean solver behind the Engine contract."""

import clearbench
from clearbench.adapters import lazy_engine

__all__ = ["ReferenceEngine", "availability", "create"]

create, __getattr__ = lazy_engine(__name__, "ReferenceEngine")


def availability() -> tuple[bool, str]:
    """Always available: the solver is part of clearbench."""
    return True, f"built in (clearbench {clearbench.__version__})"
