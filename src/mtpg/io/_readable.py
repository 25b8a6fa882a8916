"""Indented JSON that keeps short scalar lists and small objects on one line.

``json.dumps(indent=2)`` puts every integer of an instruction on its own line; this
writer prints ``[op, dst, src1, src2]`` rows, team member lists and small objects such as
``{"atomic": 0}`` inline, so a graph file reads like a listing. The output is standard
JSON: ``json.loads`` gives back exactly the object written.
"""

from __future__ import annotations

import json
from json.encoder import encode_basestring_ascii
from typing import Any

#: Objects of scalars (or scalar lists) whose one-line form is at most this long are written inline.
INLINE_WIDTH = 72


def _is_scalar(value: Any) -> bool:
    return value is None or isinstance(value, bool | int | float | str)


def _scalar_text(value: Any) -> str:
    """``json.dumps(value, allow_nan=False)`` of a scalar, without its per-call set-up.

    The exact types take the encoder's own conversions (``int.__repr__``,
    ``float.__repr__``, ``encode_basestring_ascii``); subclasses go to ``json.dumps``.
    """
    kind = type(value)
    if kind is int:
        return int.__repr__(value)
    if kind is float:
        if value != value or value in (_INF, -_INF):
            return json.dumps(value, allow_nan=False)  # raises ValueError as it would
        return float.__repr__(value)
    if kind is str:
        return encode_basestring_ascii(value)
    return json.dumps(value, allow_nan=False)


_INF = float("inf")


def _is_flat(value: Any) -> bool:
    """A scalar, or a list of non-string scalars (written on one line anyway)."""
    if isinstance(value, list | tuple):
        return all(_is_scalar(v) and not isinstance(v, str) for v in value)
    return _is_scalar(value)


class Encoded:
    """A value already rendered by :func:`encode_at` at the level where it is placed."""

    __slots__ = ("text",)

    def __init__(self, text: str) -> None:
        self.text = text


def encode_at(value: Any, level: int, indent: int = 2) -> Encoded:
    """Renders ``value`` as it appears nested at ``level`` (for a document that reuses it)."""
    return Encoded(_encode(value, level, indent))


def _encode(value: Any, level: int, indent: int) -> str:
    if type(value) is Encoded:
        return value.text
    if _is_scalar(value):
        return _scalar_text(value)
    pad = " " * (indent * (level + 1))
    end = " " * (indent * level)
    if isinstance(value, dict):
        if not value:
            return "{}"
        items = []
        for key, item in value.items():
            if not isinstance(key, str):
                raise TypeError(f"JSON object keys must be strings, got {key!r}")
            items.append(f"{encode_basestring_ascii(key)}: {_encode(item, level + 1, indent)}")
        flat = "{" + ", ".join(items) + "}"
        if all(_is_flat(v) for v in value.values()) and len(flat) <= INLINE_WIDTH:
            return flat
        return "{\n" + ",\n".join(pad + item for item in items) + "\n" + end + "}"
    if isinstance(value, list | tuple):
        if not value:
            return "[]"
        if all(type(v) is int for v in value):  # the common flat row, rendered directly
            return "[" + ", ".join(map(int.__repr__, value)) + "]"
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
