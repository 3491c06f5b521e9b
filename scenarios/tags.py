"""The tag vocabulary: every tag a scene may carry, declared once with what it means.

Tags choose where a scene runs (the CLI, CI subsets and tests select by tag). Some carry
behaviour, and code refers to them by the constants below, never by a string of its own
(:data:`SMOKE` and :data:`ANALYTIC`: the default comparison; :data:`STIFF`: the stability
suite; :data:`C60`: the C-60 scenes); the others describe what a scene exercises, for
``clearbench list --tag``. A scene with a tag not in :data:`TAGS` is refused naming the tag.
"""

from __future__ import annotations

from collections.abc import Iterable

from clearbench.scenarios.validation import SceneError

SMOKE = "smoke"
ANALYTIC = "analytic"
STIFF = "stiff"
C60 = "c60"
BENCH = "bench"

#: Every tag -> what it means.
TAGS: dict[str, str] = {
    SMOKE: "quick scene of the default comparison (`clearbench compare`, `make demo`)",
    ANALYTIC: "has an analytic reference; in the default comparison",
    STIFF: "stiff or extreme case of the stability suite (`clearbench stability`)",
    C60: "the Schneider C-60 circuit-breaker mechanism",
    BENCH: "a bench experiment of the C-60 study (force against displacement)",
    "impact": "impacts with restitution",
    "friction": "Coulomb friction: stick, slide or roll",
    "clearance": "clearance joints",
    "joints": "ideal joints",
    "closed_loop": "ideal joints closing a kinematic loop",
    "gyroscopic": "free rotation with gyroscopic terms",
    "springs": "spring-dampers",
    "many_contacts": "many simultaneous contacts",
    "edge": "a body crossing the bound of a face (an edge)",
    "example": "an example scene file of the documentation",
}

#: Tags of the scenes of the default comparison (a scene with any of them runs in it).
DEFAULT_COMPARISON = (SMOKE, ANALYTIC)


def check_tag(field: str, tag: object) -> str:
    """``tag`` if it is in :data:`TAGS`; a :class:`SceneError` naming ``field`` otherwise."""
    if tag not in TAGS:
        raise SceneError(field, tag, f"unknown tag (tags: {', '.join(TAGS)})")
    return tag


def check_tags(field: str, tags: Iterable) -> tuple[str, ...]:
    """Every tag of ``tags`` checked by :func:`check_tag` (``field[i]`` names the bad one)."""
    return tuple(check_tag(f"{field}[{index}]", tag) for index, tag in enumerate(tags))
