"""Base of every named element of a scene (body, joint, contact pair, load, driver, output).

An element validates itself when it is built; any :class:`SceneError` raised while validating is
re-raised with the element's place in the scene as a prefix, e.g. ``bodies['ball'].mass``.
Validated values are stored as given (tuples instead of lists), never silently altered.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from clearbench.scenarios.validation import SceneError, check_name


@dataclass(frozen=True)
class Element:
    """A named, self-validating, immutable part of a scene."""

    collection: ClassVar[str] = "elements"
    name: str

    def __post_init__(self) -> None:
        try:
            check_name("name", self.name)
        except SceneError as error:
            raise error.within(self.collection) from None
        try:
            self._validate()
        except SceneError as error:
            raise error.within(f"{self.collection}[{self.name!r}]") from None

    def _validate(self) -> None:
        """Check every field (overridden); use ``self._set`` to store a normalised value."""

    def _set(self, field: str, value: object) -> None:
        object.__setattr__(self, field, value)
