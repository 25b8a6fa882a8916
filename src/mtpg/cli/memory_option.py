"""The ``--memory`` option of every command that runs a graph.

A graph evolved under the TPG-NoMemory ablation (section 5.2) runs without memory: its
graph file records ``"no_memory": true`` in its metadata (written by training). Commands
that execute a graph (evaluate, replay, analyze, export) honour that setting by default and
let the user override it explicitly.
"""

from __future__ import annotations

import argparse
from typing import Any

#: Choices of ``--memory``.
MEMORY_CHOICES = ("as-evolved", "on", "off")


def evolved_without_memory(meta: dict[str, Any]) -> bool:
    """True when a graph file's metadata says the graph was evolved without memory."""
    return bool(meta.get("no_memory", False))


def add_memory_option(parser: argparse.ArgumentParser) -> None:
    """Adds ``--memory {as-evolved,on,off}`` to a command's parser."""
    parser.add_argument(
        "--memory",
        choices=MEMORY_CHOICES,
        default="as-evolved",
        help="run the graph with shared memory on or off; default: as it was evolved "
        "(a TPG-NoMemory champion runs without memory)",
    )


def resolve_no_memory(choice: str, meta: dict[str, Any]) -> tuple[bool, str]:
    """The ``no_memory`` flag to run a graph with, and a phrase saying why.

    Args:
        choice: The value of ``--memory``.
        meta: The graph file's metadata.

    Returns:
        ``(no_memory, description)``, e.g. ``(True, "memory off (as evolved)")``.
    """
    if choice not in MEMORY_CHOICES:
        raise ValueError(f"--memory must be one of {', '.join(MEMORY_CHOICES)}, got {choice!r}")
    if choice == "as-evolved":
        off = evolved_without_memory(meta)
        return off, f"memory {'off' if off else 'on'} (as evolved)"
    off = choice == "off"
    forced = off != evolved_without_memory(meta)
    return off, f"memory {choice} ({'overriding the evolved setting' if forced else 'as evolved'})"
