"""Lossless conversion of scenes to and from plain dicts, JSON and TOML.

The dict form (:mod:`.dict_form`, which writes it) is what user scene files contain: a table per
scene with lists of tables for the elements; polymorphic elements (shapes, joints, loads,
outputs) carry a ``kind`` key. ``None`` values are omitted (TOML has no null). Reading checks
every key: an unknown key or a missing required one is an error naming its path
(``bodies[0].shapes[1].radius``), and every value goes through the same validation as
Python-built scenes. Unit rescaling is :mod:`.rescaling`.
"""

from __future__ import annotations

import dataclasses
import json
import math
import tomllib
from pathlib import Path
from typing import Any

from clearbench.scenarios import toml_format
from clearbench.scenarios.bodies import Body
from clearbench.scenarios.dict_form import COLLECTIONS, scene_to_dict
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.shapes import SHAPE_TYPES
from clearbench.scenarios.units import UnitSystem
from clearbench.scenarios.validation import SceneError


def scene_to_json(scene: Scene, indent: int | None = 2) -> str:
    return json.dumps(scene_to_dict(scene), indent=indent)


def scene_to_toml(scene: Scene) -> str:
    return toml_format.dumps(scene_to_dict(scene))


# ---------------------------------------------------------------------------- from dict
def _build(cls: type, data: Any, path: str, **extra: Any) -> Any:
    if not isinstance(data, dict):
        raise SceneError(path, data, "must be a table (mapping)")
    fields = {f.name: f for f in dataclasses.fields(cls) if f.init}
    # ``kind`` selects the class of polymorphic elements; it is a field only of expectations.
    ignored = set() if "kind" in fields else {"kind"}
    unknown = sorted(set(data) - set(fields) - ignored)
    if unknown:
        raise SceneError(f"{path}.{unknown[0]}", data[unknown[0]],
                         f"unknown field for {cls.__name__} (fields: {', '.join(fields)})")
    required = [
        name for name, f in fields.items()
        if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING
    ]
    for name in required:
        if name not in data and name not in extra:
            raise SceneError(f"{path}.{name}", None, f"missing required field of {cls.__name__}")
    kwargs = {k: v for k, v in data.items() if k not in ignored}
    kwargs.update(extra)
    try:
        return cls(**kwargs)
    except SceneError as error:
        name = data.get("name")
        field = error.field
        # Element errors carry "collection['name'].field"; use the document path instead.
        marker = f"[{name!r}]"
        if isinstance(name, str) and marker in field:
            field = field.split(marker, 1)[1].lstrip(".")
        prefix = f"{path} ({name!r})" if isinstance(name, str) else path
        raise SceneError(f"{prefix}.{field}" if field else prefix, error.value,
                         error.reason) from None
    except TypeError as error:
        raise SceneError(path, data, f"cannot build {cls.__name__}: {error}") from None


def _polymorphic(table: dict[str, type], data: Any, path: str) -> Any:
    if not isinstance(data, dict):
        raise SceneError(path, data, "must be a table (mapping)")
    kind = data.get("kind")
    if kind not in table:
        raise SceneError(f"{path}.kind", kind, f"must be one of {sorted(table)}")
    return _build(table[kind], data, path)


def _list(data: Any, path: str) -> list:
    if not isinstance(data, list):
        raise SceneError(path, data, "must be a list (array of tables)")
    return data


def body_from_dict(data: Any, path: str) -> Body:
    if isinstance(data, dict) and "shapes" in data:
        shapes = tuple(
            _polymorphic(SHAPE_TYPES, s, f"{path}.shapes[{i}]")
            for i, s in enumerate(_list(data["shapes"], f"{path}.shapes"))
        )
        data = {k: v for k, v in data.items() if k != "shapes"}
        return _build(Body, data, path, shapes=shapes)
    return _build(Body, data, path)


def scene_from_dict(data: Any) -> Scene:
    """Build and validate a :class:`Scene` from its plain-dict form."""
    if not isinstance(data, dict):
        raise SceneError("scene", data, "must be a table (mapping)")
    if "name" not in data:  # a scene file names its scene (Scene's default is the library's)
        raise SceneError("scene.name", None, "missing required field of Scene")
    data = dict(data)
    units_data = data.pop("units", {})
    if not isinstance(units_data, dict):
        raise SceneError("units", units_data, "must be a table with length, mass, time")
    unknown = sorted(set(units_data) - {"length", "mass", "time"})
    if unknown:
        raise SceneError(f"units.{unknown[0]}", units_data[unknown[0]], "unknown unit field")
    units = UnitSystem(**units_data)
    collections: dict[str, tuple] = {}
    for key, kind in COLLECTIONS.items():
        items = _list(data.pop(key, []), key)
        built = []
        for index, item in enumerate(items):
            path = f"{key}[{index}]"
            if key == "bodies":
                built.append(body_from_dict(item, path))
            elif isinstance(kind, dict):
                built.append(_polymorphic(kind, item, path))
            else:
                built.append(_build(kind, item, path))
        collections[key] = tuple(built)
    if "tags" in data:
        data["tags"] = tuple(_list(data["tags"], "tags"))
    return _build(Scene, data, "scene", units=units, **collections)


def scene_from_json(text: str) -> Scene:
    try:
        data = json.loads(text)
    except json.JSONDecodeError as error:
        raise SceneError("file", "JSON text", f"not valid JSON: {error}") from None
    return scene_from_dict(data)


def scene_from_toml(text: str) -> Scene:
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise SceneError("file", "TOML text", f"not valid TOML: {error}") from None
    # A scene file may hold the scene at top level or under a [scene] table.
    if set(data) == {"scene"}:
        data = data["scene"]
    return scene_from_dict(data)


def read_scene_text(path: str | Path) -> str:
    """The text of a scene file, strictly UTF-8.

    Raises :class:`SceneError` naming the file when it holds a NUL byte (a binary file) or a
    byte sequence that is not UTF-8, or cannot be read (a directory, no permission);
    :class:`FileNotFoundError` when it does not exist."""
    path = Path(path)
    try:
        data = path.read_bytes()
    except FileNotFoundError:
        raise
    except OSError as error:
        raise SceneError("file", str(path), f"cannot be read: {error.strerror or error}") \
            from None
    nul = data.find(b"\0")
    if nul >= 0:
        raise SceneError("file", str(path), f"is a binary file (NUL byte at offset {nul}), "
                         "not a TOML or JSON scene")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as error:
        raise SceneError("file", str(path), f"is not UTF-8 text (byte "
                         f"0x{data[error.start]:02x} at offset {error.start})") from None


def load_scene_file(path: str | Path) -> Scene:
    """Read a scene from a ``.toml`` or ``.json`` file (UTF-8, :func:`read_scene_text`)."""
    path = Path(path)
    text = read_scene_text(path)
    if path.suffix == ".json":
        return scene_from_json(text)
    return scene_from_toml(text)


def is_close_scene(a: Scene, b: Scene, rtol: float = 1e-12) -> bool:
    """True when two scenes have the same structure and numbers equal within ``rtol``."""

    def close(x: Any, y: Any) -> bool:
        if isinstance(x, dict) and isinstance(y, dict):
            return x.keys() == y.keys() and all(close(x[k], y[k]) for k in x)
        if isinstance(x, list) and isinstance(y, list):
            return len(x) == len(y) and all(close(u, v) for u, v in zip(x, y, strict=True))
        if isinstance(x, float | int) and isinstance(y, float | int):
            return math.isclose(x, y, rel_tol=rtol, abs_tol=0.0) or x == y
        return x == y

    return close(scene_to_dict(a), scene_to_dict(b))
