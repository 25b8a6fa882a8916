"""The schema version of a run directory: ``RUN_DIR/format.json``.

A run directory's layout (which files it holds, the columns of ``metrics.csv`` and
``tests.csv``, what ``config.toml`` holds) has one version, written when the run is
created::

    {"format": "mtpg-run", "version": 1}

A run directory written before this file existed has none: it is of version 1
(:data:`UNVERSIONED`), the layout this mtpg writes, so it is read and resumed as it is;
resuming it writes the file, saying version 1. A directory of a version this mtpg does
not read (a newer mtpg wrote it, or an older layout no longer read) is refused with one
line naming the version found and the versions read, before anything else of the run is
read: a changed metrics header then reads as what it is, not as a corrupt file.

When the layout changes, :data:`RUN_SCHEMA_VERSION` goes up; the older version stays in
:data:`READABLE_VERSIONS` only where this module migrates it on resume, and the changelog
says which versions stopped being read.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

from mtpg.io._atomic import atomic_write_bytes

#: The file of a run directory that records its schema version.
SCHEMA_FILE = "format.json"
#: Format tag of :data:`SCHEMA_FILE`.
RUN_FORMAT = "mtpg-run"
#: The schema version this mtpg writes.
RUN_SCHEMA_VERSION = 1
#: The schema versions this mtpg reads and resumes.
READABLE_VERSIONS = (1,)
#: The version of a run directory without :data:`SCHEMA_FILE` (written before it existed).
UNVERSIONED = 1
#: Largest schema file read (bytes): the file is one short line.
_MAX_BYTES = 4096


class RunSchemaError(ValueError):
    """A run directory's schema file is unreadable or names a version this mtpg does not read."""


def schema_text(version: int = RUN_SCHEMA_VERSION) -> str:
    """The content of :data:`SCHEMA_FILE` for ``version``."""
    return json.dumps({"format": RUN_FORMAT, "version": version}) + "\n"


def write_schema(run_dir: str | os.PathLike[str], version: int = RUN_SCHEMA_VERSION) -> Path:
    """Writes :data:`SCHEMA_FILE` of ``version`` into ``run_dir`` (atomically).

    Returns:
        The file written.
    """
    path = Path(run_dir) / SCHEMA_FILE
    atomic_write_bytes(path, schema_text(version).encode("utf-8"))
    return path


def read_schema(run_dir: str | os.PathLike[str]) -> int:
    """The schema version of a run directory, :data:`UNVERSIONED` when it records none.

    Raises:
        RunSchemaError: When :data:`SCHEMA_FILE` cannot be read or is not a schema file.
    """
    path = Path(run_dir) / SCHEMA_FILE
    try:
        with open(path, "rb") as fh:
            raw = fh.read(_MAX_BYTES + 1)
    except FileNotFoundError:
        return UNVERSIONED
    except OSError as exc:
        raise RunSchemaError(f"{path}: cannot read: {exc.strerror or exc}") from exc
    try:
        if len(raw) > _MAX_BYTES:
            raise ValueError(f"larger than {_MAX_BYTES} bytes")
        doc = json.loads(raw.decode("utf-8"))
    except (ValueError, RecursionError) as exc:  # UnicodeDecodeError and JSONDecodeError too
        raise RunSchemaError(f"{path}: not a run-directory schema file: {exc}") from None
    if not isinstance(doc, dict) or doc.get("format") != RUN_FORMAT:
        raise RunSchemaError(f"{path}: not a run-directory schema file (no format {RUN_FORMAT!r})")
    version = doc.get("version")
    if type(version) is not int:
        raise RunSchemaError(f"{path}: the schema version must be an integer, got {version!r}")
    return version


def check_schema(run_dir: str | os.PathLike[str]) -> int:
    """The schema version of a run directory, refusing one this mtpg does not read.

    Returns:
        The version (one of :data:`READABLE_VERSIONS`).

    Raises:
        RunSchemaError: One line naming the version found and the versions this mtpg reads.
    """
    version = read_schema(run_dir)
    if version in READABLE_VERSIONS:
        return version
    reads = " or ".join(str(v) for v in READABLE_VERSIONS)
    why = (
        "written by a newer mtpg; upgrade mtpg to read it"
        if version > RUN_SCHEMA_VERSION
        else "an older layout this mtpg no longer reads; use the mtpg that wrote it"
    )
    raise RunSchemaError(
        f"{run_dir}: run-directory schema version {version} ({SCHEMA_FILE}), this mtpg reads "
        f"version {reads}: {why}"
    )


def stamp_schema(run_dir: str | os.PathLike[str]) -> bool:
    """Records the version of a run directory being resumed that records none.

    Such a run is of version :data:`UNVERSIONED`, which the file then says. The caller
    has checked the directory (:func:`check_schema`) and holds its lock.

    Returns:
        True when the file was written (the run had no version), False when it had one.
    """
    if (Path(run_dir) / SCHEMA_FILE).exists():
        return False
    write_schema(run_dir, UNVERSIONED)
    return True
