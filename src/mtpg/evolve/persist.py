"""Conversion of the run state to and from a JSON-native checkpoint payload."""

from __future__ import annotations

from typing import Any

import numpy as np

from mtpg.config import RunConfig, from_dict, to_dict
from mtpg.evolve.trainer import TrainerState
from mtpg.io.serialize import FormatError, population_from_dict, population_to_dict


def state_to_payload(state: TrainerState) -> dict[str, Any]:
    """Everything needed to continue the run, as JSON-native values.

    Float scores survive JSON exactly (shortest repr round trip), and the generator
    state is PCG64's own dict, so a resumed run repeats the uninterrupted one.
    """
    return {
        "config": to_dict(state.config),
        "generation": state.generation,
        "population": population_to_dict(state.population),
        "scores": [[int(root), [float(x) for x in row]] for root, row in state.scores.items()],
        "elites": [[int(r) for r in e] for e in state.elites],
        "champions": [int(r) for r in state.champions],
        "rng": state.rng.bit_generator.state,
    }


def state_from_payload(payload: dict[str, Any]) -> tuple[TrainerState, RunConfig]:
    """Rebuilds the state saved by :func:`state_to_payload`.

    Returns:
        The state and the configuration stored with it.

    Raises:
        FormatError: When a part is missing or malformed.
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
        )
    except (KeyError, TypeError, ValueError) as exc:
        if isinstance(exc, FormatError):
            raise
        raise FormatError(f"run state: {type(exc).__name__}: {exc}") from exc
    missing = [r for r in state.scores if r not in state.population.teams]
    if missing:
        raise FormatError(f"run state: scored roots {missing[:3]} are not in the population")
    return state, config
