"""Step-by-step outputs of the production decision kernel, for the parity tests.

This driver is test support and lives with the tests: the package's one episode loop is
:func:`mtpg.engine.kernels.run_jobs_queue` (training, testing and the benchmark), besides
the instrumented tracer of :mod:`mtpg.engine.trace` that the analyses use.

Training and testing call :func:`mtpg.engine.kernels.decide` from the batch kernels, which
return only per-episode totals. The drivers here call that same ``decide`` (no second copy
of its logic), with the same per-thread buffers and the same lazy bank reset, one decision
at a time, and record after every decision: the action ``a_d``, the continuous output
``a_c``, the teams visited and every memory bank. :mod:`mtpg.engine.reference` is the
oracle these outputs are compared with.

Memory is reported as a program sees it: a bank whose lazy-reset mark is stale (not yet
touched in this episode) reads zero, whatever the workspace still holds from an earlier
episode.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from mtpg.engine.batch import Episodes
from mtpg.engine.compile import CompiledPopulation
from mtpg.engine.kernels import decide, thread_buffers
from mtpg.envs import TASK_PARAMS, env_observe, env_reset, env_step
from mtpg.model.instructions import N_CONSTANTS


@njit(cache=True, error_model="numpy")
def _record(t, W, team_stamp, stamp, bank_stamp, episode, base, M, memory, team_log, n_log):  # noqa: N803
    """Writes step ``t``'s memory row and appends ``[t, team]`` for every team visited."""
    for b in range(len(bank_stamp)):
        live = bank_stamp[b] == episode
        for j in range(M):
            memory[t, b * M + j] = W[base + b * M + j] if live else 0.0
    for team in range(len(team_stamp)):
        if team_stamp[team] == stamp:
            if n_log == team_log.shape[0]:
                grown = np.empty((2 * n_log + 16, 2), dtype=np.int64)
                grown[:n_log] = team_log[:n_log]
                team_log = grown
            team_log[n_log, 0] = t
            team_log[n_log, 1] = team
            n_log += 1
    return team_log, n_log


@njit(cache=True, error_model="numpy")
def _step(
    t,
    root,
    episode,
    no_memory,
    W,
    team_stamp,
    bank_stamp,
    counts,
    actions,
    teams,
    n_instr,
    memory,
    team_log,
    n_log,
    team_offsets,
    team_members,
    prog_offsets,
    instrs,
    prog_action,
    prog_bank,
    R,
    M,
    base,
):  # noqa: N803
    """Decision ``t`` with the production ``decide``, its outputs written into row ``t``."""
    counts[:] = 0
    a_d, a_c = decide(
        root,
        W,
        team_stamp,
        t,
        bank_stamp,
        episode,
        no_memory,
        counts,
        team_offsets,
        team_members,
        prog_offsets,
        instrs,
        prog_action,
        prog_bank,
        R,
        M,
        base,
    )
    actions[t, 0] = a_d
    actions[t, 1] = a_c
    teams[t] = counts[0]
    n_instr[t] = counts[1]
    team_log, n_log = _record(
        t, W, team_stamp, t, bank_stamp, episode, base, M, memory, team_log, n_log
    )
    return a_d, a_c, team_log, n_log


@njit(cache=True, error_model="numpy")
def step_sequence(
    root,
    obs_seq,
    episode_of_step,
    no_memory,
    team_offsets,
    team_members,
    prog_offsets,
    instrs,
    prog_action,
    prog_bank,
    R,
    M,
    base,
):  # noqa: N803
    """Decides for each row of ``obs_seq`` with ``decide``, one call per step.

    ``episode_of_step[t]`` is the episode mark of step ``t`` (non-decreasing): a new mark
    starts a new episode, so every bank reads zero again (the lazy reset of the batch
    kernels).

    Returns:
        ``actions (n, 2)`` [a_d, a_c], ``teams (n)`` teams visited per step,
        ``instructions (n)`` instructions executed per step, ``memory (n, n_banks * M)``
        after each step, ``team_log (k, 2)`` [step, dense team] (ascending per step).
    """
    W, team_stamp, bank_stamp, _, counts = thread_buffers(team_offsets, prog_bank, R, M, base)  # noqa: N806
    obs = W[R + N_CONSTANTS : R + N_CONSTANTS + 2]
    n = len(obs_seq)
    actions = np.zeros((n, 2))
    teams = np.zeros(n, dtype=np.int64)
    n_instr = np.zeros(n, dtype=np.int64)
    memory = np.zeros((n, len(bank_stamp) * M))
    team_log = np.empty((16, 2), dtype=np.int64)
    n_log = 0
    for t in range(n):
        obs[0] = obs_seq[t, 0]
        obs[1] = obs_seq[t, 1]
        a_d, a_c, team_log, n_log = _step(
            t,
            root,
            episode_of_step[t],
            no_memory,
            W,
            team_stamp,
            bank_stamp,
            counts,
            actions,
            teams,
            n_instr,
            memory,
            team_log,
            n_log,
            team_offsets,
            team_members,
            prog_offsets,
            instrs,
            prog_action,
            prog_bank,
            R,
            M,
            base,
        )
    return actions, teams, n_instr, memory, team_log[:n_log]


