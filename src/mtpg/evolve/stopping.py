"""Stopping a run on SIGTERM, SIGINT (Ctrl-C) or SIGHUP at a generation boundary.

The first signal only sets a flag (and says so on standard error): the generation under
way completes, is committed, and the run ends. A second signal stops at once by raising
:class:`StopNow` wherever the program is; the generation under way is abandoned, nothing
half-done is written, and a resume continues from the last committed generation.

Exit status by convention ``128 + signal number``: 130 for SIGINT, 143 for SIGTERM, 129
for SIGHUP (see :func:`exit_code`).
"""

from __future__ import annotations

import os
import signal
from types import FrameType

#: The signals that stop a run.
STOP_SIGNALS = (signal.SIGTERM, signal.SIGINT, signal.SIGHUP)


class StopNow(KeyboardInterrupt):  # a request, like KeyboardInterrupt
    """Raised by a second stop signal: stop at once, abandoning the generation under way."""

    def __init__(self, signum: int) -> None:
        super().__init__(signal.Signals(signum).name)
        self.signum = signum


def exit_code(signum: int) -> int:
    """The conventional exit status of a process stopped by ``signum``."""
    return 128 + int(signum)


class GracefulStop:
    """Context manager installing the stop handlers (restoring the old ones on exit).

    Args:
        label: How messages start, e.g. ``"mtpg train"``.
        what: What the first signal lets finish, for its message.
    """

    def __init__(self, label: str = "mtpg", what: str = "the generation under way") -> None:
        self.label = label
        self.what = what
        self.signum: int | None = None
        self._old: dict[int, object] = {}

    def requested(self) -> bool:
        """True once a stop signal arrived."""
        return self.signum is not None

    @property
    def name(self) -> str:
        """The name of the signal received (empty before any)."""
        return signal.Signals(self.signum).name if self.signum is not None else ""

    def _handle(self, signum: int, frame: FrameType | None) -> None:
        if self.signum is not None:
            raise StopNow(signum)
        self.signum = signum
        note = (
            f"\n{self.label}: {signal.Signals(signum).name} received; stopping after "
            f"{self.what} (send it again to stop at once)\n"
        )
        try:  # os.write: safe even if the signal interrupted a print to stderr
            os.write(2, note.encode())
        except OSError:
            pass

    def __enter__(self) -> GracefulStop:
        for sig in STOP_SIGNALS:
            try:
                self._old[sig] = signal.signal(sig, self._handle)
            except (ValueError, OSError):  # not the main thread, or unsupported
                pass
        return self

    def __exit__(self, *exc: object) -> None:
        for sig, old in self._old.items():
            signal.signal(sig, old)
        self._old.clear()
