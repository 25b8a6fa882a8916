"""The six partially-observable tasks: compiled kernels, episode data and Gymnasium envs.

Importing this package registers the Gymnasium ids ``mtpg/<Task>-v0`` (only Gymnasium is
imported for that). The numba-backed names below load on first access, so the import
itself stays light.

Public names: ``TASK_NAMES``, ``STATE_SIZE`` and the task ids (``mtpg.envs.core``);
``TASK_PARAMS``, ``N_PARAMS``, ``MAX_STEPS``, ``ACTION_BOUND``, ``USES_CONTINUOUS``,
``STATE_DIMS`` (``mtpg.envs.tasks``); ``env_reset``, ``env_observe``, ``env_step``
(``mtpg.envs.kernels``); ``sample_start``, ``make_episodes`` (``mtpg.envs.episodes``);
``MtpgEnv`` (``mtpg.envs.gym_env``); ``REFERENCE``, ``normalise`` (``mtpg.envs.reference``).
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from mtpg.envs.core import (
    ACROBOT,
    CARTCENTERING,
    CARTPOLE,
    MOUNTAINCAR,
    MOUNTAINCARCONTINUOUS,
    N_OBS,
    PENDULUM,
    PREV_FORCE_SLOT,
    STATE_SIZE,
    STEP_SLOT,
    TASK_NAMES,
)
from mtpg.envs.registration import GYM_IDS, register_envs

if TYPE_CHECKING:
    from mtpg.envs.episodes import make_episodes, sample_start
    from mtpg.envs.gym_env import MtpgEnv
    from mtpg.envs.kernels import env_observe, env_reset, env_step
    from mtpg.envs.reference import REFERENCE, normalise
    from mtpg.envs.tasks import (
        ACTION_BOUND,
        MAX_STEPS,
        N_PARAMS,
        STATE_DIMS,
        TASK_PARAMS,
        USES_CONTINUOUS,
    )

_LAZY: dict[str, str] = {
    "TASK_PARAMS": "mtpg.envs.tasks",
    "N_PARAMS": "mtpg.envs.tasks",
    "MAX_STEPS": "mtpg.envs.tasks",
    "ACTION_BOUND": "mtpg.envs.tasks",
    "USES_CONTINUOUS": "mtpg.envs.tasks",
    "STATE_DIMS": "mtpg.envs.tasks",
    "env_reset": "mtpg.envs.kernels",
    "env_observe": "mtpg.envs.kernels",
    "env_step": "mtpg.envs.kernels",
    "sample_start": "mtpg.envs.episodes",
    "make_episodes": "mtpg.envs.episodes",
    "MtpgEnv": "mtpg.envs.gym_env",
    "REFERENCE": "mtpg.envs.reference",
    "normalise": "mtpg.envs.reference",
}

__all__ = [
    "ACROBOT",
    "CARTCENTERING",
    "CARTPOLE",
    "GYM_IDS",
    "MOUNTAINCAR",
    "MOUNTAINCARCONTINUOUS",
    "N_OBS",
    "PENDULUM",
    "PREV_FORCE_SLOT",
    "STATE_SIZE",
    "STEP_SLOT",
    "TASK_NAMES",
    "register_envs",
    "TASK_PARAMS",
    "N_PARAMS",
    "MAX_STEPS",
    "ACTION_BOUND",
    "USES_CONTINUOUS",
    "STATE_DIMS",
    "env_reset",
    "env_observe",
    "env_step",
    "sample_start",
    "make_episodes",
    "MtpgEnv",
    "REFERENCE",
    "normalise",
]


def __getattr__(name: str) -> Any:
    """Loads a numba-backed public name on first access."""
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY))


register_envs()
