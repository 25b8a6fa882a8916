"""Episodes of a Gymnasium task: the environments step in Python, the agents do not.

:func:`play_gym` plays a batch of jobs ``(root, reset seed)`` of one
:class:`~mtpg.envs.specs.gym_task.GymTask`: every job has its own environment instance, reset
with its seed; at each step one compiled call (:class:`~mtpg.engine.live.LiveDecider`)
decides for every live job, then each live environment steps. A job's return is the sum
of its rewards in step order, as a plain loop over ``env.step`` adds them, so an episode
can be replayed with Gymnasium alone (``reset(seed=s)``, then the same actions).

Jobs are played in chunks of :data:`CHUNK` environments, to bound the memory the
environments take; results do not depend on it (each job is independent).
"""

from __future__ import annotations

import numpy as np

from mtpg.engine.compile import CompiledPopulation
from mtpg.engine.live import LiveDecider
from mtpg.envs.specs.gym_task import GymTask, GymTaskError

#: Environments alive at once.
CHUNK = 1024


def _step(task: GymTask, env, action, seed: int):
    try:
        return env.step(action)
    except GymTaskError:
        raise
    except Exception as exc:  # the user's step raised: name the task and the episode
        what = str(exc).splitlines()[0] if str(exc) else ""
        raise GymTaskError(
            f"task {task.name}: episode seed {seed}: step raised {type(exc).__name__}: {what}"
        ) from None


def _reset(task: GymTask, env, seed: int) -> np.ndarray:
    try:
        obs, _ = env.reset(seed=seed)
    except Exception as exc:
        what = str(exc).splitlines()[0] if str(exc) else ""
        raise GymTaskError(
            f"task {task.name}: episode seed {seed}: reset raised {type(exc).__name__}: {what}"
        ) from None
    return task.flat(obs, seed)


def play_gym(
    cp: CompiledPopulation, roots: np.ndarray, task: GymTask, seeds: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Plays job ``j``: dense root ``roots[j]`` on ``task`` from ``reset(seed=seeds[j])``.

    Args:
        cp: The compiled population (its memory mode is the run's).
        roots: int64 dense root teams, one per job.
        task: The Gymnasium task.
        seeds: int64 reset seeds, one per job.

    Returns:
        Per job: returns (float64), steps, teams visited and instructions executed (int64),
        the fields of :class:`~mtpg.engine.batch.BatchResult`.

    Raises:
        GymTaskError: One line naming the task and the episode's seed, for an observation
            that is not finite or outside its bounds, or a ``reset`` / ``step`` that raised.
    """
    n = len(roots)
    returns = np.zeros(n)
    steps = np.zeros(n, dtype=np.int64)
    teams = np.zeros(n, dtype=np.int64)
    instructions = np.zeros(n, dtype=np.int64)
    for lo in range(0, n, CHUNK):
        hi = min(lo + CHUNK, n)
        r, s, t, i = _play_chunk(cp, roots[lo:hi], task, seeds[lo:hi])
        returns[lo:hi], steps[lo:hi], teams[lo:hi], instructions[lo:hi] = r, s, t, i
    return returns, steps, teams, instructions


def _play_chunk(cp, roots, task, seeds):
    n = len(roots)
    live = LiveDecider(cp, roots, n_continuous=task.n_continuous)
    envs = [task.make() for _ in range(n)]
    try:
        raw = np.zeros((n, task.n_obs))
        for j in range(n):
            raw[j] = _reset(task, envs[j], int(seeds[j]))
        returns = [0.0] * n
        steps = np.zeros(n, dtype=np.int64)
        alive = np.arange(n, dtype=np.int64)
        while len(alive):
            # every live observation scaled (and checked) at once, then one decision call
            obs = task.scale_rows(raw[alive], seeds[alive])
            a_d, a_c = live.decide(alive, obs)
            still = []
            for k, j in enumerate(alive.tolist()):
                seed = int(seeds[j])
                o, reward, terminated, truncated, _ = _step(
                    task, envs[j], task.action(a_d[k], a_c[k]), seed
                )
                returns[j] += float(reward)
                steps[j] += 1
                if not (terminated or truncated):
                    raw[j] = task.flat(o, seed)
                    still.append(j)
            alive = np.array(still, dtype=np.int64)
    finally:
        for env in envs:
            env.close()
    work = live.pairs.work
    return np.array(returns), steps, work[:, 0].copy(), work[:, 1].copy()
