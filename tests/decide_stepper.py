"""Step-by-step outputs of the production decision kernel, for the parity tests.

The tracer (:mod:`mtpg.engine.trace`) runs the production :func:`mtpg.engine.episode_kernels.decide`
and :func:`mtpg.engine.episode_kernels.play_episode` with a recorder, with the same per-thread
buffers and the same lazy bank reset; this adapter turns its trace into what the parity
tests compare with :mod:`mtpg.engine.oracle`, decision by decision: the action ``a_d``,
the continuous output ``a_c``, the teams visited and every memory bank.

Memory is reported as a program sees it: a bank whose lazy-reset mark is stale (not yet
touched in this episode) reads zero, whatever the workspace still holds from an earlier
episode.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mtpg.engine.batch import Episodes
from mtpg.engine.compile import CompiledPopulation
from mtpg.engine.trace import Trace, trace_episode, trace_sequence


@dataclass(frozen=True)
class Steps:
    """Per-decision outputs of the production kernel; ids are dense compiled indices.

    Attributes:
        actions: float64 ``(n, 2)``: ``a_d, a_c`` per decision.
        teams: int64 ``(n)``: teams visited per decision.
        instructions: int64 ``(n)``: instructions executed per decision (introns removed).
        memory: float64 ``(n, n_banks * M)``: every compiled bank after each decision.
        team_log: int64 ``(k, 2)``: ``step, team`` for every team visited, in visit order.
    """

    actions: np.ndarray
    teams: np.ndarray
    instructions: np.ndarray
    memory: np.ndarray
    team_log: np.ndarray

    @classmethod
    def of(cls, trace: Trace) -> Steps:
        """The per-decision outputs of a trace."""
        n = len(trace.actions)
        instructions = np.bincount(trace.instr_log[:, 0], minlength=n).astype(np.int64)
        return cls(
            trace.actions, trace.teams_per_decision(), instructions, trace.memory, trace.team_log
        )

    def visited(self, t: int) -> np.ndarray:
        """Dense indices of the teams visited in decision ``t``, in visit order."""
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
    trace = trace_sequence(
        cp, root_id, observations, no_memory=no_memory, episode_of_step=episode_of_step
    )
    return Steps.of(trace)


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
    trace = trace_episode(
        cp,
        root_id,
        int(episodes.tasks[row]),
        episodes.starts[row],
        episodes.noise[row],
        no_memory=no_memory,
        snapshot=True,
    )
    return Steps.of(trace), trace.observations, trace.rewards
