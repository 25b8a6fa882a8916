"""Fault-injection points: the process signals itself at a named moment of a run.

Private to mtpg; only the robustness tests use it. They stop training processes at
precise moments (mid-variation, during a test point, during a checkpoint write, during
run-directory creation ...) to show that a run resumes exactly from any of them. Timed
kills alone hit such moments only by chance, so the code calls :func:`point` at the
places named in :data:`PHASES`, and the environment variable ``MTPG_TEST_STOP_AT`` makes
one of them send a signal to the process itself::

    MTPG_TEST_STOP_AT="PHASE:GENERATION[:SIGNAL][,PHASE:GENERATION[:SIGNAL]...]"

e.g. ``MTPG_TEST_STOP_AT=vary:4:KILL`` (SIGKILL mid-variation of generation 4) or
``test:5:TERM``. ``SIGNAL`` is KILL, TERM, INT or HUP (KILL when left out); generation 0
stands for the run directory's creation. Each entry fires at most once per process. The
variable is read once per process, by :func:`check_stop_at`, which a training session
calls before it writes anything; an unknown phase, a malformed entry or an unknown signal
is refused there with one line naming what is allowed, so a typo cannot go unnoticed as
a point that never fires.

Without the variable, :func:`point` costs two dictionary lookups.
"""

from __future__ import annotations

import os
import signal
import time

#: The environment variable naming the moments to stop at.
ENV = "MTPG_TEST_STOP_AT"

#: The fault-injection points, in the order a run meets them, and where each one is.
PHASES = {
    "create": "run directory made and locked, config.toml not yet written",
    "created": "config.toml written, sub-directories not yet made",
    "vary": "half of a generation's children bred",
    "evaluate": "variation done, evaluation not yet started",
    "select": "evaluation done, selection not yet started",
    "metrics": "the generation's metrics row written",
    "test": "a test point's rows written, its graph files not yet",
    "commit": "champion files written, checkpoint not yet",
    "checkpoint": "checkpoint data in its temporary file, not yet renamed",
    "committed": "checkpoint renamed into place, older ones not yet pruned",
}

#: The signals an entry may name.
SIGNALS = {
    "KILL": signal.SIGKILL,
    "TERM": signal.SIGTERM,
    "INT": signal.SIGINT,
    "HUP": signal.SIGHUP,
}


def parse(text: str) -> dict[tuple[str, int], int]:
    """The moments a value of ``MTPG_TEST_STOP_AT`` names.

    Args:
        text: Comma-separated ``PHASE:GENERATION[:SIGNAL]`` entries (blank: none).

    Returns:
        The signal number to send at each ``(phase, generation)``.

    Raises:
        ValueError: One line naming the entry and what is allowed, for a malformed
            entry, an unknown phase or an unknown signal.
    """
    out = {}
    for item in filter(None, (s.strip() for s in text.split(","))):
        parts = item.split(":")
        if len(parts) not in (2, 3) or not parts[1].isdigit():
            raise ValueError(f"{ENV}: {item!r} must look like PHASE:GENERATION[:SIGNAL]")
        if parts[0] not in PHASES:
            raise ValueError(
                f"{ENV}: unknown phase {parts[0]!r} in {item!r}; the phases are {', '.join(PHASES)}"
            )
        sig = parts[2].upper() if len(parts) == 3 else "KILL"
        if sig not in SIGNALS:
            raise ValueError(
                f"{ENV}: unknown signal {parts[2]!r} in {item!r}; use {', '.join(SIGNALS)}"
            )
        out[(parts[0], int(parts[1]))] = SIGNALS[sig]
    return out


#: The moments still to fire, once the variable is read (None before).
_PENDING: dict[tuple[str, int], int] | None = None


def check_stop_at() -> None:
    """Reads ``MTPG_TEST_STOP_AT`` once (a session does so before its first write).

    Raises:
        ValueError: One line, when the variable's value is not valid (see :func:`parse`).
    """
    global _PENDING
    if _PENDING is None:
        _PENDING = parse(os.environ.get(ENV, ""))


def point(phase: str, generation: int) -> None:
    """Signals this process when ``phase:generation`` is named in ``MTPG_TEST_STOP_AT``.

    Args:
        phase: One of :data:`PHASES`.
        generation: The generation under way (0 while the run directory is created).

    Raises:
        ValueError: ``phase`` is not one of :data:`PHASES` (a mistake in the caller).
    """
    if phase not in PHASES:
        raise ValueError(f"unknown fault-injection phase {phase!r}; add it to PHASES")
    if _PENDING is None:
        check_stop_at()
    if not _PENDING:
        return
    sig = _PENDING.pop((phase, generation), None)
    if sig is None:
        return
    os.kill(os.getpid(), sig)
    if sig == signal.SIGKILL:  # delivery is asynchronous: never run past this point
        time.sleep(60)
