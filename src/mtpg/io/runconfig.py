"""The resolved configuration stored in a run directory (``config.toml``)."""

from __future__ import annotations

import tomllib
from pathlib import Path

from mtpg.config import ConfigError, RunConfig, from_dict
from mtpg.io.rundir import RunDir, check_resumable, check_run
from mtpg.io.runschema import check_schema


def read_run_config(run_dir: str | Path, resuming: bool = False) -> RunConfig:
    """Reads the resolved configuration stored in a run directory.

    The directory's schema version is checked first (:func:`mtpg.io.runschema.check_schema`),
    so a run written by a newer mtpg is refused in one line naming both versions.

    Args:
        run_dir: The run directory.
        resuming: The caller resumes the run (``mtpg train --resume``): a directory that
            holds no run is then refused in the words of resuming.

    Raises:
        RunDirError: When ``run_dir`` holds no run (the message says why).
        RunSchemaError: When the run is of a schema version this mtpg does not read.
        ConfigError: When its ``config.toml`` cannot be read or is not valid.
    """
    path = RunDir(Path(run_dir)).config
    try:
        text = path.read_text(encoding="utf-8")
    except (FileNotFoundError, NotADirectoryError):
        if resuming:
            check_resumable(run_dir)  # says why when the directory holds no run to resume
        else:
            check_run(run_dir)
        raise ConfigError(f"{path}: no such file") from None
    except (OSError, UnicodeDecodeError) as exc:
        why = exc.strerror if isinstance(exc, OSError) else "not UTF-8 text"
        raise ConfigError(f"{path}: cannot read: {why}") from exc
    check_schema(run_dir)
    try:
        return from_dict(tomllib.loads(text))
    except (tomllib.TOMLDecodeError, ConfigError) as exc:
        raise ConfigError(f"{path}: {exc}") from exc
    except RecursionError:
        raise ConfigError(f"{path}: not valid TOML: nested too deeply") from None
