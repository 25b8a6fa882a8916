"""Indented JSON that keeps short scalar lists and small objects on one line.

``json.dumps(indent=2)`` puts every integer of an instruction on its own line; this
writer prints ``[op, dst, src1, src2]`` rows, team member lists and small objects such as
``{"atomic": 0}`` inline, so a graph file reads like a listing. The output is standard
JSON: ``json.loads`` gives back exactly the object written.
"""

from __future__ import annotations

import json
from typing import Any

#: Objects of scalars (or scalar lists) whose one-line form is at most this long are written inline.
INLINE_WIDTH = 72


def _is_scalar(value: Any) -> bool:
    return value is None or isinstance(value, bool | int | float | str)


def _is_flat(value: Any) -> bool:
    """A scalar, or a list of non-string scalars (written on one line anyway)."""
    if isinstance(value, list | tuple):
        return all(_is_scalar(v) and not isinstance(v, str) for v in value)
    return _is_scalar(value)


def _encode(value: Any, level: int, indent: int) -> str:
    if _is_scalar(value):
        return json.dumps(value, allow_nan=False)
    pad = " " * (indent * (level + 1))
    end = " " * (indent * level)
    if isinstance(value, dict):
        if not value:
            return "{}"
        items = []
        for key, item in value.items():
            if not isinstance(key, str):
                raise TypeError(f"JSON object keys must be strings, got {key!r}")
            items.append(f"{json.dumps(key)}: {_encode(item, level + 1, indent)}")
        flat = "{" + ", ".join(items) + "}"
        if all(_is_flat(v) for v in value.values()) and len(flat) <= INLINE_WIDTH:
            return flat
        return "{\n" + ",\n".join(pad + item for item in items) + "\n" + end + "}"
    if isinstance(value, list | tuple):
        if not value:
            return "[]"
        items = [_encode(item, level + 1, indent) for item in value]
        if _is_flat(value):
            return "[" + ", ".join(items) + "]"
        return "[\n" + ",\n".join(pad + item for item in items) + "\n" + end + "]"
    raise TypeError(f"{type(value).__name__} is not JSON-serializable: {value!r}")


def dumps_readable(value: Any, indent: int = 2) -> str:
    """Renders ``value`` as readable JSON.

    Args:
        value: JSON-native data (dicts with string keys, lists, tuples, scalars).
        indent: Spaces per nesting level.

    Returns:
        The JSON text, ending with a newline.

    Raises:
        TypeError: For a value JSON cannot represent.
        ValueError: For NaN or infinity.
    """
    return _encode(value, 0, indent) + "\n"
