"""The Exudyn engine: a scene rebuilt in Exudyn's multibody code (index-3 joints, penalty
contact connectors), stepped with guards, read out."""

from clearbench.adapters.exudyn.engine import ExudynEngine, availability, create

__all__ = ["ExudynEngine", "availability", "create"]
