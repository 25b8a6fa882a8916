"""Decisions for many live episodes at once: the engine of tasks that step in Python.

A task whose dynamics run in Python (a Gymnasium environment, :mod:`mtpg.envs.specs.gym_task`)
cannot be stepped inside the compiled episode loop. Its episodes are played from Python
instead, and at every step one compiled call, :func:`decide_live`, decides for every live
``(root, episode)`` pair; then the environments step.

Each pair keeps its own memory: ``store`` holds, per pair, the registers of every bank its
root can reach (:func:`reach_banks`). A decision copies the pair's banks into the thread's
workspace, runs the one decision rule of the engine
(:func:`~mtpg.engine.episode_kernels.decide_bank`), reads the continuous outputs and
copies the banks back. A pair's episode starts with its banks zeroed (:meth:`LiveDecider.reset`),
which equals the lazy reset of the batch kernels, so a pair plays exactly the decisions
:func:`~mtpg.engine.episode_kernels.run_jobs_queue` would (tested against the oracle).

Continuous output ``j`` is ``m[j]`` of the final program's bank (``m[0]`` the paper's
``a_c``). An observation shorter than the layout's inputs leaves the rest at 0 (a program
reading an input its task lacks reads 0).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from mtpg.engine.compile import CompiledPopulation, Graph
from mtpg.engine.episode_kernels import Buffers, decide_bank, thread_buffers


class LivePairs(NamedTuple):
    """The pairs a :class:`LiveDecider` plays (a kernel argument).

    Attributes:
        roots: int64 ``[n]`` dense root team of each pair.
        slots: int64 ``[n]`` the pair's root among the distinct roots (``reach_off`` row).
        store_off: int64 ``[n + 1]``: pair ``i``'s banks are
            ``store[store_off[i]:store_off[i + 1]]``, ``M`` registers per reachable bank.
        reach_off: int64 ``[n_slots + 1]``: the banks root slot ``u`` reaches are
            ``reach_banks[reach_off[u]:reach_off[u + 1]]``.
        reach_banks: int64 dense bank indices.
        work: int64 ``[n, 2]``: teams visited and instructions executed by each pair.
        clock: int64 ``[1]``: the decision stamp (one per decision, never reused).
    """

    roots: np.ndarray
    slots: np.ndarray
    store_off: np.ndarray
    reach_off: np.ndarray
    reach_banks: np.ndarray
    work: np.ndarray
    clock: np.ndarray


@njit(cache=True, error_model="numpy")
def reach_banks(g: Graph, roots: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The dense banks of every program reachable from each root, as CSR rows.

    Args:
        g: The compiled graph.
        roots: int64 dense root teams.

    Returns:
        ``(offsets, banks)``: root ``k`` reaches ``banks[offsets[k]:offsets[k + 1]]``.
    """
    n_teams = len(g.team_offsets) - 1
    n_banks = (g.prog_bank.max() + 1) if len(g.prog_bank) else 0
    seen_team = np.full(n_teams, -1, dtype=np.int64)
    seen_bank = np.full(max(n_banks, 1), -1, dtype=np.int64)
    offsets = np.zeros(len(roots) + 1, dtype=np.int64)
    out = []
    stack = np.zeros(max(n_teams, 1), dtype=np.int64)
    for k in range(len(roots)):
        top = 0
        stack[top] = roots[k]
        top += 1
        seen_team[roots[k]] = k
        while top > 0:
            top -= 1
            t = stack[top]
            for q in range(g.team_offsets[t], g.team_offsets[t + 1]):
                p = g.team_members[q]
                b = g.prog_bank[p]
                if seen_bank[b] != k:
                    seen_bank[b] = k
                    out.append(b)
                a = g.prog_action[p]
                if a >= 0 and seen_team[a] != k:
                    seen_team[a] = k
                    stack[top] = a
                    top += 1
        offsets[k + 1] = len(out)
    banks = np.zeros(len(out), dtype=np.int64)
    for i in range(len(out)):
        banks[i] = out[i]
    return offsets, banks


