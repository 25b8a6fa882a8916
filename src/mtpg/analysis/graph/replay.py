"""Traced replays of a graph on test episodes, and their ``.npz`` file format.

A replay plays the same held-out episodes as ``mtpg evaluate`` (seeds from
:func:`mtpg.envs.taskset.episode_seeds.held_out_seeds`) with the tracing kernel, which follows
exactly the decisions of the batch kernel, so the returns are equal.

``.npz`` schema (version 1). ``N`` steps over all episodes, ``E`` episodes, teams, banks
and programs numbered as in :mod:`mtpg.analysis.description.numbering` (team 1 is the root). Ragged
per-step lists are flat arrays with offsets: the entries of step ``i`` are
``x[x_offsets[i]:x_offsets[i + 1]]``.

=====================  ==========  ===========================================================
key                    shape       meaning
=====================  ==========  ===========================================================
schema_version         ()          1
task, task_id          ()          task name and id
root_team              ()          model id of the root team
no_memory              ()          whether memory was off (ablation semantics)
seed                   ()          test seed offset
team_ids               (T,)        model id of team number ``k + 1``
bank_ids               (B,)        model id of bank number ``k + 1``
n_memory               ()          registers per bank ``M``
episode_seeds          (E,)        episode seeds
returns                (E,)        episode returns
episode_offsets        (E + 1,)    steps of episode ``e``: ``episode_offsets[e]:[e + 1]``
episode, step          (N,)        episode index and step within the episode
hidden_state           (N, 6)      full task state before the decision (see envs.specs.contract)
observation            (N, 2)      the inputs ``s(t)`` the decision saw
a_d, a_c, reward       (N,)        discrete action, continuous action, reward of the step
final_state            (E, 6)      task state after the last step
memory                 (N', B*M)   every memory register after each decision, column
                                   ``(b - 1) * M + r`` for bank ``b`` register ``r``; rows
                                   for the first ``memory_episodes`` episodes only
memory_episodes        ()          episodes covered by ``memory``
visit_team             (V,)        team numbers in visiting order; ``visit_offsets`` (N+1,)
exec_program, exec_bid (P,)        programs executed (model ids) and their bids;
                                   ``exec_offsets`` (N+1,)
instr_program          (I,)        model program id of each instruction executed
instr_position         (I,)        its index in the program's full code; ``instr_offsets``
mem_bank, mem_register (A,)        memory register accessed (bank number, register)
mem_is_write           (A,)        True for a write, False for a read
mem_age                (A,)        steps since the value read (or overwritten) was written:
                                   0 = this step; a value still holding the reset 0 from
                                   the episode start counts as written at step -1 (age
                                   ``t + 1``); with memory off every value is reset before
                                   each program, so ages are 0. ``mem_offsets`` (N+1,)
mem_from_reset         (A,)        True when the value had not been written in the episode
                                   (it is the reset 0)
=====================  ==========  ===========================================================

A Gymnasium task's replay (:mod:`mtpg.analysis.graph.gym_replay`) has every key; its
``observation`` is ``(N, n_obs)``, ``hidden_state`` and ``final_state`` have no columns, and
it adds ``raw_observation``, ``env_action_d`` and ``env_action_c``.
"""

from __future__ import annotations

from collections.abc import Iterator, KeysView
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from mtpg.analysis.description.numbering import effective_instruction_map, index_graph
from mtpg.analysis.graph.gym_replay import gym_keys, trace_gym_episodes
from mtpg.engine.compile import CompiledPopulation, compile_population
from mtpg.engine.trace import Trace, trace_episode, trace_sequence
from mtpg.envs.taskset.episode_seeds import held_out_seeds
from mtpg.envs.taskset.episodes import draw_episodes
from mtpg.envs.taskset.task_table import TaskTable
from mtpg.envs.taskset.variants import canonical, known
from mtpg.model.graph import Population

SCHEMA_VERSION = 1
#: The ragged per-step lists and the keys they hold.
RAGGED = {
    "visit": ("visit_team",),
    "exec": ("exec_program", "exec_bid"),
    "instr": ("instr_program", "instr_position"),
    "mem": ("mem_bank", "mem_register", "mem_is_write", "mem_age", "mem_from_reset"),
}


@dataclass(frozen=True)
class Replay:
    """Traced episodes of one task: the arrays of the module's ``.npz`` schema.

    Attributes:
        data: Arrays by schema key.
    """

    data: dict[str, np.ndarray]

    def __getitem__(self, key: str) -> np.ndarray:
        return self.data[key]

    def __iter__(self) -> Iterator[str]:
        """The schema keys, as iterating over the ``.npz`` file gives them."""
        return iter(self.data)

    def __len__(self) -> int:
        return len(self.data)

    def __contains__(self, key: object) -> bool:
        return key in self.data

    def keys(self) -> KeysView[str]:
        """The schema keys (``dict(replay)`` and ``np.savez(f, **replay)`` work)."""
        return self.data.keys()

    @property
    def task(self) -> str:
        """Task name."""
        return str(self.data["task"])

    @property
    def n_steps(self) -> int:
        """Steps over all episodes."""
        return len(self.data["step"])

    def per_step(self, name: str, key: str) -> list[np.ndarray]:
        """The ragged list ``name`` (visit, exec, instr, mem) of ``key`` split by step."""
        offsets = self.data[f"{name}_offsets"]
        return np.split(self.data[key], offsets[1:-1])

    def counts(self, name: str) -> np.ndarray:
        """Entries per step of a ragged list."""
        return np.diff(self.data[f"{name}_offsets"])

    def episode_slice(self, episode: int) -> slice:
        """Steps of one episode."""
        off = self.data["episode_offsets"]
        return slice(int(off[episode]), int(off[episode + 1]))

    def save(self, path: str | Path) -> Path:
        """Writes the replay as a compressed ``.npz`` file."""
        path = Path(path)
        if path.suffix != ".npz":
            raise ValueError(f"{path}: a replay file must end in .npz")
        np.savez_compressed(path, **self.data)
        return path


