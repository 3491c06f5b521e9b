"""The reference engine: our nonsmooth Moreau--Jean solver behind the Engine contract."""

from clearbench.adapters.reference.engine import OPTION_NAMES, PRESETS, availability, create

__all__ = ["OPTION_NAMES", "PRESETS", "availability", "create"]
