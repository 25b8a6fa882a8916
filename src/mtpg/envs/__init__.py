"""The six partially-observable tasks: compiled kernels, episode data and Gymnasium envs.

Importing this package registers the Gymnasium ids ``mtpg/<Task>-v0`` (only Gymnasium is
imported for that). The numba-backed names below load on first access, so the import
itself stays light.

Public names: ``TASK_NAMES``, ``STATE_SIZE`` and the task ids (``mtpg.envs.specs.contract``);
``TASK_PARAMS``, ``N_PARAMS``, ``MAX_STEPS``, ``ACTION_BOUND``, ``USES_CONTINUOUS``,
``STATE_DIMS`` (``mtpg.envs.specs.param_table``); ``env_reset``, ``env_observe``, ``env_step``
(``mtpg.envs.dynamics.dispatch``); ``sample_start``, ``make_episodes``
(``mtpg.envs.taskset.episodes``); ``MtpgEnv`` (``mtpg.envs.gym_api.env``); ``REFERENCE``,
``normalise`` (``mtpg.envs.taskset.reference_scores``). The layers beneath (``specs``,
``dynamics``, ``taskset``, ``gym_api``): docs/architecture.md.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from mtpg.envs.gym_api.registration import GYM_IDS, register_envs
from mtpg.envs.specs.contract import (
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

if TYPE_CHECKING:
    from mtpg.envs.dynamics.dispatch import env_observe, env_reset, env_step
    from mtpg.envs.gym_api.env import MtpgEnv
    from mtpg.envs.specs.param_table import (
        ACTION_BOUND,
        MAX_STEPS,
        N_PARAMS,
        STATE_DIMS,
        TASK_PARAMS,
        USES_CONTINUOUS,
    )
    from mtpg.envs.taskset.episodes import make_episodes, sample_start
    from mtpg.envs.taskset.reference_scores import REFERENCE, normalise

_LAZY: dict[str, str] = {
    "TASK_PARAMS": "mtpg.envs.specs.param_table",
    "N_PARAMS": "mtpg.envs.specs.param_table",
    "MAX_STEPS": "mtpg.envs.specs.param_table",
    "ACTION_BOUND": "mtpg.envs.specs.param_table",
    "USES_CONTINUOUS": "mtpg.envs.specs.param_table",
    "STATE_DIMS": "mtpg.envs.specs.param_table",
    "env_reset": "mtpg.envs.dynamics.dispatch",
    "env_observe": "mtpg.envs.dynamics.dispatch",
    "env_step": "mtpg.envs.dynamics.dispatch",
    "sample_start": "mtpg.envs.taskset.episodes",
    "make_episodes": "mtpg.envs.taskset.episodes",
    "MtpgEnv": "mtpg.envs.gym_api.env",
    "REFERENCE": "mtpg.envs.taskset.reference_scores",
    "normalise": "mtpg.envs.taskset.reference_scores",
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
