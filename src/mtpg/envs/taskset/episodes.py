"""Reproducible episodes: start states and noise sequences drawn from one seed per episode."""

from __future__ import annotations

import numpy as np

from mtpg.envs.specs.contract import PREV_FORCE_SLOT, STATE_SIZE, STEP_SLOT
from mtpg.envs.taskset.task_table import REGISTERED, TaskTable
from mtpg.envs.taskset.variants import obs_noise_sd


def sample_start(task: int, rng: np.random.Generator, table: TaskTable = REGISTERED) -> np.ndarray:
    """Draws a start state with Gymnasium's reset distribution (CartCentering: Koza's).

    The draws are those of the Gymnasium environment's ``reset``, so for the five Gymnasium
    tasks ``sample_start(task, np.random.default_rng(s))`` equals the state of
    ``gymnasium.make(name).reset(seed=s)``. CartCentering redraws a start already captured.

    Args:
        task: The task id in ``table``.
        rng: The episode's generator (advanced by the draws).
        table: The task table (the registered tasks by default).

    Returns:
        A float64 array of :func:`state_width` slots: the physical state, then the previous
        force (``+F``) and the step count (0); a compiled task's state from ``STATE_SIZE``.

    Raises:
        ValueError: For an id the table does not know.
    """
    spec = table.spec(int(task))
    start = np.zeros(state_width(table), dtype=np.float64)
    if table.is_user(int(task)):  # its own slots, after the registered tasks' (user_dispatch)
        phys = spec.start(rng)
        start[STATE_SIZE : STATE_SIZE + phys.shape[0]] = phys
        return start
    phys = np.asarray(spec.kernel("sample_start")(rng), dtype=np.float64)
    start[: phys.shape[0]] = phys
    start[PREV_FORCE_SLOT] = spec.params[1]
    start[STEP_SLOT] = 0.0
    return start


def state_width(table: TaskTable) -> int:
    """Slots of a state array of ``table``'s tasks: ``STATE_SIZE``, more with compiled tasks."""
    return STATE_SIZE + max((t.slots for t in table.user), default=0)


def make_episodes(
    tasks: np.ndarray, seeds: np.ndarray, table: TaskTable = REGISTERED
) -> tuple[np.ndarray, np.ndarray]:
    """Draws the start states and noise sequences of a batch of episodes.

    The start states and U[0, 1] sequences of :func:`draw_episodes` (without the
    observation noise of variants that have it).

    For episode ``i``: ``rng = np.random.default_rng(seeds[i])``, the start state is
    ``sample_start(tasks[i], rng)``, then ``MAX_STEPS[tasks[i]] + 1`` noise values are drawn
    with ``rng.random``. ``noise[i, 0]`` is observed at reset and ``noise[i, t + 1]`` after
    step ``t``; padding beyond a task's limit is 0.

    Args:
        tasks: int array [n] of task ids of ``table``.
        seeds: int array [n] of episode seeds.
        table: The task table (the registered tasks by default).

    Returns:
        (starts float64 [n, STATE_SIZE], noise float64 [n, max(MAX_STEPS[tasks]) + 1]).

    Raises:
        ValueError: If the arrays differ in length or a task id is unknown.
    """
    starts, noise, _ = draw_episodes(tasks, seeds, table)
    return starts, noise


def draw_episodes(
    tasks: np.ndarray, seeds: np.ndarray, table: TaskTable = REGISTERED
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Draws the start states, noise sequences and observation noise of a batch of episodes.

    As :func:`make_episodes`; then, for an episode of a variant with observation noise
    (``noise=SD``), the same generator draws ``standard_normal((MAX_STEPS + 1, 2))``: the
    two inputs' normal values of each observation, ``obs_noise[i, t]`` read with
    ``noise[i, t]``. Episodes of other tasks draw nothing more, so their streams are those
    of :func:`make_episodes` alone.

    Returns:
        (starts, noise, obs_noise): ``obs_noise`` float64 ``[n, width, 2]`` (zeros for
        episodes without observation noise), or ``[n, 0, 2]`` when no episode has any.

    Raises:
        ValueError: If the arrays differ in length or a task id is unknown.
    """
    tasks = np.asarray(tasks).reshape(-1)
    seeds = np.asarray(seeds).reshape(-1)
    if tasks.shape != seeds.shape:
        raise ValueError(f"tasks and seeds differ in length: {tasks.shape} vs {seeds.shape}")
    n = tasks.shape[0]
    specs = {int(t): table.spec(int(t)) for t in set(tasks.tolist())}
    # a Gymnasium task's episodes come from its reset(seed=...): its rows stay zero
    gym = {t for t in specs if table.is_gym(t)}
    limits = {t: spec.max_steps for t, spec in specs.items() if t not in gym}
    width = max(limits.values()) + 1 if limits else 1
    noisy = {
        t
        for t, spec in specs.items()
        if t not in gym and not table.is_user(t) and obs_noise_sd(spec) > 0.0
    }
    starts = np.zeros((n, state_width(table)), dtype=np.float64)
    noise = np.zeros((n, width), dtype=np.float64)
    obs_noise = np.zeros((n, width if noisy else 0, 2), dtype=np.float64)
    for i in range(n):
        task = int(tasks[i])
        if task in gym:
            continue
        rng = np.random.default_rng(int(seeds[i]))
        starts[i] = sample_start(task, rng, table)
        k = limits[task] + 1
        noise[i, :k] = rng.random(k)
        if task in noisy:
            obs_noise[i, :k] = rng.standard_normal((k, 2))
    return starts, noise, obs_noise
