"""The ``mtpg`` entry point: parses arguments and dispatches to one command module.

Each command lives in its own module ``mtpg.cli.cmd_<name>`` exposing
``register(subparsers)`` (adds its parser and sets ``func``) and keeps heavy imports
inside its ``run`` function, so ``mtpg --help`` stays fast.

Every failure a user can cause or meet is one line on standard error naming the file or
field and the problem, with exit status 2 for bad input (options, settings, files) and 1
for a failure of the machine (disk full, permission denied, out of memory, a directory in
use by another process). ``--debug`` (before or after the command) adds the traceback.
A missing dependency is one line naming the module and the extra that installs it
(:mod:`mtpg._extras`). Output piped into a program that stops reading
(``mtpg ... | head -1``) ends quietly with status 141, as if killed by SIGPIPE.

Messages of the library (not a command's own output) go through the standard
:mod:`logging` module under the ``mtpg`` logger; :func:`main` shows them on standard
error while a command runs: INFO and above by default, WARNING and above with
``--quiet``, everything with ``--debug``. Importing this module changes nothing: the
logger, ``MTPG_DEBUG`` and Numba's kernel cache (:mod:`mtpg._kernel_cache`) are seen to
by :func:`main` only.
"""

from __future__ import annotations

import argparse
import importlib
import logging
import os
import sys
import traceback

from mtpg import __version__

#: Command modules, in the order ``mtpg --help`` lists them.
COMMAND_MODULES = (
    "mtpg.cli.cmd_envs",
    "mtpg.cli.cmd_bench",
    "mtpg.cli.cmd_train",
    "mtpg.cli.cmd_evaluate",
    "mtpg.cli.cmd_probe",
    "mtpg.cli.cmd_report",
    "mtpg.cli.cmd_experiment",
    "mtpg.cli.cmd_show",
    "mtpg.cli.cmd_replay",
    "mtpg.cli.cmd_analyze",
    "mtpg.cli.cmd_export",
)

#: Exit status for bad input, a runtime failure and a closed output pipe.
EXIT_USAGE, EXIT_FAILURE, EXIT_PIPE = 2, 1, 141
#: The logger of the library's messages (every module logs under it).
LOGGER = "mtpg"


class UsageError(Exception):
    """A user error that the CLI reports as one line and exit code 2."""


