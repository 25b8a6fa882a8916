"""What happens inside a graph during replays (paper section 6), as plain arrays.

Every function takes :class:`~mtpg.analysis.graph.replay.Replay` objects and returns NumPy arrays
or dicts of them; :mod:`mtpg.analysis.graph.figures` only draws these.
"""

from __future__ import annotations

import numpy as np

from mtpg.analysis.graph.replay import Replay
from mtpg.envs.specs.registry import TASKS
from mtpg.envs.taskset.variants import task_spec

#: State slot of the hidden velocity each task's analysis tracks (section 6.3), each spec's
#: ``velocity_slot``: CartPole the pole's angular velocity, Acrobot the first joint's (the
#: paper's choice), the others their only velocity. The paper leaves CartPole's choice
#: open; the pole's is the one its control depends on most.
HIDDEN_VELOCITY: dict[str, int] = {t.name: t.velocity_slot for t in TASKS}
#: Label of that variable.
VELOCITY_NAME: dict[str, str] = {t.name: t.velocity_name for t in TASKS}


def final_teams(replay: Replay) -> np.ndarray:
    """The team number that produced the action at each step (the last team visited)."""
    return replay["visit_team"][replay["visit_offsets"][1:] - 1]


def visit_statistics(replays: dict[str, Replay], n_teams: int) -> dict[str, np.ndarray]:
    """How often each team runs in each task (Fig. 9 top).

    Args:
        replays: Replays by task name.
        n_teams: Teams of the graph (numbers 1..n_teams).

    Returns:
        ``tasks`` (K,), ``teams`` (T,) numbers, ``visits`` (T, K) visit counts,
        ``rate`` (T, K) fraction of the task's steps in which the team was visited (1 for
        the root), ``share`` (T, K) the team's part of all team visits in the task (each
        column sums to 1), ``pie`` (T, K) each team's rates normalised over tasks (each
        row of a visited team sums to 1: the pie slices), ``final`` (T, K) fraction of the
        task's steps in which the team chose the action.
    """
    tasks = list(replays)
    visits = np.zeros((n_teams, len(tasks)))
    final = np.zeros((n_teams, len(tasks)))
    steps = np.zeros(len(tasks))
    for k, task in enumerate(tasks):
        r = replays[task]
        visits[:, k] = np.bincount(r["visit_team"] - 1, minlength=n_teams)[:n_teams]
        final[:, k] = np.bincount(final_teams(r) - 1, minlength=n_teams)[:n_teams]
        steps[k] = r.n_steps
    steps = np.maximum(steps, 1)
    rate = visits / steps
    col = visits.sum(axis=0, keepdims=True)
    share = np.divide(visits, col, out=np.zeros_like(visits), where=col > 0)
    row = rate.sum(axis=1, keepdims=True)
    pie = np.divide(rate, row, out=np.zeros_like(rate), where=row > 0)
    return {
        "tasks": np.array(tasks),
        "teams": np.arange(1, n_teams + 1),
        "visits": visits,
        "rate": rate,
        "share": share,
        "pie": pie,
        "final": final / steps,
    }


def register_access(replays: dict[str, Replay]) -> dict[str, np.ndarray]:
    """Share of accesses (read or write) of each memory register by task (Fig. 9 bottom).

    Accesses are counted per step of each task (so a register of the root, used at every
    step, gets equal shares whatever the episode lengths), then normalised over tasks.
    Registers never accessed are left out; the rest are ordered from the most specialised
    (largest share of one task) to the most evenly shared, ties by their dominant task.

    Returns:
        ``tasks`` (K,), ``bank`` and ``register`` (R,) of each register, ``labels`` (R,)
        like ``"b3.m0"``, ``count`` (R, K) accesses, ``rate`` (R, K) accesses per step,
        ``share`` (R, K) (rows sum to 1).
    """
    tasks = list(replays)
    m = int(next(iter(replays.values()))["n_memory"]) if replays else 1
    n_banks = max((len(r["bank_ids"]) for r in replays.values()), default=0)
    count = np.zeros((n_banks * m, len(tasks)))
    steps = np.ones(len(tasks))
    for k, task in enumerate(tasks):
        r = replays[task]
        cell = (r["mem_bank"] - 1) * m + r["mem_register"]
        count[:, k] = np.bincount(cell, minlength=n_banks * m)[: n_banks * m]
        steps[k] = max(r.n_steps, 1)
    used = np.flatnonzero(count.sum(axis=1) > 0)
    rate = count[used] / steps
    share = rate / rate.sum(axis=1, keepdims=True) if len(used) else rate
    top = np.round(share.max(axis=1), 9)
    order = np.lexsort((share.argmax(axis=1), -top))  # most specialised first, even last
    used = used[order]
    bank, reg = used // m + 1, used % m
    return {
        "tasks": np.array(tasks),
        "bank": bank,
        "register": reg,
        "labels": np.array([f"b{b}.m{r}" for b, r in zip(bank, reg, strict=True)]),
        "count": count[used],
        "rate": rate[order],
        "share": share[order],
    }


