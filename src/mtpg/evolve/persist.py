"""Conversion of the run state to and from a JSON-native checkpoint payload.

A payload records the identity of its run (:func:`run_identity`: a digest of the
resolved configuration without the settings a resume may change) and its generation, so
that a checkpoint copied from another run, or renamed, is refused instead of silently
continuing a different run.
"""

from __future__ import annotations

import hashlib
import json
from typing import Any

import numpy as np

from mtpg.config import EXTENSIONS, ConfigError, RunConfig, from_dict, to_dict
from mtpg.evolve.state import TrainerState
from mtpg.io.serialize import FormatError, population_from_dict, population_to_dict

#: Settings a resumed run may change: they do not alter what the run computes.
RESUMABLE_CHANGES = (
    "generations",
    "workers",
    "checkpoint_interval",
    "backend",
    "address",
    "dask_workers",
)


def _computing_fields(config: RunConfig) -> dict[str, Any]:
    """The resolved configuration without :data:`RESUMABLE_CHANGES`."""
    data = to_dict(config)
    for key in RESUMABLE_CHANGES:
        data.pop(key)
    return data


def identity_fields(config: RunConfig) -> dict[str, Any]:
    """The resolved configuration without :data:`RESUMABLE_CHANGES`.

    The settings beyond the paper (:data:`mtpg.config.EXTENSIONS`) are left out while they
    hold their default (off) value, so a run made before they existed keeps its identity;
    a field that is absent stands for its default, so two different configurations never
    share their identity fields.
    """
    data = _computing_fields(config)
    defaults = to_dict(RunConfig())
    for section, names in EXTENSIONS.items():
        for name in names:
            if data[section][name] == defaults[section][name]:
                del data[section][name]
    return data


