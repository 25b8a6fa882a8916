"""The resolved configuration stored in a run directory (``config.toml``)."""

from __future__ import annotations

import tomllib
from pathlib import Path

from mtpg.config import ConfigError, RunConfig, from_dict
from mtpg.io.rundir import RunDir, check_resumable


def read_run_config(run_dir: str | Path) -> RunConfig:
    """Reads the resolved configuration stored in a run directory."""
    path = RunDir(Path(run_dir)).config
    try:
        text = path.read_text(encoding="utf-8")
    except (FileNotFoundError, NotADirectoryError):
        check_resumable(run_dir)  # says why when the directory holds no run
        raise ConfigError(f"{path}: no such file") from None
    except (OSError, UnicodeDecodeError) as exc:
        why = exc.strerror if isinstance(exc, OSError) else "not UTF-8 text"
        raise ConfigError(f"{path}: cannot read: {why}") from exc
    try:
        return from_dict(tomllib.loads(text))
    except (tomllib.TOMLDecodeError, ConfigError) as exc:
        raise ConfigError(f"{path}: {exc}") from exc
    except RecursionError:
        raise ConfigError(f"{path}: not valid TOML: nested too deeply") from None
