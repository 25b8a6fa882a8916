"""``mtpg envs --tasks`` / ``--run``: the tasks named, Gymnasium tasks included.

A Gymnasium task's row shows what mtpg reads of it (:mod:`mtpg.envs.specs.gym_task`): the
flattened observation's size and how each input is scaled (linearly from finite bounds
to [-1, 1], through ``tanh`` where a bound is infinite), the action mapping, the time
limit and the random-play score mtpg measures (100 episodes from seed 2,000,000); its
best is the one ``evaluation.references`` gives, else none (scores are raw).
"""

from __future__ import annotations

import argparse
from pathlib import Path

HEADER = ("id", "task", "observed", "action", "limit", "random", "best", "solved", "source")


def _num(value: float) -> str:
    return "-" if value != value else f"{value:.4g}"


def _bounds(lo: float, hi: float) -> str:
    return f"[{lo:.4g}, {hi:.4g}]"


def observation_text(task) -> str:
    """A Gymnasium task's inputs: how many, and how many are scaled or squashed."""
    finite = sum(1 for lo, hi in zip(task.obs_low, task.obs_high, strict=True) if _finite(lo, hi))
    return f"{task.n_obs} inputs: {finite} linear, {task.n_obs - finite} tanh"


def _finite(lo: float, hi: float) -> bool:
    return bool(abs(lo) != float("inf") and abs(hi) != float("inf"))


def scaling_lines(task) -> list[str]:
    """One line per input: ``s[i]`` from its bounds, linearly or through ``tanh``."""
    lines = []
    for i, (lo, hi) in enumerate(zip(task.obs_low, task.obs_high, strict=True)):
        how = "linear to [-1, 1]" if _finite(lo, hi) else "tanh (a bound is infinite)"
        lines.append(f"    s[{i}] {_bounds(lo, hi)}: {how}")
    return lines


def action_text(task) -> str:
    """A Gymnasium task's action mapping, as ``mtpg envs`` prints it."""
    parts = []
    if task.n_actions:
        first = task.action_start
        parts.append(f"Discrete({task.n_actions}): {first} + a_d mod {task.n_actions}")
    if task.continuous:
        box = ", ".join(
            _bounds(lo, hi) if _finite(lo, hi) else "m as it is"
            for lo, hi in zip(task.cont_low, task.cont_high, strict=True)
        )
        parts.append(f"Box({task.n_continuous}): m[0..{task.n_continuous}) clipped onto {box}")
    return "; ".join(parts)


def list_tasks(args: argparse.Namespace) -> int:
    """Prints the tasks of ``--tasks`` or of the run ``--run``.

    Raises:
        UsageError: For both options at once, or an empty list.
        ValueError: One line, for an unknown task or an environment that does not make.
    """
    from mtpg.cli.common import target_task_table, task_list
    from mtpg.cli.main import UsageError
    from mtpg.envs.specs.gym_task import GymTask
    from mtpg.envs.specs.param_table import P_MAX_STEPS
    from mtpg.envs.taskset.reference_scores import reference_of
    from mtpg.envs.taskset.task_table import TaskTable

    if args.tasks is not None and args.run is not None:
        raise UsageError("give --tasks or --run, not both")
    if args.measure:
        raise UsageError("--measure re-measures the six tasks; give it without --tasks or --run")
    if args.run is not None:
        from mtpg.io.runconfig import read_run_config

        run = Path(args.run)
        if not run.is_dir():
            raise FileNotFoundError(f"{run}: no such run directory")
        table = target_task_table(run, list(read_run_config(run).evaluation.tasks))
    else:
        table = TaskTable.from_names(task_list(args.tasks))
    rows, details = [], []
    for name, task_id in zip(table.names, table.ids, strict=True):
        spec, ref = table.spec(task_id), reference_of(task_id, table)
        if isinstance(spec, GymTask):
            observed, action, limit = observation_text(spec), action_text(spec), spec.max_steps
            details += [f"{name}: observation", *scaling_lines(spec)]
            random = f"{_num(ref.random)} (sd {_num(ref.random_std)})"
        else:
            observed, action = spec.observed, spec.action_text
            limit = int(table.params[task_id, P_MAX_STEPS])
            random = _num(ref.random)
        rows.append(
            (
                str(task_id),
                name,
                observed,
                action,
                str(limit),
                random,
                _num(ref.best),
                _num(ref.solved),
                ref.source,
            )
        )
    widths = [max(len(r[i]) for r in (HEADER, *rows)) for i in range(len(HEADER))]
    for row in (HEADER, *rows):
        print("  ".join(cell.ljust(w) for cell, w in zip(row, widths, strict=True)).rstrip())
    for line in details:
        print(line)
    if table.gym:
        print(
            "random: mean (sd) of 100 episodes of actions sampled from the action space, "
            "seeds 2,000,000..2,000,099; ids are this listing's"
        )
    return 0
