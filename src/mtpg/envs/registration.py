"""Registers every task of the registry with Gymnasium under the ``mtpg/`` namespace.

Only Gymnasium is imported here; the environment class (and numba) loads when an
environment is made.
"""

from __future__ import annotations

from mtpg.envs.registry import TASKS

#: Gymnasium ids, in task-id order.
GYM_IDS: tuple[str, ...] = tuple(t.gym_id for t in TASKS)

ENTRY_POINT = "mtpg.envs.gym_env:MtpgEnv"

#: Gymnasium id of the multi-task environment (:mod:`mtpg.envs.multitask`).
MULTITASK_ID = "mtpg/MultiTask-v0"
MULTITASK_ENTRY_POINT = "mtpg.envs.multitask:MultiTaskEnv"


def register_envs() -> None:
    """Registers every task id and ``mtpg/MultiTask-v0`` with Gymnasium (idempotent).

    The time limit is enforced by the environment itself (it reports ``truncated``), so
    no ``TimeLimit`` wrapper is added.
    """
    import gymnasium

    for task, env_id in enumerate(GYM_IDS):
        if env_id in gymnasium.registry:
            continue
        gymnasium.register(
            id=env_id,
            entry_point=ENTRY_POINT,
            kwargs={"task": task},
            disable_env_checker=False,
        )
    if MULTITASK_ID not in gymnasium.registry:
        gymnasium.register(
            id=MULTITASK_ID, entry_point=MULTITASK_ENTRY_POINT, disable_env_checker=False
        )
