"""A plain-Python reference interpreter: the oracle the compiled kernels must match.

It interprets the :class:`~mtpg.model.Population` directly (every instruction, introns
included, logical register layout, memory as one list per bank), following the semantics
of paper section 4 and :mod:`mtpg.model.instructions` line by line. It is slow by design
and used by the tests and by ``mtpg bench engine`` as the baseline.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from mtpg.model.graph import Population
from mtpg.model.instructions import BIG, CONSTANTS, DIV_EPS, LOG_BIG, LOG_TINY

_CONST = [float(c) for c in CONSTANTS]


def reference_op(op: int, d: float, a: float, b: float) -> float:
    """The protected operation table of :mod:`mtpg.model.instructions` in plain Python."""
    if op == 0:
        v = a + b
    elif op == 1:
        v = a - b
    elif op == 2:
        v = a * b
    elif op == 3:
        v = a if abs(b) < DIV_EPS else a / b
    elif op == 4:
        x = abs(a)
        if x == 0.0:
            v = 0.0
        else:
            e = b * math.log(x)
            v = BIG if e > LOG_BIG else 0.0 if e < LOG_TINY else math.pow(x, b)
    elif op == 5:
        v = math.cos(b)
    elif op == 6:
        v = 0.0 if b == 0.0 else math.log(abs(b))
    elif op == 7:
        v = BIG if b > LOG_BIG else math.exp(b)
    elif op == 8:
        v = math.sqrt(abs(b))
    elif op == 9:
        v = math.sin(b)
    elif op == 10:
        v = math.tanh(b)
    elif op == 11:
        v = b * b
    elif op == 12:
        v = abs(b)
    elif op == 13:
        v = b * b * b
    elif op == 14:
        v = -d if a < b else d
    else:
        v = -d if a > b else d
    return min(max(v, -BIG), BIG)


@dataclass
class Decision:
    """What one reference decision did.

    Attributes:
        action: The discrete action ``a_d``.
        continuous: The continuous action ``a_c``.
        teams: Team ids visited, in order.
        bids: ``(program id, bid)`` of every program executed, in order.
        bank: Id of the final program's memory bank (continuous output ``j`` is its
            ``m[j]``).
    """

    action: int
    continuous: float
    teams: list[int] = field(default_factory=list)
    bids: list[tuple[int, float]] = field(default_factory=list)
    bank: int = -1


class ReferenceAgent:
    """Runs one root team of a population, decision by decision.

    Args:
        pop: The population.
        root: Id of the team to start every decision from.
        no_memory: Zero each bank before every program execution (ablation).
    """

    def __init__(self, pop: Population, root: int, no_memory: bool = False) -> None:
        self.pop = pop
        self.root = root
        self.no_memory = no_memory
        self.memory: dict[int, list[float]] = {}

    def reset(self) -> None:
        """Starts an episode: every memory bank reads zero."""
        self.memory = {}

    def bank(self, bank_id: int) -> list[float]:
        """The registers of a bank (zeros if not used yet in this episode)."""
        if bank_id not in self.memory:
            self.memory[bank_id] = [0.0] * self.pop.layout.n_memory
        return self.memory[bank_id]

    def run_program(self, pid: int, obs: list[float]) -> float:
        """Executes program ``pid`` (all instructions) and returns its bid ``r[0]``."""
        layout = self.pop.layout
        prog = self.pop.programs[pid]
        if self.no_memory:
            self.memory[prog.bank] = [0.0] * layout.n_memory
        m = self.bank(prog.bank)
        r = [0.0] * layout.n_registers
        n_r, n_m = layout.n_registers, layout.n_memory

        def read(i: int) -> float:
            if i < n_r:
                return r[i]
            if i < n_r + n_m:
                return m[i - n_r]
            if i < layout.obs_start:
                return _CONST[i - n_r - n_m]
            return obs[i - layout.obs_start]

        for op, dst, a, b in prog.instructions.tolist():
            value = reference_op(op, read(dst), read(a), read(b))
            if dst < n_r:
                r[dst] = value
            else:
                m[dst - n_r] = value
        return r[0]

    def act(self, obs: np.ndarray | list[float]) -> Decision:
        """Makes one decision for observation ``obs``.

        An observation shorter than the layout's inputs leaves the rest at 0 (a program
        reading an input its task lacks reads 0).
        """
        obs = [float(x) for x in obs]
        obs += [0.0] * (self.pop.layout.n_obs - len(obs))
        visited: set[int] = set()
        decision = Decision(action=-1, continuous=0.0)
        team_id = self.root
        while True:
            visited.add(team_id)
            decision.teams.append(team_id)
            best_pid, best_bid = None, 0.0
            for pid in self.pop.teams[team_id].programs:
                bid = self.run_program(pid, obs)
                decision.bids.append((pid, bid))
                target = self.pop.programs[pid].action
                eligible = target < 0 or target not in visited
                if eligible and (best_pid is None or bid > best_bid):
                    best_pid, best_bid = pid, bid
            winner = self.pop.programs[best_pid]
            if winner.is_atomic:
                decision.action = winner.atomic_action
                decision.continuous = self.bank(winner.bank)[0]
                decision.bank = winner.bank
                return decision
            team_id = winner.action


def reference_episode(
    agent: ReferenceAgent,
    task: int,
    start: np.ndarray,
    noise: np.ndarray,
    obs_noise: np.ndarray | None = None,
    params: np.ndarray | None = None,
) -> tuple[float, int]:
    """Plays one episode with the environment kernels called from Python.

    Args:
        agent: The agent (its memory is reset first).
        task: Task id.
        start: Start state (``STATE_SIZE``).
        noise: The episode's noise row.
        obs_noise: The episode's observation-noise rows ``[T + 1, 2]`` (a variant with
            ``noise``), or None.
        params: The parameter table ``task`` indexes (its task table's ``params``; the
            registered tasks' by default).

    Returns:
        ``(return, steps)``.
    """
    from mtpg.envs import env_observe, env_reset, env_step
    from mtpg.envs.specs.contract import STATE_SIZE
    from mtpg.envs.specs.param_table import TASK_PARAMS

    params = TASK_PARAMS if params is None else params

    agent.reset()
    state = np.zeros(STATE_SIZE)
    obs = np.zeros(2)
    env_reset(task, params, start, state)
    eps = obs_noise if obs_noise is not None and len(obs_noise) else None
    env_observe(task, params, state, noise[0], obs, None if eps is None else eps[0])
    total, t = 0.0, 0
    while True:
        d = agent.act(obs)
        reward, terminated, truncated = env_step(task, params, state, d.action, d.continuous)
        total += reward
        t += 1
        if terminated or truncated:
            return total, t
        env_observe(task, params, state, noise[t], obs, None if eps is None else eps[t])
