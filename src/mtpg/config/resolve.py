"""A configuration resolved from a preset, a TOML file and overrides, and written back.

A configuration is built from a preset, then a TOML file, then ``section.field=value``
overrides; each step validates and names the offending field on error. Values are
checked against the fields' type hints. A run's ``config.toml`` is written by
`tomli-w <https://github.com/hukkin/tomli-w>`_ (the writer companion of the standard
library's ``tomllib``, by its author), so every string, escapes included, reads back exactly.
"""

from __future__ import annotations

import dataclasses
import functools
import tomllib
import types
import typing
from dataclasses import fields, replace
from pathlib import Path
from typing import Any

import tomli_w

from mtpg.config.sections import (
    ConfigError,
    EvaluationConfig,
    ProgramConfig,
    RunConfig,
    TeamConfig,
)
from mtpg.envs.taskset.variants import from_tables
from mtpg.presets import PRESETS

_SECTIONS = {"program": ProgramConfig, "team": TeamConfig, "evaluation": EvaluationConfig}


@functools.cache
def _hints(cls: type) -> dict[str, Any]:
    """The resolved type of each field of a configuration class."""
    return typing.get_type_hints(cls)


def _coerce(name: str, hint: Any, value: Any, spelled: str) -> Any:
    """Checks ``value`` against the field's type ``hint``; ints are accepted for floats.

    Args:
        name: The field's dotted name (for the message).
        hint: Its resolved type: ``int``, ``float``, ``bool``, ``str``, ``tuple[T, ...]``
            or a union of these with ``None``.
        value: The value given.
        spelled: The type as the class spells it (for the message).

    Raises:
        ConfigError: Naming the field, its type and the value.
    """
    args = typing.get_args(hint)
    if isinstance(hint, types.UnionType) or typing.get_origin(hint) is typing.Union:
        if value is None and type(None) in args:
            return None
        for arg in args:
            if arg is not type(None):
                try:
                    return _coerce(name, arg, value, spelled)
                except ConfigError:
                    pass
    elif typing.get_origin(hint) is tuple:
        if isinstance(value, list | tuple) and all(
            isinstance(v, args[0]) and not isinstance(v, bool) for v in value
        ):
            return tuple(value)
    elif hint is float and isinstance(value, int | float) and not isinstance(value, bool):
        return float(value)
    elif hint is bool and isinstance(value, bool):
        return value
    elif hint in (int, str) and isinstance(value, hint) and not isinstance(value, bool):
        return value
    raise ConfigError(f"{name} must be {spelled}, got {type(value).__name__} {value!r}")


def _apply(obj: Any, data: dict[str, Any], prefix: str) -> Any:
    known = {f.name: f for f in fields(obj)}
    changes: dict[str, Any] = {}
    for key, value in data.items():
        name = f"{prefix}{key}"
        if key not in known:
            raise ConfigError(f"unknown field {name!r}")
        if key in _SECTIONS:
            if not isinstance(value, dict):
                raise ConfigError(f"{name} must be a table, got {value!r}")
            changes[key] = _apply(getattr(obj, key), value, f"{key}.")
        else:
            hint = _hints(type(obj))[key]
            changes[key] = _coerce(name, hint, value, str(known[key].type))
    return replace(obj, **changes)


def merge(config: RunConfig, data: dict[str, Any]) -> RunConfig:
    """Returns ``config`` updated with a nested dict (as read from TOML), validated."""
    return _apply(config, data, "")


def parse_override(text: str) -> dict[str, Any]:
    """Turns ``section.field=value`` (value in TOML syntax) into a nested dict."""
    if "=" not in text:
        raise ConfigError(f"override {text!r} must look like section.field=value")
    key, raw = (s.strip() for s in text.split("=", 1))
    if not key or any(not part for part in key.split(".")):
        raise ConfigError(f"override {text!r} must look like section.field=value")
    try:
        value = tomllib.loads(f"v = {raw}")["v"]
    except tomllib.TOMLDecodeError:
        value = raw  # a bare word: a string
    except RecursionError:
        raise ConfigError(f"override {text!r}: value is nested too deeply") from None
    out: dict[str, Any] = {}
    node = out
    *parents, leaf = key.split(".")
    for part in parents:
        node = node.setdefault(part, {})
    node[leaf] = value
    return out


#: Largest configuration file read (bytes): far above any real one.
MAX_TOML_BYTES = 1 << 20


def read_toml(path: str | Path) -> dict[str, Any]:
    """Reads a TOML settings file, every problem as one :class:`ConfigError` naming it."""
    path = Path(path)
    try:
        if path.is_dir():
            raise ConfigError(f"{path}: is a directory, not a TOML file")
        with open(path, "rb") as fh:
            raw = fh.read(MAX_TOML_BYTES + 1)
    except FileNotFoundError:
        raise ConfigError(f"{path}: no such file") from None
    except OSError as exc:
        raise ConfigError(f"{path}: cannot read: {exc.strerror or exc}") from None
    if len(raw) > MAX_TOML_BYTES:
        raise ConfigError(f"{path}: larger than {MAX_TOML_BYTES} bytes; not a settings file")
    try:
        return tomllib.loads(raw.decode("utf-8"))
    except UnicodeDecodeError as exc:
        raise ConfigError(f"{path}: not UTF-8 text ({exc.reason} at byte {exc.start})") from None
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{path}: not valid TOML: {exc}") from None
    except RecursionError:
        raise ConfigError(f"{path}: not valid TOML: nested too deeply") from None


