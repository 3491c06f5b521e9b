"""The tagged scene registry: a plain dict from name to entry, filled by the library modules
(:mod:`clearbench.scenarios.library`, which also looks scenes up).

A scene is registered by a factory that builds it (keyword parameters allowed, e.g. a clearance
for ladders), with tags the CLI, CI subsets and tests select by.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass

from clearbench.scenarios.scene import Scene


@dataclass(frozen=True)
class SceneEntry:
    """A registered scene: its factory, tags and one-line summary."""

    name: str
    factory: Callable[..., Scene]
    tags: tuple[str, ...]
    summary: str

    def build(self, **parameters) -> Scene:
        """Build the scene (``parameters`` override the factory's defaults)."""
        return self.factory(**parameters)


#: Every registered scene by name.
SCENES: dict[str, SceneEntry] = {}


def register(name: str, tags: Iterable[str], summary: str, **fixed_parameters):
    """Decorator registering ``factory`` under ``name``; ``fixed_parameters`` bind a variant."""

    def decorator(factory: Callable[..., Scene]) -> Callable[..., Scene]:
        if name in SCENES:
            raise ValueError(f"scene {name!r} registered twice")

        def build(**parameters) -> Scene:
            return factory(**{**fixed_parameters, **parameters})

        SCENES[name] = SceneEntry(name, build, tuple(tags), summary)
        return factory

    return decorator