def load_replay(path: str | Path) -> Replay:
    """Reads a replay ``.npz`` file.

    Raises:
        ValueError: When the file is not a replay of a known schema version.
    """
    with np.load(path, allow_pickle=False) as f:
        data = {k: f[k] for k in f.files}
    if int(data.get("schema_version", -1)) != SCHEMA_VERSION:
        raise ValueError(f"{path}: not a version-{SCHEMA_VERSION} mtpg replay file")
    return Replay(data)


def _offsets(step_col: np.ndarray, n_steps: int) -> np.ndarray:
    return np.searchsorted(step_col, np.arange(n_steps + 1)).astype(np.int64)


def replay_task(
    pop: Population,
    root: int,
    task: str,
    episodes: int = 1,
    seed: int = 0,
    no_memory: bool = False,
    memory_episodes: int | None = None,
    table: TaskTable | None = None,
) -> Replay:
    """Plays and traces test episodes of one task.

    Args:
        pop: The population holding the graph.
        root: Root team id.
        task: Task name.
        episodes: Number of test episodes (the seeds ``mtpg evaluate`` uses).
        seed: Test seed offset.
        no_memory: Run with memory off (the TPG-NoMemory semantics).
        memory_episodes: Record all memory registers for this many leading episodes
            (None: all; large graphs over many episodes make this array big).
        table: A task table holding ``task`` (a run's); the table of ``task`` alone when
            None. The replay's ``task_id`` is the task's id there.

    Returns:
        The replay.
    """
    if not known(task):
        canonical(task)  # raises, naming the fault
        raise ValueError(f"write task {task!r} as {canonical(task)!r}")
    if episodes < 1:
        raise ValueError(f"episodes must be >= 1, got {episodes}")
    table = TaskTable.from_names([task]) if table is None else table
    task_id = table.id_of(task)
    # the tracer logs programs as stated (unfolded); the ablation is the compiled graph's
    cp = compile_population(pop, fold_constants=False, no_memory=no_memory)
    seeds = held_out_seeds(episodes, seed)
    n_mem_eps = episodes if memory_episodes is None else min(episodes, memory_episodes)
    header = {"task": task, "task_id": task_id, "seed": seed, "episode_seeds": seeds}
    if table.is_gym(task_id):  # the environment steps in Python: traced from Python
        played = trace_gym_episodes(cp, root, table.spec(task_id), seeds, n_mem_eps)
        replay = _assemble(pop, root, cp, [p.trace for p in played], header, no_memory, n_mem_eps)
        return Replay({**replay.data, **gym_keys(played)})
    starts, noise, obs_noise = draw_episodes(np.full(episodes, task_id), seeds, table)
    traces = [
        trace_episode(
            cp,
            root,
            task_id,
            starts[e],
            noise[e],
            snapshot=e < n_mem_eps,
            obs_noise=obs_noise[e] if obs_noise.shape[1] else None,
            params=table.params,
            user=table.user,
        )
        for e in range(episodes)
    ]
    return _assemble(pop, root, cp, traces, header, no_memory, n_mem_eps)


def replay_observations(
    pop: Population, root: int, observations: np.ndarray, no_memory: bool = False
) -> Replay:
    """Traces the graph's decisions on a given input sequence ``(n, 2)`` (one "episode").

    No task runs: ``task`` is empty, ``task_id`` -1, hidden states and rewards are 0.
    Useful to probe a graph with inputs of one's own making.
    """
    # the tracer logs programs as stated (unfolded); the ablation is the compiled graph's
    cp = compile_population(pop, fold_constants=False, no_memory=no_memory)
    trace = trace_sequence(cp, root, observations, snapshot=True)
    header = {"task": "", "task_id": -1, "seed": 0, "episode_seeds": np.zeros(1, np.int64)}
    return _assemble(pop, root, cp, [trace], header, no_memory, 1)


def _dense_numbers(index, cp: CompiledPopulation, m: int) -> tuple[np.ndarray, ...]:
    """Team and bank numbers of the compiled (dense) indices, and the graph's memory columns."""
    team_number = np.zeros(len(cp.team_ids), dtype=np.int64)
    for k, tid in enumerate(index.teams):
        team_number[cp.team_index(tid)] = k + 1
    bank_number = np.zeros(len(cp.bank_ids), dtype=np.int64)
    columns = []
    for k, bid in enumerate(index.banks):
        dense = cp.bank_index(bid)
        bank_number[dense] = k + 1
        columns.extend(range(dense * m, (dense + 1) * m))
    return team_number, bank_number, np.array(columns, dtype=np.int64)


