"""The reference engine: our nonsmooth Moreau--Jean solver behind the Engine contract."""

from clearbench.adapters.reference.engine import ReferenceEngine, availability, create

__all__ = ["ReferenceEngine", "availability", "create"]
