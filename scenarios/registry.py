"""The tagged scene registry: a plain dict from name to entry, filled by the library modules
(:mod:`clearbench.scenarios.library`, which also looks scenes up).

A scene is registered by a factory that builds it (keyword parameters allowed, e.g. a clearance
for ladders), with tags the CLI, CI subsets and tests select by. The name and the tags are
written once, in :func:`register`: the factory builds its :class:`Scene` without them and the
registry names and tags every scene it builds.
"""

from __future__ import annotations

import dataclasses
import functools
import inspect
from collections.abc import Callable, Iterable
from dataclasses import dataclass

from clearbench.scenarios.scene import Scene
from clearbench.scenarios.tags import check_tags


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

    def parameter_names(self) -> list[str] | None:
        """The factory's keyword parameters (None when it takes any: ``**kwargs``)."""
        signature = inspect.signature(self.factory)
        if any(p.kind is p.VAR_KEYWORD for p in signature.parameters.values()):
            return None
        return [name for name, p in signature.parameters.items()
                if p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)]


#: Every registered scene by name.
SCENES: dict[str, SceneEntry] = {}


def register(name: str, tags: Iterable[str], summary: str, **fixed_parameters):
    """Decorator registering ``factory`` under ``name`` with ``tags`` (of
    :data:`~clearbench.scenarios.tags.TAGS`); ``fixed_parameters`` bind a variant.

    Returns the factory wrapped so that every scene it builds, through the registry or called
    directly, carries ``name`` and ``tags``.
    """
    tags = check_tags(f"register({name!r}).tags", tags)

    def decorator(factory: Callable[..., Scene]) -> Callable[..., Scene]:
        if name in SCENES:
            raise ValueError(f"scene {name!r} registered twice")

        @functools.wraps(factory)
        def build(*arguments, **parameters) -> Scene:
            bound = inspect.signature(factory).bind_partial(*arguments, **parameters)
            scene = factory(**{**fixed_parameters, **bound.arguments})
            return dataclasses.replace(scene, name=name, tags=tags)

        SCENES[name] = SceneEntry(name, build, tags, summary)
        return build

    return decorator
