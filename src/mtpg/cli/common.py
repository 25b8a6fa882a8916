"""Helpers the command modules share: option lists, presets, overrides, graph targets.

Only light modules are imported at the top, so that ``mtpg --help`` stays fast; each
helper imports what it needs when called.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from mtpg.ablations import ABLATION_TABLE
from mtpg.presets import PRESETS


def preset_help() -> str:
    """The help of ``--preset``: every preset by name, as :data:`mtpg.presets.PRESETS` has them."""
    names = list(PRESETS)
    listed = ", ".join(names[:-1]) + " or " + names[-1]
    return (
        f"configuration preset: {listed} (robust = paper with the training episodes redrawn "
        "every 10 generations; default: demo)"
    )


def task_list(text: str, option: str = "--tasks") -> list[str]:
    """The canonical names of a comma-separated list option, refusing an empty one.

    Commas inside a variant's brackets do not split (``CartPole[max_steps=500],Pendulum``);
    each name is checked and spelled canonically (``mtpg.envs.taskset.variants.canonical``).
    """
    from mtpg.cli.main import UsageError
    from mtpg.envs.specs.contract import TASK_NAMES
    from mtpg.envs.taskset.variants import canonical, is_variant

    parts, depth, word = [], 0, ""
    for ch in text:
        depth += {"[": 1, "]": -1}.get(ch, 0)
        if ch == "," and depth <= 0:
            parts.append(word)
            word = ""
        else:
            word += ch
    names = [t.strip() for t in [*parts, word] if t.strip()]
    if not names:
        raise UsageError(f"{option}: empty list; name at least one of {', '.join(TASK_NAMES)}")
    try:  # a plain unknown name is left to the configuration's check, which names the field
        return [canonical(t) if is_variant(t) else t for t in names]
    except ValueError as exc:
        raise UsageError(f"{option}: {exc}") from None


def overrides(args: argparse.Namespace) -> list[str]:
    """The ``section.field=value`` overrides the options stand for."""
    out = list(args.set)
    if args.tasks is not None:
        names = task_list(args.tasks)
        out.append("evaluation.tasks=[" + ", ".join(f'"{t}"' for t in names) + "]")
    for key in ("generations", "seed", "workers", "dask_workers"):
        if getattr(args, key) is not None:
            out.append(f"{key}={getattr(args, key)}")
    for key in ("backend", "address"):
        if getattr(args, key) is not None:
            out.append(f'{key}="{getattr(args, key)}"')
    out += [abl.override for abl in ABLATION_TABLE if getattr(args, abl.dest)]
    return out


def resolve_graph(target: Path):
    """Loads the graph a path names: a graph file, or a run's reported champion.

    For a run directory this is the champion the report shows
    (:func:`mtpg.analysis.runs.champions.run_champion`).

    Returns:
        ``(population, root, meta, default task names)``.
    """
    from mtpg.io.serialize import load_graph

    if not target.exists():
        raise FileNotFoundError(f"{target}: no such graph file or run directory")
    if target.is_dir():
        from mtpg.analysis.runs.champions import run_champion
        from mtpg.io.runconfig import read_run_config

        config = read_run_config(target)
        pop, root, meta = load_graph(run_champion(target))
        meta.setdefault("no_memory", config.evaluation.no_memory)  # the run's ablation
        meta.setdefault("test_episodes", config.evaluation.test_episodes)
        return pop, root, meta, list(config.evaluation.tasks)
    pop, root, meta = load_graph(target)
    from mtpg.envs.specs.registry import PAPER_TASKS

    return pop, root, meta, list(meta.get("tasks", PAPER_TASKS))


def target_task_table(target: Path, tasks: list[str]):
    """The task table of ``tasks`` for a graph target (:func:`resolve_graph`).

    A run directory's given reference scores (``evaluation.references``) come with the
    tasks they name; a graph file's tasks have none.

    Returns:
        A :class:`mtpg.envs.taskset.task_table.TaskTable`.
    """
    from mtpg.envs.taskset.task_table import TaskTable, parse_given

    references: list[str] = []
    if target.is_dir():
        from mtpg.io.runconfig import read_run_config

        given = read_run_config(target).evaluation.references
        references = [r for r in given if parse_given(r).task in tasks]
    return TaskTable.from_names(tasks, references)