def run_identity(config: RunConfig) -> str:
    """A run's identity: the first 16 hex digits of the SHA-256 of :func:`identity_fields`.

    Seed, tasks and every setting that changes what the run computes enter it; two runs
    with the same identity compute the same generations.
    """
    text = json.dumps(identity_fields(config), sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def config_differences(a: RunConfig, b: RunConfig) -> list[str]:
    """Dotted names of the identity fields in which two configurations differ."""
    out = []
    da, db = _computing_fields(a), _computing_fields(b)
    for key in da:
        if isinstance(da[key], dict):
            out += [f"{key}.{k}" for k in da[key] if da[key][k] != db[key][k]]
        elif da[key] != db[key]:
            out.append(key)
    return out


def state_to_payload(state: TrainerState) -> dict[str, Any]:
    """Everything needed to continue the run, as JSON-native values.

    Float scores survive JSON exactly (shortest repr round trip), and the generator
    state is PCG64's own dict, so a resumed run repeats the uninterrupted one.
    """
    return {
        "run": run_identity(state.config),
        "config": to_dict(state.config),
        "generation": state.generation,
        "population": population_to_dict(state.population),
        "scores": [[int(root), [float(x) for x in row]] for root, row in state.scores.items()],
        "elites": [[int(r) for r in e] for e in state.elites],
        "champions": [int(r) for r in state.champions],
        "rng": state.rng.bit_generator.state,
    } | _validation_payload(state)


def _validation_payload(state: TrainerState) -> dict[str, Any]:
    """Validation scores, per-episode returns and block counts, each only when its option is on.

    With every option off (the paper) the payload has none of these keys, as before they
    existed.
    """
    out: dict[str, Any] = {}
    if state.config.evaluation.validation_episodes > 0:
        rows = sorted(state.validation.items())
        out["validation"] = [[int(root), [float(x) for x in row]] for root, row in rows]
    if state.config.team.parent_selection == "lexicase":
        out["returns"] = [
            [int(root), [[float(x) for x in task] for task in table]]
            for root, table in sorted(state.returns.items())
        ]
    if state.config.evaluation.resample_mean:
        out["blocks"] = [
            [int(root), int(n), [float(x) for x in total]]
            for root, (n, total) in sorted(state.blocks.items())
        ]
    return out


def state_from_payload(payload: dict[str, Any]) -> tuple[TrainerState, RunConfig]:
    """Rebuilds the state saved by :func:`state_to_payload`.

    Returns:
        The state and the configuration stored with it.

    Raises:
        FormatError: When a part is missing, malformed or inconsistent.
    """
    try:
        config = from_dict(payload["config"])
        rng = np.random.Generator(np.random.PCG64())
        rng.bit_generator.state = payload["rng"]
        state = TrainerState(
            config=config,
            generation=int(payload["generation"]),
            population=population_from_dict(payload["population"]),
            scores={int(r): np.array(row, dtype=np.float64) for r, row in payload["scores"]},
            elites=[[int(r) for r in e] for e in payload["elites"]],
            champions=[int(r) for r in payload["champions"]],
            rng=rng,
            validation={
                int(r): np.array(row, dtype=np.float64) for r, row in payload.get("validation", [])
            },
            returns={
                int(r): np.array(table, dtype=np.float64) for r, table in payload.get("returns", [])
            },
            blocks={
                int(r): (int(n), np.array(total, dtype=np.float64))
                for r, n, total in payload.get("blocks", [])
            },
        )
    except (KeyError, TypeError, ValueError, OverflowError) as exc:
        if isinstance(exc, FormatError):
            raise
        if isinstance(exc, ConfigError):
            raise FormatError(f"run state: config: {exc}") from exc
        raise FormatError(f"run state: {type(exc).__name__}: {exc}") from exc
    _check_consistent(state, payload)
    return state, config


def _check_consistent(state: TrainerState, payload: dict[str, Any]) -> None:
    cfg, pop = state.config, state.population
    run = payload.get("run")
    if run is not None and run != run_identity(cfg):
        raise FormatError("run state: its run identity does not match its configuration")
    if state.generation < 0:
        raise FormatError(f"run state: generation must be >= 0, got {state.generation}")
    layout = pop.layout
    n_obs, n_actions, _ = cfg.evaluation.task_table().shape
    want = (cfg.program.n_registers, cfg.program.n_memory, n_obs, n_actions)
    have = (layout.n_registers, layout.n_memory, layout.n_obs, layout.n_actions)
    if state.generation > 0 and have != want:
        raise FormatError(
            f"run state: population layout {layout} does not match the configuration {want}"
        )
    missing = [r for r in state.scores if r not in pop.teams]
    if missing:
        raise FormatError(f"run state: scored roots {missing[:3]} are not in the population")
    n_tasks = len(cfg.evaluation.tasks)
    bad = [r for r, row in state.scores.items() if row.shape != (n_tasks,)]
    if bad:
        raise FormatError(f"run state: root {bad[0]} has scores for the wrong number of tasks")
    unscored = [r for r in state.validation if r not in state.scores]
    if unscored:
        raise FormatError(f"run state: validated root {unscored[0]} is not a scored root")
    bad = [r for r, row in state.validation.items() if row.shape != (n_tasks,)]
    if bad:
        raise FormatError(f"run state: root {bad[0]} has validation scores for the wrong tasks")
    shape = (n_tasks, cfg.evaluation.train_episodes)
    bad = [r for r, table in state.returns.items() if table.shape != shape or r not in pop.teams]
    if bad:
        raise FormatError(f"run state: root {bad[0]} has returns of the wrong shape or no team")
    if cfg.evaluation.resample_mean and (
        set(state.blocks) != set(state.scores)
        or any(n < 1 or t.shape != (n_tasks,) for n, t in state.blocks.values())
    ):
        raise FormatError("run state: block counts and sums must be given for every scored root")
    if state.generation > 0:
        subsets = cfg.evaluation.n_subsets
        if len(state.champions) != subsets:
            raise FormatError(f"run state: needs the champions of {subsets} task subsets")
        unscored = [r for r in state.champions if r not in state.scores]
        if unscored:
            raise FormatError(f"run state: champion {unscored[0]} has no score")
