"""``import mtpg`` writes nothing, deletes nothing and leaves ``os.environ`` as it was.

The import runs in a fresh interpreter on a copy of the package, whose kernel cache is
stale on purpose (a Numba cache file and no stamp of the sources: the state in which the
kernel-cache guard deletes files), with home, cache and working folders of its own.
Python's own bytecode cache is kept out of the package (``PYTHONPYCACHEPREFIX``).
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import mtpg

PACKAGE = Path(mtpg.__file__).resolve().parent

#: Prints the environment before and after the import, and where mtpg came from.
PROBE = """
import json, os, sys
before = dict(os.environ)
import {module}
after = dict(os.environ)
print(json.dumps({{"before": before, "after": after, "file": sys.modules["mtpg"].__file__}}))
"""


def _tree(root: Path) -> dict[str, tuple[int, int]]:
    """Every file and folder under ``root``: its size and modification time."""
    out = {}
    for path in sorted(root.rglob("*")):
        st = path.lstat()
        out[str(path.relative_to(root))] = (st.st_size if path.is_file() else -1, st.st_mtime_ns)
    return out


def _bare_environ() -> dict[str, str]:
    """An environment without what this test process (or its imports) set."""
    return {"PATH": os.environ.get("PATH", "")}


def _import(tmp_path: Path, module: str) -> tuple[dict, Path]:
    site = tmp_path / "site"
    shutil.copytree(PACKAGE, site / "mtpg", ignore=shutil.ignore_patterns("__pycache__"))
    stale = site / "mtpg" / "engine" / "__pycache__"
    stale.mkdir()
    (stale / "batch.evaluate-1.py311.nbi").write_text("a kernel compiled from older sources")
    folders = {n: tmp_path / n for n in ("home", "cache", "config", "numba", "pycache", "cwd")}
    for folder in folders.values():
        folder.mkdir()
    env = _bare_environ() | {
        "PYTHONPATH": str(site),  # before the editable install's path
        "PYTHONPYCACHEPREFIX": str(folders["pycache"]),
        "HOME": str(folders["home"]),
        "XDG_CACHE_HOME": str(folders["cache"]),
        "XDG_CONFIG_HOME": str(folders["config"]),
        "MPLCONFIGDIR": str(folders["config"] / "matplotlib"),
        "NUMBA_CACHE_DIR": str(folders["numba"]),
    }
    before = {n: _tree(p) for n, p in folders.items() if n != "pycache"}
    package_before = _tree(site)
    done = subprocess.run(
        [sys.executable, "-c", PROBE.format(module=module)],
        cwd=folders["cwd"],
        env=env,
        capture_output=True,
        text=True,
        check=True,
    )
    report = json.loads(done.stdout)
    assert Path(report["file"]).resolve() == (site / "mtpg" / "__init__.py").resolve()
    assert _tree(site) == package_before  # the stale kernel is still there, no stamp written
    assert {n: _tree(p) for n, p in folders.items() if n != "pycache"} == before
    assert done.stderr == ""
    return report, site


def _third_party_environ(tmp_path: Path) -> dict[str, str]:
    """What importing Gymnasium alone writes into ``os.environ``.

    Gymnasium sets ``PYGAME_HIDE_SUPPORT_PROMPT`` when imported; ``import mtpg`` imports
    it to register the ids ``mtpg/<Task>-v0``. That write is Gymnasium's, not mtpg's.
    """
    code = "import json, os; b = dict(os.environ); import gymnasium; " + (
        "print(json.dumps({k: v for k, v in os.environ.items() if b.get(k) != v}))"
    )
    done = subprocess.run(
        [sys.executable, "-c", code],
        cwd=tmp_path,
        env=_bare_environ(),
        capture_output=True,
        text=True,
        check=True,
    )
    return json.loads(done.stdout)


@pytest.mark.parametrize("module", ["mtpg", "mtpg.cli.main"])
def test_import_changes_no_file_and_no_environment_variable(tmp_path: Path, module: str) -> None:
    report, _ = _import(tmp_path, module)
    before, after = report["before"], report["after"]
    assert set(before) <= set(after)  # nothing removed
    changed = {k: v for k, v in after.items() if before.get(k) != v}
    gymnasium = _third_party_environ(tmp_path)
    assert changed == gymnasium
    assert set(gymnasium) <= {"PYGAME_HIDE_SUPPORT_PROMPT"}  # a new write shows up here
