"""The git side of growing: the checkout that runs, and the commits of the grown runs.

The mtpg that grows the runs must be a clean git checkout whose commit is in the
repository's history, so that the commit recorded in ``provenance.csv`` reproduces the
generations exactly (``tests/evolve/test_paper_pin.py`` guards that later commits keep
resuming them exactly).
"""

from __future__ import annotations

import logging
import subprocess
from collections.abc import Sequence
from pathlib import Path

__all__ = ["GrowError", "commit_runs", "repository_of", "source_commit"]

_LOG = logging.getLogger(__name__)


class GrowError(ValueError):
    """Growing cannot go on: a git command failed, or the checkout is not fit (one line)."""


def _git(*args: str, cwd: Path, check: bool = True) -> str:
    """Runs a command and returns its standard output, stripped."""
    done = subprocess.run(args, cwd=cwd, capture_output=True, text=True)
    if check and done.returncode != 0:
        raise GrowError(f"{' '.join(args)}: {done.stderr.strip()}")
    return done.stdout.strip()


def repository_of(folder: Path) -> Path:
    """The top of the git work tree holding ``folder``."""
    return Path(_git("git", "rev-parse", "--show-toplevel", cwd=folder))


def source_commit(python: str, repo: Path) -> str:
    """The commit of the mtpg that ``python`` imports; refuses a dirty or foreign tree.

    Args:
        python: The interpreter whose ``mtpg`` runs the trainings.
        repo: The repository the runs are committed to.

    Returns:
        The commit (40 hex digits).

    Raises:
        GrowError: Its ``src/`` has uncommitted changes, or its commit is not in
            ``repo``'s history.
    """
    init = _git(python, "-c", "import mtpg; print(mtpg.__file__)", cwd=repo)
    top = repository_of(Path(init).parent)
    dirty = _git("git", "status", "--porcelain", "--untracked-files=no", "--", "src", cwd=top)
    if dirty:
        files = ", ".join(line.split()[-1] for line in dirty.splitlines())
        raise GrowError(f"{top} has uncommitted changes in src/: {files}")
    commit = _git("git", "rev-parse", "HEAD", cwd=top)
    known = subprocess.run(["git", "merge-base", "--is-ancestor", commit, "HEAD"], cwd=repo)
    if known.returncode != 0:
        raise GrowError(f"mtpg commit {commit[:12]} is not in {repo}'s history")
    return commit


def commit_runs(repo: Path, runs: Path, moved: Sequence[str]) -> str | None:
    """Commits a ``runs`` folder (and nothing else that may be staged).

    Args:
        repo: The repository.
        runs: The folder of run directories (``results/runs``).
        moved: What each process did, ``"NAME FROM->TO"``, for the message.

    Returns:
        The commit message, or None when nothing changed.

    Raises:
        GrowError: ``git commit`` failed.
    """
    where = str(runs.relative_to(repo))
    # run logs and lock files stay out, whatever the repository's ignore rules
    _git("git", "add", "-A", "--", where, f":!{where}/*.log", f":!{where}/*/.lock", cwd=repo)
    if not _git("git", "status", "--porcelain", "--", where, cwd=repo):
        return None
    msg = "results: grow " + ", ".join(moved) + " (generations committed by the runs)"
    _git("git", "commit", "-q", "-m", msg, "--", where, cwd=repo)
    return msg
