"""Run configuration: frozen dataclasses with one docstring per field, presets and TOML.

:mod:`mtpg.config.sections` holds the dataclasses (every default the paper's value, each
field validated); :mod:`mtpg.config.resolve` builds a configuration from a preset, a TOML
file and ``section.field=value`` overrides, and writes it back as TOML. Everything a
caller needs is importable from here.
"""

from mtpg.ablations import ABLATIONS
from mtpg.config.resolve import (
    MAX_TOML_BYTES,
    build_config,
    from_dict,
    merge,
    merge_overrides,
    parse_override,
    read_toml,
    reference_entry,
    to_dict,
    to_toml,
)
from mtpg.config.sections import (
    ConfigError,
    EvaluationConfig,
    ProgramConfig,
    RunConfig,
    TeamConfig,
)
from mtpg.presets import EXTENSIONS, PRESETS

__all__ = [
    "ABLATIONS",
    "EXTENSIONS",
    "MAX_TOML_BYTES",
    "PRESETS",
    "ConfigError",
    "EvaluationConfig",
    "ProgramConfig",
    "RunConfig",
    "TeamConfig",
    "build_config",
    "from_dict",
    "merge",
    "merge_overrides",
    "parse_override",
    "read_toml",
    "reference_entry",
    "to_dict",
    "to_toml",
]
