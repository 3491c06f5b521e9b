"""The tagged scene registry: a plain dict from name to entry, filled by the library modules.

A scene is registered by a factory that builds it (keyword parameters allowed, e.g. a clearance
for ladders), with tags the CLI, CI subsets and tests select by.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass

from .scene import Scene


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


def _load_library() -> None:
    # Importing the library modules fills SCENES (kept here so that importing the registry is
    # enough for every caller).
    from . import library_basic, library_mechanisms, library_stiff  # noqa: F401


def scene_names(tag: str | None = None) -> list[str]:
    """Registered names, in registration order, optionally only those with ``tag``."""
    _load_library()
    return [name for name, entry in SCENES.items() if tag is None or tag in entry.tags]


def get_entry(name: str) -> SceneEntry:
    """The entry called ``name``; KeyError listing the known names otherwise."""
    _load_library()
    if name not in SCENES:
        raise KeyError(f"unknown scene {name!r}; known scenes: {', '.join(SCENES)}")
    return SCENES[name]


def get_scene(name: str, **parameters) -> Scene:
    """Build the registered scene ``name``."""
    return get_entry(name).build(**parameters)
