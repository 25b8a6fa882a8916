"""Hard limits on sizes, and the memory and work a configuration needs, known in advance.

A configuration is checked twice before anything is allocated or written:

* every size has a hard limit (:data:`LIMITS`): values far beyond any sensible run
  (a billion roots, a billion episodes) are refused by the configuration itself;
* :func:`check_training_fits` estimates the peak memory and the worst-case work of one
  generation and refuses a run that cannot fit the machine (memory estimate above the
  memory available now) or would take absurdly long (:data:`MAX_DECISIONS_PER_GENERATION`).

The memory estimate is deliberately a lower bound of the start of a run (initial
population, evaluation and test buffers, one checkpoint being written, the interpreter
with its libraries): programs and teams grow during a run, which no configuration
determines. It exists to refuse at once what would otherwise hang while memory fills.
"""

from __future__ import annotations

import os
from typing import Any

#: Hard upper limits of configuration fields (``section.field``) and CLI options.
LIMITS: dict[str, int] = {
    "seed": 2**63 - 1,
    "generations": 100_000_000,
    "workers": 1024,
    "checkpoint_interval": 100_000_000,
    "program.n_registers": 256,
    "program.n_memory": 256,
    "program.init_max_length": 100_000,
    "program.max_length": 100_000,
    "team.root_size": 1_000_000,
    "team.init_team_size": 100_000,
    "team.n_elite": 100_000,
    "team.min_elite_total": 1_000_000,
    "team.max_team_size": 100_000,
    "evaluation.train_episodes": 100_000,
    "evaluation.test_episodes": 1_000_000,
    "evaluation.test_interval": 100_000_000,
    "evaluation.validation_episodes": 100_000,
    "evaluation.validation_top_k": 100_000,
    "evaluation.resample_interval": 100_000_000,
    "episodes": 1_000_000,
}

#: Worst-case decisions of one generation above which a run is refused (at the
#: engine's ~5 million decisions per second this is more than five hours per generation).
MAX_DECISIONS_PER_GENERATION = 10**11

#: Memory of the interpreter with numpy, numba and the compiled kernels (bytes).
BASE_BYTES = 200 * 2**20
#: Python objects of one program besides its instructions (the object, its array
#: headers, dict slots, the compiled copy's share).
PROGRAM_BYTES = 700
#: Bytes per instruction: the int32 row, its compiled copy and the effective cache.
INSTRUCTION_BYTES = 48
#: Bytes per instruction while a checkpoint is written (JSON text, Python int lists).
CHECKPOINT_INSTRUCTION_BYTES = 220
#: Python objects of one team besides its member list.
TEAM_BYTES = 400
#: Per-job outcome arrays of a batch evaluation (returns, steps, teams, instructions)
#: plus the job index arrays.
JOB_BYTES = 6 * 8
#: Per-episode bytes of an episode table besides its noise row.
EPISODE_BYTES = 8 * 8


class BudgetError(ValueError):
    """A configuration cannot run on this machine; the message gives the estimate."""


def available_memory() -> int | None:
    """Memory available to a new allocation now, in bytes (None when unknown).

    Reads ``MemAvailable`` from ``/proc/meminfo``, else the free physical pages.
    """
    try:
        with open("/proc/meminfo", encoding="ascii") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, AttributeError):
        return None


def gib(n: float) -> str:
    """A byte count for people: ``"1.5 GB"``, ``"320 MB"``."""
    return f"{n / 2**30:.1f} GB" if n >= 2**30 else f"{n / 2**20:.0f} MB"


def episode_table_bytes(n_episodes: int, max_steps: int) -> int:
    """Bytes of an episode table of ``n_episodes`` rows (start state plus noise row)."""
    return n_episodes * (EPISODE_BYTES + 8 * (max_steps + 1))


def evaluation_bytes(roots: int, n_episodes: int, max_steps: int) -> int:
    """Bytes of one batch evaluation of ``roots`` roots on ``n_episodes`` episodes."""
    return roots * n_episodes * JOB_BYTES + episode_table_bytes(n_episodes, max_steps)


