"""A test hook that makes the process signal itself at a named moment of a run.

The robustness tests stop training processes at precise moments (mid-variation, during a
test point, during a checkpoint write, during run-directory creation ...) to show that a
run resumes exactly from any of them. Timed kills alone hit such moments only by chance,
so the code calls :func:`point` at named places, and the environment variable
``MTPG_TEST_STOP_AT`` makes one of them send a signal to the process itself::

    MTPG_TEST_STOP_AT="PHASE:GENERATION:SIGNAL[,PHASE:GENERATION:SIGNAL...]"

e.g. ``MTPG_TEST_STOP_AT=vary:4:KILL`` (SIGKILL mid-variation of generation 4) or
``test:5:TERM``. ``SIGNAL`` is KILL, TERM, INT or HUP (KILL when left out). Each entry
fires at most once per process. Phases (generation 0 for creation):

======================  ===============================================================
``create``              run directory made and locked, ``config.toml`` not yet written
``created``             ``config.toml`` written, sub-directories not yet made
``vary``                half of a generation's children bred
``evaluate``            variation done, evaluation not yet started
``select``              evaluation done, selection not yet started
``metrics``             the generation's metrics row written
``test``                a test point's rows written, its graph files not yet
``commit``              champion files written, checkpoint not yet
``checkpoint``          checkpoint data in its temporary file, not yet renamed
``committed``           checkpoint renamed into place, older ones not yet pruned
======================  ===============================================================

Without the variable, :func:`point` costs one dictionary lookup. Nothing else reads it.
"""

from __future__ import annotations

import os
import signal
import time

#: The environment variable naming the moments to stop at.
ENV = "MTPG_TEST_STOP_AT"

_SIGNALS = {
    "KILL": signal.SIGKILL,
    "TERM": signal.SIGTERM,
    "INT": signal.SIGINT,
    "HUP": signal.SIGHUP,
}


def _parse(text: str) -> dict[tuple[str, int], int]:
    out = {}
    for item in filter(None, (s.strip() for s in text.split(","))):
        parts = item.split(":")
        if len(parts) not in (2, 3) or not parts[1].isdigit():
            raise ValueError(f"{ENV}: {item!r} must look like PHASE:GENERATION[:SIGNAL]")
        sig = parts[2].upper() if len(parts) == 3 else "KILL"
        if sig not in _SIGNALS:
            raise ValueError(f"{ENV}: unknown signal {parts[2]!r}; use {', '.join(_SIGNALS)}")
        out[(parts[0], int(parts[1]))] = _SIGNALS[sig]
    return out


_PENDING = _parse(os.environ.get(ENV, ""))


def point(phase: str, generation: int) -> None:
    """Signals this process when ``phase:generation`` is named in ``MTPG_TEST_STOP_AT``."""
    if not _PENDING:
        return
    sig = _PENDING.pop((phase, generation), None)
    if sig is None:
        return
    os.kill(os.getpid(), sig)
    if sig == signal.SIGKILL:  # delivery is asynchronous: never run past this point
        time.sleep(60)