@njit(cache=True, error_model="numpy")
def step_episode(
    root,
    task,
    params,
    start,
    noise,
    no_memory,
    team_offsets,
    team_members,
    prog_offsets,
    instrs,
    prog_action,
    prog_bank,
    R,
    M,
    base,
):  # noqa: N803
    """Plays one episode as ``run_jobs_queue`` does, recording every decision.

    Returns:
        The outputs of :func:`step_sequence`, then ``observations (n, 2)`` (what each
        decision saw) and ``rewards (n)``.
    """
    W, team_stamp, bank_stamp, state, counts = thread_buffers(  # noqa: N806
        team_offsets, prog_bank, R, M, base
    )
    obs = W[R + N_CONSTANTS : R + N_CONSTANTS + 2]
    n = len(noise) - 1
    actions = np.zeros((n, 2))
    teams = np.zeros(n, dtype=np.int64)
    n_instr = np.zeros(n, dtype=np.int64)
    memory = np.zeros((n, len(bank_stamp) * M))
    observations = np.zeros((n, 2))
    rewards = np.zeros(n)
    team_log = np.empty((16, 2), dtype=np.int64)
    n_log = 0
    state[:] = 0.0
    env_reset(task, params, start, state)
    env_observe(task, params, state, noise[0], obs)
    t = 0
    while t < n:
        observations[t, 0] = obs[0]
        observations[t, 1] = obs[1]
        a_d, a_c, team_log, n_log = _step(
            t,
            root,
            0,
            no_memory,
            W,
            team_stamp,
            bank_stamp,
            counts,
            actions,
            teams,
            n_instr,
            memory,
            team_log,
            n_log,
            team_offsets,
            team_members,
            prog_offsets,
            instrs,
            prog_action,
            prog_bank,
            R,
            M,
            base,
        )
        reward, terminated, truncated = env_step(task, params, state, a_d, a_c)
        rewards[t] = reward
        t += 1
        if terminated or truncated:
            break
        env_observe(task, params, state, noise[t], obs)
    return (
        actions[:t],
        teams[:t],
        n_instr[:t],
        memory[:t],
        team_log[:n_log],
        observations[:t],
        rewards[:t],
    )


@dataclass(frozen=True)
class Steps:
    """Per-decision outputs of the production kernel; ids are dense compiled indices.

    Attributes:
        actions: float64 ``(n, 2)``: ``a_d, a_c`` per decision.
        teams: int64 ``(n)``: teams visited per decision.
        instructions: int64 ``(n)``: instructions executed per decision (introns removed).
        memory: float64 ``(n, n_banks * M)``: every compiled bank after each decision.
        team_log: int64 ``(k, 2)``: ``step, team`` for every team visited.
    """

    actions: np.ndarray
    teams: np.ndarray
    instructions: np.ndarray
    memory: np.ndarray
    team_log: np.ndarray

    def visited(self, t: int) -> np.ndarray:
        """Dense indices of the teams visited in decision ``t``, ascending."""
        return self.team_log[self.team_log[:, 0] == t, 1]


def production_steps(
    cp: CompiledPopulation,
    root_id: int,
    observations: np.ndarray,
    episode_of_step: np.ndarray | None = None,
    no_memory: bool = False,
) -> Steps:
    """Runs the production ``decide`` on an observation sequence, one decision per row.

    Args:
        cp: The compiled population.
        root_id: Model id of the root team.
        observations: ``(n, 2)`` observations.
        episode_of_step: Non-decreasing episode marks per step (default: one episode).
        no_memory: The no-memory ablation.

    Returns:
        The outputs after every decision.
    """
    obs = np.ascontiguousarray(observations, dtype=np.float64).reshape(-1, 2)
    if episode_of_step is None:
        episode_of_step = np.zeros(len(obs), dtype=np.int64)
    marks = np.ascontiguousarray(episode_of_step, dtype=np.int64)
    if len(marks) != len(obs) or np.any(np.diff(marks) < 0) or np.any(marks < 0):
        raise ValueError("episode_of_step must be non-negative, non-decreasing, one per step")
    out = step_sequence(cp.team_index(root_id), obs, marks, no_memory, *cp.kernel_args())
    return Steps(*out)


def play_episode(
    cp: CompiledPopulation,
    root_id: int,
    episodes: Episodes,
    row: int,
    no_memory: bool = False,
) -> tuple[Steps, np.ndarray, np.ndarray]:
    """Plays one episode of the table with the production ``decide``, step by step.

    Args:
        cp: The compiled population.
        root_id: Model id of the root team.
        episodes: The episode table.
        row: The episode's row in the table.
        no_memory: The no-memory ablation.

    Returns:
        ``(steps, observations (n, 2), rewards (n))``: the observation each decision saw
        and the reward of its environment step.
    """
    out = step_episode(
        cp.team_index(root_id),
        int(episodes.tasks[row]),
        TASK_PARAMS,
        episodes.starts[row],
        episodes.noise[row],
        no_memory,
        *cp.kernel_args(),
    )
    return Steps(*out[:5]), out[5], out[6]