def training_estimate(config: Any) -> dict[str, float]:
    """Estimated peak memory (bytes, by part) and worst-case decisions of one generation.

    Args:
        config: A :class:`mtpg.config.RunConfig`.

    Returns:
        ``population``, ``evaluation``, ``test`` (or validation, the larger),
        ``checkpoint``, ``base`` and ``total`` bytes, and ``decisions`` (upper bound of one
        generation, validation and re-evaluation of survivors included).
    """
    ev, team, prog = config.evaluation, config.team, config.program
    steps = [spec.max_steps for spec in ev.task_table().specs]
    subsets = ev.n_subsets
    children = config.elites_per_subset * subsets
    roots = max(team.root_size, 2 * children)  # kept elites plus new children
    programs = team.root_size * team.init_team_size + children * 2
    mean_length = (prog.init_max_length + 1) / 2
    instructions = programs * mean_length
    population = programs * PROGRAM_BYTES + instructions * INSTRUCTION_BYTES + roots * TEAM_BYTES
    new_roots = max(team.root_size, children)
    train_eps = ev.train_episodes * len(steps)
    evaluation = evaluation_bytes(new_roots, train_eps, max(steps))
    test = evaluation_bytes(subsets, ev.test_episodes * len(steps), max(steps))
    candidates = min(subsets * ev.validation_top_k, roots) if ev.validation_episodes else 0
    validation = evaluation_bytes(candidates, ev.validation_episodes * len(steps), max(steps))
    test = max(test, validation)  # validation happens between evaluation and test
    checkpoint = instructions * CHECKPOINT_INSTRUCTION_BYTES
    total = BASE_BYTES + population + max(evaluation, test, checkpoint)
    evaluated = roots if ev.resample_interval else new_roots  # resampling: every root again
    decisions = float(evaluated) * ev.train_episodes * sum(steps)
    decisions += float(candidates) * ev.validation_episodes * sum(steps)
    return {
        "population": float(population),
        "evaluation": float(evaluation),
        "test": float(test),
        "checkpoint": float(checkpoint),
        "base": float(BASE_BYTES),
        "total": float(total),
        "decisions": decisions,
    }


def check_training_fits(config: Any, available: int | None = None) -> dict[str, float]:
    """Refuses a configuration whose estimated memory or work cannot fit the machine.

    Args:
        config: A :class:`mtpg.config.RunConfig`.
        available: Bytes of memory to compare with (default: :func:`available_memory`).

    Returns:
        The estimate (see :func:`training_estimate`).

    Raises:
        BudgetError: With the estimate, its largest part and what is available.
    """
    check_continuous_fits(config)
    est = training_estimate(config)
    if est["decisions"] > MAX_DECISIONS_PER_GENERATION:
        raise BudgetError(
            f"configuration: one generation may take up to {est['decisions']:.3g} decisions "
            f"(limit {MAX_DECISIONS_PER_GENERATION:.0e}); reduce team.root_size, team.n_elite "
            "or evaluation.train_episodes"
        )
    available = available_memory() if available is None else available
    if available is not None and est["total"] > available:
        parts = ("population", "evaluation", "test", "checkpoint")
        largest = max(parts, key=lambda k: est[k])
        raise BudgetError(
            f"configuration: needs an estimated {gib(est['total'])} of memory at the start "
            f"(largest part: {largest} {gib(est[largest])}), more than the "
            f"{gib(available)} available; reduce {_CULPRITS[largest]}"
        )
    return est


def check_continuous_fits(config: Any) -> None:
    """Refuses tasks with more continuous outputs than a memory bank has registers.

    Continuous dimension ``j`` is ``m[j]`` of the deciding program's bank, so a run's
    tasks may take at most ``program.n_memory`` of them.

    Raises:
        BudgetError: Naming the task and both sizes.
    """
    table = config.evaluation.task_table()
    n_memory = config.program.n_memory
    for spec in table.specs:
        n = getattr(spec, "n_continuous", 1)
        if n > n_memory:
            raise BudgetError(
                f"evaluation.tasks: {spec.name} takes {n} continuous outputs (m[0..{n})), "
                f"more than the {n_memory} registers of a memory bank; raise program.n_memory"
            )


def check_evaluation_fits(n_episodes: int, max_steps: int, available: int | None = None) -> None:
    """Refuses an evaluation of one graph on ``n_episodes`` episodes that cannot fit.

    Raises:
        BudgetError: With the estimate and what is available.
    """
    need = BASE_BYTES + evaluation_bytes(1, n_episodes, max_steps)
    available = available_memory() if available is None else available
    if available is not None and need > available:
        raise BudgetError(
            f"--episodes: {n_episodes} episodes need an estimated {gib(need)} of memory, "
            f"more than the {gib(available)} available"
        )


_CULPRITS = {
    "population": "team.root_size, team.init_team_size or program.init_max_length",
    "evaluation": "team.root_size, team.n_elite or evaluation.train_episodes",
    "test": "evaluation.test_episodes or the number of tasks",
    "checkpoint": "team.root_size, team.init_team_size or program.init_max_length",
}