def step_series(replay: Replay, episode: int = 0) -> dict[str, np.ndarray]:
    """Per-step complexity and memory window of one episode (Figs. 11-12, top rows).

    Returns:
        ``step`` (n,), ``teams`` teams visited, ``instructions`` instructions executed,
        ``newest`` and ``oldest`` the smallest and largest age (steps since written, see the
        replay schema) of the memory values read at the step that were written in this
        episode (NaN: none; a read of a register still holding its reset 0 carries no
        information from the past, so it does not widen the window), ``reads`` memory
        reads (all of them).
    """
    sl = replay.episode_slice(episode)
    n = sl.stop - sl.start
    teams = replay.counts("visit")[sl]
    instructions = replay.counts("instr")[sl]
    off = replay["mem_offsets"]
    ages = replay["mem_age"]
    reads = ~replay["mem_is_write"]
    remembered = reads & ~replay["mem_from_reset"]
    newest = np.full(n, np.nan)
    oldest = np.full(n, np.nan)
    n_reads = np.zeros(n, dtype=np.int64)
    for i in range(n):
        lo, hi = off[sl.start + i], off[sl.start + i + 1]
        a = ages[lo:hi][remembered[lo:hi]]
        n_reads[i] = int(reads[lo:hi].sum())
        if len(a):
            newest[i], oldest[i] = a.min(), a.max()
    return {
        "step": np.arange(n),
        "teams": teams,
        "instructions": instructions,
        "newest": newest,
        "oldest": oldest,
        "reads": n_reads,
    }


def pearson_columns(x: np.ndarray, columns: np.ndarray) -> np.ndarray:
    """Pearson r of ``x`` (n,) with each column of ``columns`` (n, c); NaN for constants."""
    x = np.asarray(x, dtype=np.float64)
    cols = np.asarray(columns, dtype=np.float64)
    xc = x - x.mean()
    cc = cols - cols.mean(axis=0)
    denom = np.sqrt((xc**2).sum()) * np.sqrt((cc**2).sum(axis=0))
    num = xc @ cc
    with np.errstate(invalid="ignore", divide="ignore"):
        r = num / denom
    r[~(denom > 0)] = np.nan
    return r


def best_register(velocity: np.ndarray, memory: np.ndarray) -> tuple[int, float]:
    """The memory column that correlates best (largest ``|r|``) with the velocity.

    Args:
        velocity: (n,) the hidden velocity.
        memory: (n, c) memory registers.

    Returns:
        ``(column, r)``; ``(-1, nan)`` when no column varies (or the velocity is constant).
    """
    if memory.shape[1] == 0 or len(velocity) < 2:
        return -1, float("nan")
    r = pearson_columns(velocity, memory)
    if np.all(np.isnan(r)):
        return -1, float("nan")
    col = int(np.nanargmax(np.abs(r)))
    return col, float(r[col])


def scale_pm1(x: np.ndarray) -> np.ndarray:
    """Linearly maps ``x`` onto [-1, 1] (a constant maps to 0)."""
    x = np.asarray(x, dtype=np.float64)
    if len(x) == 0:
        return x.copy()
    lo, hi = x.min(), x.max()
    if hi == lo:
        return np.zeros_like(x)
    return 2.0 * (x - lo) / (hi - lo) - 1.0


def velocity_prediction(replay: Replay, episode: int = 0) -> dict[str, np.ndarray | float | str]:
    """The memory register that best tracks the hidden velocity in one episode (sec. 6.3).

    Returns:
        ``velocity`` and ``register`` (n,) both scaled to [-1, 1] (the register negated
        when ``r < 0``, so the curves can be compared), ``r`` Pearson r of the raw series,
        ``label`` the register (``"b3.m0"``, empty when none varies), ``variable`` the
        velocity's name.
    """
    if episode >= int(replay["memory_episodes"]):
        raise ValueError(f"episode {episode} has no memory recording in this replay")
    sl = replay.episode_slice(episode)
    task = replay.task
    velocity = replay["hidden_state"][sl, task_spec(task).velocity_slot]
    memory = replay["memory"][sl]
    col, r = best_register(velocity, memory)
    m = int(replay["n_memory"])
    reg = memory[:, col] * (np.sign(r) if r == r and r != 0 else 1.0) if col >= 0 else None
    return {
        "step": np.arange(len(velocity)),
        "velocity": scale_pm1(velocity),
        "register": scale_pm1(reg) if reg is not None else np.zeros(len(velocity)),
        "r": r,
        "label": f"b{col // m + 1}.m{col % m}" if col >= 0 else "",
        "variable": task_spec(task).velocity_name,
    }
