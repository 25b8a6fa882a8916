"""``mtpg.preset``: a configuration from a preset, a TOML file and overrides.

The same resolution as ``mtpg train --preset NAME --config FILE --set ...``
(:func:`mtpg.config.build_config`), with the command's named options as keywords.
"""

from __future__ import annotations

import json
import os
from collections.abc import Sequence
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from mtpg.config import RunConfig

__all__ = ["preset"]


def preset(
    name: str = "demo",
    *overrides: str,
    tasks: Sequence[str] | None = None,
    generations: int | None = None,
    seed: int | None = None,
    workers: int | None = None,
    config_file: str | os.PathLike[str] | None = None,
) -> RunConfig:
    """A configuration: a preset, then a TOML file, then overrides (as ``mtpg train``).

    Args:
        name: A preset of :data:`mtpg.presets.PRESETS` (``paper``, ``demo``, ``robust``).
        *overrides: ``section.field=value`` strings, as ``mtpg train --set`` takes them
            (``"team.root_size=60"``, ``"checkpoint_interval=5"``).
        tasks: Task names (``--tasks``): registered tasks, variants such as
            ``"CartPole[max_steps=500]"``, or Gymnasium ids ``"gym:CartPole-v1"``.
        generations: Generations to run (``--generations``).
        seed: The run's seed (``--seed``).
        workers: Threads evaluating episodes (``--workers``; results do not depend on it).
        config_file: A TOML file of settings (``--config``).

    Returns:
        The validated, frozen configuration (an :class:`mtpg.Config`).

    Raises:
        ConfigError: One line naming the preset, file or field that is wrong.
    """
    from mtpg.config import build_config

    named = list(overrides)
    if tasks is not None:
        named.append("evaluation.tasks=" + json.dumps(_task_names(tasks)))
    for key, value in (("generations", generations), ("seed", seed), ("workers", workers)):
        if value is not None:
            named.append(f"{key}={int(value)}")
    return build_config(name, config_file, named)


def _task_names(tasks: Sequence[str]) -> list[str]:
    """Task names spelled canonically (a variant's keys in their order), as ``--tasks``."""
    from mtpg.config import ConfigError
    from mtpg.envs.taskset.variants import canonical, is_variant

    if isinstance(tasks, str):
        raise ConfigError(f"tasks: give a list of task names, not the string {tasks!r}")
    try:
        return [canonical(t) if is_variant(t) else t for t in tasks]
    except ValueError as exc:
        raise ConfigError(f"tasks: {exc}") from None
