"""The plain-dict form of scenes and their elements: what scene files contain.

This is the writing direction, which needs no :class:`~clearbench.scenarios.scene.Scene` class
(it walks the dataclass fields), so the scene can use it for its
:attr:`~clearbench.scenarios.scene.Scene.content_hash`; reading a dict back into a validated scene
is :mod:`clearbench.scenarios.serialization`. Polymorphic elements (shapes, joints, loads,
outputs) carry a ``kind`` key first; ``None`` values are omitted (TOML has no null).
"""

from __future__ import annotations

import dataclasses
from enum import Enum
from types import MappingProxyType
from typing import Any

from clearbench.scenarios.bodies import Body
from clearbench.scenarios.contacts import ContactPair
from clearbench.scenarios.drivers import Driver
from clearbench.scenarios.expectations import Expectation
from clearbench.scenarios.joints import JOINT_TYPES, ClearanceRevoluteJoint
from clearbench.scenarios.loads import LOAD_TYPES
from clearbench.scenarios.outputs import OUTPUT_TYPES

#: Element collections of a scene: key -> (kind table or single class).
COLLECTIONS: dict[str, Any] = {
    "bodies": Body,
    "joints": JOINT_TYPES,
    "clearance_joints": ClearanceRevoluteJoint,
    "contacts": ContactPair,
    "loads": LOAD_TYPES,
    "drivers": Driver,
    "outputs": OUTPUT_TYPES,
    "expectations": Expectation,
}


def _plain(value: Any) -> Any:
    if dataclasses.is_dataclass(value):
        return element_to_dict(value)
    if isinstance(value, Enum):
        return value.value
    if isinstance(value, MappingProxyType | dict):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, tuple | list):
        return [_plain(v) for v in value]
    return value


def element_to_dict(element: Any) -> dict[str, Any]:
    """Plain-dict form of a scene element (``kind`` first for polymorphic elements)."""
    out: dict[str, Any] = {}
    kind = getattr(type(element), "kind", None)
    if isinstance(kind, str) and kind and not isinstance(element, Expectation):
        out["kind"] = kind
    for f in dataclasses.fields(element):
        value = getattr(element, f.name)
        if value is None:
            continue
        out[f.name] = _plain(value)
    return out


def scene_to_dict(scene: Any) -> dict[str, Any]:
    """Plain-dict form of a :class:`~clearbench.scenarios.scene.Scene` (JSON and TOML
    serialisable, lossless)."""
    out = element_to_dict(scene)
    out["units"] = dataclasses.asdict(scene.units)
    for key in list(out):
        if out[key] == [] and key in COLLECTIONS:
            del out[key]
    return out
