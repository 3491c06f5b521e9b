"""A compact TOML writer for scene dicts: short arrays inline, elements as arrays of tables.

``tomli_w`` writes every array one element per line, which makes a scene file hard to read;
this writer keeps numeric vectors and matrices on one line. Output is checked by parsing it back
with :mod:`tomllib` in the tests. Floats are written with ``repr`` so the round trip is exact.
"""

from __future__ import annotations

import math
from typing import Any

import tomli_w


def _is_table_list(value: Any) -> bool:
    return isinstance(value, list) and bool(value) and all(isinstance(v, dict) for v in value)


def _inline(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        if math.isnan(value) or math.isinf(value):
            return tomli_w.dumps({"x": value}).split("=", 1)[1].strip()
        return repr(value)
    if isinstance(value, int):
        return str(value)
    if isinstance(value, str):
        return tomli_w.dumps({"x": value}).split("=", 1)[1].strip()
    if isinstance(value, list):
        return "[" + ", ".join(_inline(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{ " + ", ".join(f"{_key(k)} = {_inline(v)}" for k, v in value.items()) + " }"
    raise TypeError(f"cannot write {type(value).__name__} to TOML")


def _key(key: str) -> str:
    bare = key.replace("_", "").replace("-", "").isalnum()
    return key if bare else tomli_w.dumps({key: 0}).split("=", 1)[0].strip()


def dumps(data: dict[str, Any]) -> str:
    """TOML text of ``data`` (a dict of scalars, inline arrays, tables, arrays of tables)."""
    lines: list[str] = []
    _write_table(data, [], lines)
    return "\n".join(lines).strip() + "\n"


def _write_table(table: dict[str, Any], path: list[str], lines: list[str]) -> None:
    nested = []
    for key, value in table.items():
        if isinstance(value, dict) and not _is_small(value):
            nested.append(("table", key, value))
        elif _is_table_list(value):
            nested.append(("array", key, value))
        else:
            lines.append(f"{_key(key)} = {_inline(value)}")
    for kind, key, value in nested:
        sub = path + [_key(key)]
        if kind == "table":
            lines.extend(["", f"[{'.'.join(sub)}]"])
            _write_table(value, sub, lines)
        else:
            for item in value:
                lines.extend(["", f"[[{'.'.join(sub)}]]"])
                _write_table(item, sub, lines)


def _is_small(value: dict) -> bool:
    """Small flat tables (expectation parameters) are written inline."""
    return all(not isinstance(v, dict | list) for v in value.values()) and len(value) <= 6
