"""The scene library: registered scenes, grouped by kind, and the look-ups every caller uses.

Importing this package registers every library scene (basic, mechanisms, edges, stiff, C-60) in
:data:`clearbench.scenarios.registry.SCENES`.
"""

from __future__ import annotations

from clearbench.scenarios.library import basic, c60, edges, mechanisms, stiff
from clearbench.scenarios.registry import SCENES, SceneEntry
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.tags import check_tag

#: The library modules, each registering its scenes when imported.
LIBRARY_MODULES = (basic, mechanisms, edges, stiff, c60)


def scene_names(tag: str | None = None) -> list[str]:
    """Registered names, in registration order, optionally only those with ``tag`` (a tag of
    :data:`~clearbench.scenarios.tags.TAGS`: SceneError naming an unknown one)."""
    if tag is not None:
        check_tag("tag", tag)
    return [name for name, entry in SCENES.items() if tag is None or tag in entry.tags]


def get_entry(name: str) -> SceneEntry:
    """The entry called ``name``; KeyError listing the known names otherwise."""
    if name not in SCENES:
        raise KeyError(f"unknown scene {name!r}; known scenes: {', '.join(SCENES)}")
    return SCENES[name]


def get_scene(name: str, **parameters) -> Scene:
    """Build the registered scene ``name``."""
    return get_entry(name).build(**parameters)