@njit(cache=True, error_model="numpy", nogil=True)
def decide_live(g, buf, pairs, store, which, obs, act_d, act_c):
    """Decides once for each pair of ``which``, from its observation row.

    Args:
        g: The compiled graph.
        buf: The :class:`~mtpg.engine.episode_kernels.Buffers` of ``g``, every bank
            stamped 0 (so the decision rule never resets a bank: the store holds them).
        pairs: :class:`LivePairs`.
        store: float64: every pair's banks (see :attr:`LivePairs.store_off`).
        which: int64 ``[k]`` the pairs deciding now.
        obs: float64 ``[k, n_in]`` their observations (``n_in`` at most the layout's
            inputs; missing inputs read 0).
        act_d: int64 ``[k]`` out: the atomic actions.
        act_c: float64 ``[k, n_c]`` out: ``m[0..n_c)`` of each final program's bank.
    """
    M, base = g.n_memory, g.mem_base
    W, slots = buf.W, buf.obs
    n_in = min(obs.shape[1], len(slots))
    for i in range(len(slots)):
        slots[i] = 0.0
    for k in range(len(which)):
        i = which[k]
        for s in range(n_in):
            slots[s] = obs[k, s]
        u = pairs.slots[i]
        lo, hi = pairs.reach_off[u], pairs.reach_off[u + 1]
        off = pairs.store_off[i]
        for q in range(lo, hi):
            w = base + pairs.reach_banks[q] * M
            s0 = off + (q - lo) * M
            for j in range(M):
                W[w + j] = store[s0 + j]
        teams, instrs = buf.counts[0], buf.counts[1]
        stamp = pairs.clock[0]
        pairs.clock[0] += 1
        a, at = decide_bank(g, buf, pairs.roots[i], stamp, 0, None)
        act_d[k] = a
        for j in range(act_c.shape[1]):
            act_c[k, j] = W[at + j]
        pairs.work[i, 0] += buf.counts[0] - teams
        pairs.work[i, 1] += buf.counts[1] - instrs
        for q in range(lo, hi):
            w = base + pairs.reach_banks[q] * M
            s0 = off + (q - lo) * M
            for j in range(M):
                store[s0 + j] = W[w + j]


class LiveDecider:
    """Plays ``(root, episode)`` pairs step by step: one compiled call decides for many.

    Args:
        cp: The compiled population.
        roots: Dense root team of each pair (a root may appear in many pairs).
        n_continuous: Continuous outputs per decision (``m[0..n)``; at most ``n_memory``).

    Raises:
        ValueError: When ``n_continuous`` exceeds the bank size.
    """

    def __init__(self, cp: CompiledPopulation, roots: np.ndarray, n_continuous: int = 1) -> None:
        g = cp.graph
        if not 0 <= n_continuous <= g.n_memory:
            raise ValueError(
                f"{n_continuous} continuous outputs need as many memory registers "
                f"(program.n_memory is {g.n_memory})"
            )
        roots = np.ascontiguousarray(roots, dtype=np.int64)
        distinct, slots = np.unique(roots, return_inverse=True)
        reach_off, banks = reach_banks(g, distinct)
        sizes = (reach_off[1:] - reach_off[:-1])[slots] * g.n_memory
        store_off = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
        self.graph = g
        self.n_continuous = n_continuous
        self.buffers: Buffers = thread_buffers(g)
        self.buffers.bank_stamp[:] = 0
        self.pairs = LivePairs(
            roots,
            slots.astype(np.int64),
            store_off,
            reach_off,
            banks,
            np.zeros((len(roots), 2), dtype=np.int64),
            np.zeros(1, dtype=np.int64),
        )
        self.store = np.zeros(int(store_off[-1]))

    def reset(self, pair: int) -> None:
        """Starts a new episode for ``pair``: its banks read zero, its counts restart."""
        lo, hi = self.pairs.store_off[pair], self.pairs.store_off[pair + 1]
        self.store[lo:hi] = 0.0
        self.pairs.work[pair] = 0

    def decide(self, which: np.ndarray, obs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """One decision for each pair of ``which``.

        Args:
            which: int64 ``[k]`` pair indices.
            obs: float64 ``[k, n_in]`` their observations, already in the programs' range.

        Returns:
            ``(a_d, a_c)``: int64 ``[k]`` atomic actions and float64 ``[k, n_continuous]``.
        """
        which = np.ascontiguousarray(which, dtype=np.int64)
        obs = np.ascontiguousarray(obs, dtype=np.float64).reshape(len(which), -1)
        act_d = np.zeros(len(which), dtype=np.int64)
        act_c = np.zeros((len(which), self.n_continuous))
        decide_live(self.graph, self.buffers, self.pairs, self.store, which, obs, act_d, act_c)
        return act_d, act_c