class _Parser(argparse.ArgumentParser):
    """An argument parser whose errors are one line (the usage is in ``--help``)."""

    def error(self, message: str) -> None:  # type: ignore[override]
        """Prints one line and exits with status 2."""
        self.exit(EXIT_USAGE, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def build_parser() -> argparse.ArgumentParser:
    """Builds the top-level parser with every available command.

    Returns:
        The parser; each sub-parser sets ``func`` to its command's ``run``.
    """
    parser = _Parser(
        prog="mtpg",
        description="Tangled Program Graphs with temporal memory for multi-task RL.",
    )
    parser.add_argument(
        "--debug", action="store_true", help="show tracebacks of errors and debug messages"
    )
    parser.add_argument("--version", action="version", version=f"mtpg {__version__}")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name in COMMAND_MODULES:
        importlib.import_module(name).register(subparsers)
    for sub in subparsers.choices.values():
        sub.add_argument(
            "--debug", action="store_true", default=argparse.SUPPRESS, help=argparse.SUPPRESS
        )
    return parser


def _one_line(text: str) -> str:
    return " ".join(str(text).split())


def classify(exc: BaseException) -> tuple[int, str]:
    """The exit status and the one-line message of an error.

    Bad input (status 2): :class:`UsageError`, ``ValueError`` (every configuration, file
    format, checkpoint and run-directory error derives from it), a missing file or a
    directory given for a file. A failure of the machine (status 1): other ``OSError``
    (disk full, permission, read-only file system), ``MemoryError``, a locked directory,
    a missing dependency (named with the extra that installs it).
    """
    from mtpg.io.lock import LockedError

    missing = getattr(exc, "name", None) if isinstance(exc, ModuleNotFoundError) else None
    if missing and missing.partition(".")[0] != "mtpg":  # mtpg's own: a broken install
        from mtpg._extras import missing_dependency

        return EXIT_FAILURE, f"missing dependency: {missing_dependency(missing)}"

    if isinstance(exc, OSError) and exc.strerror:
        where = f"{exc.filename}: " if exc.filename else ""
        text = f"{where}{exc.strerror}"
        bad_input = isinstance(exc, FileNotFoundError | IsADirectoryError | NotADirectoryError)
        return (EXIT_USAGE if bad_input else EXIT_FAILURE), _one_line(text)
    if isinstance(exc, UsageError | ValueError | FileNotFoundError):
        return EXIT_USAGE, _one_line(str(exc))
    if isinstance(exc, RecursionError):
        return EXIT_USAGE, "input nested too deeply"
    if isinstance(exc, MemoryError):
        return EXIT_FAILURE, "out of memory"
    if isinstance(exc, LockedError | OSError):
        return EXIT_FAILURE, _one_line(str(exc))
    text = f"internal error: {type(exc).__name__}: {exc} (run with --debug for the traceback)"
    return EXIT_FAILURE, _one_line(text)


def _silence_stdout() -> None:
    """Points standard output at /dev/null so that exit does not fail flushing it."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError, AttributeError):
        pass


class _Formatter(logging.Formatter):
    """INFO as the message alone; other levels prefixed by theirs (``warning: ...``)."""

    def format(self, record: logging.LogRecord) -> str:
        text = record.getMessage()
        if record.levelno != logging.INFO:
            text = f"{record.levelname.lower()}: {text}"
        if record.exc_info:
            text += "\n" + self.formatException(record.exc_info)
        return text


def log_level(args: argparse.Namespace, debug: bool) -> int:
    """The level of the ``mtpg`` logger for a command: DEBUG, WARNING with --quiet, else INFO."""
    if debug:
        return logging.DEBUG
    return logging.WARNING if getattr(args, "quiet", False) else logging.INFO


def _configure_logging(level: int) -> tuple[logging.Handler, int, bool]:
    """Shows the ``mtpg`` logger's messages of ``level`` and above on standard error.

    Returns:
        The handler added, and the logger's level and ``propagate`` before, which
        :func:`_restore_logging` puts back (``main`` may run many times in one process).
    """
    logger = logging.getLogger(LOGGER)
    before = logger.level, logger.propagate
    handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(_Formatter())
    logger.addHandler(handler)
    logger.setLevel(level)
    logger.propagate = False  # the command line owns the output; no second copy via root
    return handler, *before


def _restore_logging(handler: logging.Handler, level: int, propagate: bool) -> None:
    logger = logging.getLogger(LOGGER)
    logger.removeHandler(handler)
    logger.setLevel(level)
    logger.propagate = propagate


def _fail(command: str | None, exc: BaseException, debug: bool) -> int:
    """Prints an error's one line (and with ``debug`` its traceback); its exit status."""
    code, text = classify(exc)
    if debug:
        traceback.print_exception(exc)
    try:
        print(
            f"mtpg {command}: error: {text}" if command else f"mtpg: error: {text}", file=sys.stderr
        )
    except BrokenPipeError:
        pass
    return code


def main(argv: list[str] | None = None) -> int:
    """Runs the command line.

    Before the command runs, Numba's kernel cache is cleared if the package's sources
    changed since it was compiled (:func:`mtpg._kernel_cache.refresh`), and the ``mtpg``
    logger is shown on standard error at the level of ``--quiet`` and ``--debug``;
    ``--debug`` also sets ``MTPG_DEBUG`` for the libraries' own logs and child processes.
    The logger and ``MTPG_DEBUG`` are put back when it returns.

    Args:
        argv: Arguments without the program name; ``sys.argv[1:]`` when None.

    Returns:
        The process exit code.
    """
    try:
        parser = build_parser()
    except ModuleNotFoundError as exc:  # a command module's dependency is missing
        return _fail(None, exc, bool(os.environ.get("MTPG_DEBUG")))
    args = parser.parse_args(argv)
    if not getattr(args, "func", None):
        parser.print_help()
        return EXIT_USAGE
    debug = args.debug or bool(os.environ.get("MTPG_DEBUG"))
    set_here = debug and not os.environ.get("MTPG_DEBUG")
    if set_here:  # libraries' own logs too (Dask's, see DaskEvaluator), and child processes
        os.environ["MTPG_DEBUG"] = "1"
    logs = _configure_logging(log_level(args, debug))
    try:
        from mtpg._kernel_cache import refresh

        refresh()  # before any kernel loads: a cache older than the sources goes
        code = int(args.func(args) or 0)
        sys.stdout.flush()  # a closed pipe shows here, not at exit
        return code
    except BrokenPipeError:
        _silence_stdout()
        return EXIT_PIPE
    except KeyboardInterrupt as exc:
        import signal

        from mtpg.evolve.stopping import exit_code

        if debug:
            traceback.print_exc()
        print(f"mtpg {args.command}: interrupted", file=sys.stderr)
        return exit_code(getattr(exc, "signum", signal.SIGINT))
    except Exception as exc:  # every error: one line (with --debug, the traceback too)
        return _fail(args.command, exc, debug)
    finally:
        _restore_logging(*logs)
        if set_here:
            del os.environ["MTPG_DEBUG"]


if __name__ == "__main__":
    raise SystemExit(main())
