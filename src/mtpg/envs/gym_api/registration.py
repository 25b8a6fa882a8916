"""Registers every task of the registry with Gymnasium under the ``mtpg/`` namespace.

Only Gymnasium is imported here; the environment class (and numba) loads when an
environment is made. A variant is registered on request (:func:`register`).
"""

from __future__ import annotations

from mtpg.envs.specs.registry import TASKS

#: Gymnasium ids, in task-id order.
GYM_IDS: tuple[str, ...] = tuple(t.gym_id for t in TASKS)

ENTRY_POINT = "mtpg.envs.gym_api.env:MtpgEnv"

#: Gymnasium id of the multi-task environment (:mod:`mtpg.envs.gym_api.multitask`).
MULTITASK_ID = "mtpg/MultiTask-v0"
MULTITASK_ENTRY_POINT = "mtpg.envs.gym_api.multitask:MultiTaskEnv"


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


def register(name: str) -> str:
    """Registers a task or variant with Gymnasium (idempotent); returns its id.

    ``gymnasium.make(register("CartPole[max_steps=500]"), action="native")`` then makes
    the variant's environment.
    """
    import gymnasium

    from mtpg.envs.taskset.variants import canonical, gym_id

    env_id = gym_id(name)
    if env_id not in gymnasium.registry:
        gymnasium.register(id=env_id, entry_point=ENTRY_POINT, kwargs={"task": canonical(name)})
    return env_id
