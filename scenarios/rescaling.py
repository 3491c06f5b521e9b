"""A scene element (or a whole scene) expressed in another consistent unit system."""

from __future__ import annotations

import dataclasses
from types import MappingProxyType
from typing import Any

from clearbench.scenarios.units import UnitSystem


def _scale(value: Any, factor: float) -> Any:
    if isinstance(value, tuple):
        return tuple(_scale(v, factor) for v in value)
    if isinstance(value, float | int) and not isinstance(value, bool):
        return float(value) * factor
    return value


def rescale_element(element: Any, source: UnitSystem, target: UnitSystem) -> Any:
    """Copy of a scene element (or scene) with every dimensioned value converted.

    Dimensions come from field metadata (``dimension``), or from the element's
    ``field_dimension(name)`` where they depend on other fields (drivers, expectations).
    """
    changes: dict[str, Any] = {}
    for f in dataclasses.fields(element):
        value = getattr(element, f.name)
        dynamic = getattr(element, "field_dimension", None)
        dimension = dynamic(f.name) if dynamic else None
        if dimension is None:
            dimension = f.metadata.get("dimension")
        if isinstance(dimension, dict):  # per-key dimensions of a parameter mapping
            changes[f.name] = MappingProxyType({
                key: v * source.factor_to(target, dimension[key]) for key, v in value.items()
            })
        elif dimension is not None and value is not None:
            changes[f.name] = _scale(value, source.factor_to(target, dimension))
        elif isinstance(value, tuple) and value and dataclasses.is_dataclass(value[0]):
            changes[f.name] = tuple(rescale_element(v, source, target) for v in value)
        elif isinstance(value, UnitSystem):
            changes[f.name] = target
    return dataclasses.replace(element, **changes)
