"""Explicit contact pairs: mechanisms name the pairs that may touch, no broad phase is needed."""

from __future__ import annotations

from dataclasses import dataclass, field

from clearbench.scenarios.element import Element
from clearbench.scenarios.validation import (
    LENGTH,
    SceneError,
    check_finite,
    check_in_range,
    check_name,
    check_non_negative,
    dim,
    dimensionless,
)


@dataclass(frozen=True)
class ContactPair(Element):
    """A unilateral frictional contact between shape ``shape_a`` of ``body_a`` and ``shape_b``
    of ``body_b``.

    The gap used by every engine and metric is the signed distance between the two shapes minus
    ``offset`` (the C-60 data sheet varies radial clearances through the offset). The offset is
    taken on A's side, as the C-60 source does: A's contact point is moved by ``offset`` along
    the normal, so a closed contact acts at one point on both bodies. The contact normal points
    from A toward B (see :mod:`.geometry`).

    Parameters
    ----------
    friction : float
        Coulomb coefficient mu >= 0.
    restitution : float
        Newton restitution coefficient e in [0, 1].
    offset : float
        Subtracted from the geometric gap [L]; may be negative.
    """

    collection = "contacts"
    body_a: str = ""
    shape_a: str = ""
    body_b: str = ""
    shape_b: str = ""
    friction: float = field(default=0.0, metadata=dimensionless())
    restitution: float = field(default=0.0, metadata=dimensionless())
    offset: float = field(default=0.0, metadata=dim(LENGTH))

    def _validate(self) -> None:
        for name in ("body_a", "shape_a", "body_b", "shape_b"):
            check_name(name, getattr(self, name))
        if self.body_a == self.body_b:
            raise SceneError("body_b", self.body_b, "a contact pair needs two different bodies")
        check_non_negative("friction", self.friction)
        check_in_range("restitution", self.restitution, 0.0, 1.0)
        check_finite("offset", self.offset)
