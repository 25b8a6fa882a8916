"""The ``mtpg`` entry point: parses arguments and dispatches to one command module.

Each command lives in its own module ``mtpg.cli.cmd_<name>`` exposing
``register(subparsers)`` (adds its parser and sets ``func``) and keeps heavy imports
inside its ``run`` function, so ``mtpg --help`` stays fast.
"""

from __future__ import annotations

import argparse
import importlib
import sys

#: Command modules, in the order ``mtpg --help`` lists them.
COMMAND_MODULES = (
    "mtpg.cli.cmd_envs",
    "mtpg.cli.cmd_bench",
    "mtpg.cli.cmd_train",
    "mtpg.cli.cmd_evaluate",
    "mtpg.cli.cmd_report",
    "mtpg.cli.cmd_experiment",
    "mtpg.cli.cmd_show",
    "mtpg.cli.cmd_replay",
    "mtpg.cli.cmd_analyze",
    "mtpg.cli.cmd_export",
)


class UsageError(Exception):
    """A user error that the CLI reports as one line and exit code 2."""


def build_parser() -> argparse.ArgumentParser:
    """Builds the top-level parser with every available command.

    Returns:
        The parser; each sub-parser sets ``func`` to its command's ``run``.
    """
    parser = argparse.ArgumentParser(
        prog="mtpg",
        description="Tangled Program Graphs with temporal memory for multi-task RL.",
    )
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name in COMMAND_MODULES:
        try:
            module = importlib.import_module(name)
        except ModuleNotFoundError as exc:  # a command not built yet
            if exc.name != name:
                raise
            continue
        module.register(subparsers)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Runs the command line.

    Args:
        argv: Arguments without the program name; ``sys.argv[1:]`` when None.

    Returns:
        The process exit code.
    """
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "func", None):
        parser.print_help()
        return 2
    try:
        return int(args.func(args) or 0)
    except (UsageError, ValueError, FileNotFoundError) as exc:
        print(f"mtpg {args.command}: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    raise SystemExit(main())