def _memory_accesses(
    log: np.ndarray, bank_number: np.ndarray, no_memory: bool, n: int
) -> dict[str, np.ndarray]:
    """The ``mem_*`` arrays of one episode's memory log (see the schema for the ages)."""
    t, last = log[:, 0], log[:, 4]
    age = np.where(last >= 0, t - last, 0 if no_memory else t + 1)
    return {
        "mem_bank": bank_number[log[:, 1]],
        "mem_register": log[:, 2],
        "mem_is_write": log[:, 3].astype(bool),
        "mem_age": age.astype(np.int64),
        "mem_from_reset": last < 0,
        "mem_offsets": _offsets(t, n),
    }


def _assemble(
    pop: Population,
    root: int,
    cp: CompiledPopulation,
    traces: list[Trace],
    header: dict,
    no_memory: bool,
    n_mem_eps: int,
) -> Replay:
    """Joins traced episodes into the arrays of the schema, with graph numbering."""
    index = index_graph(pop, root)
    m = pop.layout.n_memory
    team_number, bank_number, columns = _dense_numbers(index, cp, m)
    instr_prog, instr_pos = effective_instruction_map(pop, cp.program_ids)
    parts: dict[str, list[np.ndarray]] = {}

    def add(key: str, value: np.ndarray) -> None:
        parts.setdefault(key, []).append(value)

    returns, lengths, finals = [], [], []
    for e, tr in enumerate(traces):
        n = len(tr.actions)
        lengths.append(n)
        returns.append(float(sum(tr.rewards.tolist(), 0.0)))  # the kernel's summation order
        finals.append(tr.states[n])
        add("episode", np.full(n, e, dtype=np.int64))
        add("step", np.arange(n, dtype=np.int64))
        add("hidden_state", tr.states[:n])
        add("observation", tr.observations)
        add("a_d", tr.actions[:, 0].astype(np.int64))
        add("a_c", tr.actions[:, 1])
        add("reward", tr.rewards)
        if e < n_mem_eps:
            add("memory", tr.memory[:, columns])
        add("visit_team", team_number[tr.team_log[:, 1]])
        add("visit_offsets", _offsets(tr.team_log[:, 0], n))
        add("exec_program", cp.program_ids[tr.prog_log[:, 1]])
        add("exec_bid", tr.bids)
        add("exec_offsets", _offsets(tr.prog_log[:, 0], n))
        add("instr_program", instr_prog[tr.instr_log[:, 1]])
        add("instr_position", instr_pos[tr.instr_log[:, 1]])
        add("instr_offsets", _offsets(tr.instr_log[:, 0], n))
        for key, value in _memory_accesses(tr.mem_log, bank_number, no_memory, n).items():
            add(key, value)
    data: dict[str, np.ndarray] = {
        "schema_version": np.array(SCHEMA_VERSION),
        "task": np.array(header["task"]),
        "task_id": np.array(header["task_id"]),
        "root_team": np.array(root),
        "no_memory": np.array(bool(no_memory)),
        "seed": np.array(header["seed"]),
        "team_ids": np.array(index.teams, dtype=np.int64),
        "bank_ids": np.array(index.banks, dtype=np.int64),
        "n_memory": np.array(m),
        "episode_seeds": np.asarray(header["episode_seeds"], dtype=np.int64),
        "returns": np.array(returns),
        "episode_offsets": np.concatenate([[0], np.cumsum(lengths)]).astype(np.int64),
        "final_state": np.array(finals).reshape(len(traces), -1),
        "memory_episodes": np.array(n_mem_eps),
    }
    for key, chunks in parts.items():
        if key.endswith("_offsets"):
            data[key] = _join_offsets(chunks)
        else:
            data[key] = np.concatenate(chunks)
    if "memory" not in data:
        data["memory"] = np.zeros((0, len(columns)))
    return Replay(data)


def _join_offsets(chunks: list[np.ndarray]) -> np.ndarray:
    """Concatenates per-episode offset arrays (each starting at 0) into one."""
    out = [np.zeros(1, dtype=np.int64)]
    base = 0
    for c in chunks:
        out.append(c[1:] + base)
        base += int(c[-1])
    return np.concatenate(out)


def replay_tasks(
    pop: Population,
    root: int,
    tasks: list[str],
    episodes: int = 1,
    seed: int = 0,
    no_memory: bool = False,
    memory_episodes: int | None = None,
    table: TaskTable | None = None,
) -> dict[str, Replay]:
    """:func:`replay_task` for several tasks, by task name in the order given.

    ``table``: a task table holding the tasks (a run's); the table of ``tasks`` when None.
    """
    table = TaskTable.from_names(tasks) if table is None else table
    return {
        t: replay_task(pop, root, t, episodes, seed, no_memory, memory_episodes, table)
        for t in tasks
    }