def build_config(
    preset: str = "paper", toml_file: str | Path | None = None, overrides: list[str] | None = None
) -> RunConfig:
    """Resolves a configuration from a preset, a TOML file and overrides, in that order.

    Args:
        preset: A name in :data:`PRESETS`.
        toml_file: Optional TOML file with top-level run fields and ``[program]``,
            ``[team]``, ``[evaluation]`` tables.
        overrides: ``section.field=value`` strings.

    Returns:
        The validated configuration.

    Raises:
        ConfigError: Naming the offending field, file or preset.
    """
    if preset not in PRESETS:
        raise ConfigError(f"unknown preset {preset!r}; choose from {', '.join(PRESETS)}")
    config = merge(RunConfig(), PRESETS[preset])
    if toml_file is not None:
        data = read_toml(toml_file)
        if "task" in data:
            data = _task_tables(data, toml_file)
        try:
            config = merge(config, data)
        except ConfigError as exc:
            raise ConfigError(f"{toml_file}: {exc}") from exc
    return merge_overrides(config, overrides or [])


def _task_tables(data: dict[str, Any], toml_file: str | Path) -> dict[str, Any]:
    """Turns ``[[task]]`` tables into ``evaluation.tasks`` (one canonical name each)."""
    data = dict(data)
    tables = data.pop("task")
    if "tasks" in data.get("evaluation", {}):
        raise ConfigError(f"{toml_file}: give the tasks as [[task]] or evaluation.tasks, not both")
    if "references" in data.get("evaluation", {}) and any(
        isinstance(t, dict) and "reference" in t for t in tables
    ):
        raise ConfigError(
            f"{toml_file}: give reference scores in [[task]] or evaluation.references, not both"
        )
    try:
        references = [
            reference_entry(t) for t in tables if isinstance(t, dict) and "reference" in t
        ]
        names = from_tables(
            [
                {k: v for k, v in t.items() if k != "reference"} if isinstance(t, dict) else t
                for t in tables
            ]
        )
    except ValueError as exc:
        raise ConfigError(f"{toml_file}: {exc}") from None
    data["evaluation"] = {**data.get("evaluation", {}), "tasks": names}
    if references:
        data["evaluation"]["references"] = references
    return data


def reference_entry(table: dict[str, Any]) -> str:
    """The ``evaluation.references`` entry of a ``[[task]]`` table's ``reference``.

    ``{base = "CartPole", max_steps = 500, reference = {best = 500, source = "..."}}``
    gives ``"CartPole[max_steps=500]: best=500.0, source=..."``.

    Raises:
        ValueError: If ``reference`` is not a table of best, source and optionally random.
    """
    ref = table["reference"]
    name = from_tables([{k: v for k, v in table.items() if k != "reference"}])[0]
    if not isinstance(ref, dict) or set(ref) - {"best", "random", "source"}:
        raise ValueError(f"{name}: reference must be a table of best, source and random")
    items = [f"{k}={ref[k]!r}" for k in ("best", "random") if k in ref]
    return f"{name}: {', '.join(items)}, source={ref.get('source', '')}"


def _deep_update(into: dict[str, Any], data: dict[str, Any]) -> None:
    for key, value in data.items():
        if isinstance(value, dict) and isinstance(into.get(key), dict):
            _deep_update(into[key], value)
        else:
            into[key] = value


def merge_overrides(config: RunConfig, overrides: list[str]) -> RunConfig:
    """Applies ``section.field=value`` overrides together, so their order does not matter.

    All overrides are parsed into one nested dict (a later one wins for the same field)
    and validated once, so e.g. raising ``program.init_max_length`` and
    ``program.max_length`` works in either order.
    """
    data: dict[str, Any] = {}
    for text in overrides:
        _deep_update(data, parse_override(text))
    return merge(config, data)


def to_dict(config: RunConfig) -> dict[str, Any]:
    """The configuration as a nested dict of JSON-native values (tuples become lists)."""
    return dataclasses.asdict(
        config,
        dict_factory=lambda items: {k: list(v) if isinstance(v, tuple) else v for k, v in items},
    )


def to_toml(config: RunConfig) -> str:
    """Renders the configuration as TOML that :func:`build_config` reads back exactly.

    Top-level run fields first, then the ``[program]``, ``[team]`` and ``[evaluation]``
    tables. Any string survives: a raw newline in a reference's source once made a
    hand-escaped ``config.toml`` that ``tomllib`` refused, so the run trained but could
    not be resumed or reported.
    """
    return tomli_w.dumps(to_dict(config))


def from_dict(data: dict[str, Any]) -> RunConfig:
    """Rebuilds a configuration from :func:`to_dict` output, validated."""
    return merge(RunConfig(), data)
