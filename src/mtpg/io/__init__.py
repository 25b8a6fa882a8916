"""Persistence: graph files, run checkpoints and the run-directory layout (no pickle)."""

from mtpg.io.checkpoint import (
    CheckpointError,
    checkpoint_path,
    latest_checkpoint,
    list_checkpoints,
    load_checkpoint,
    prune_checkpoints,
    save_checkpoint,
)
from mtpg.io.serialize import (
    FormatError,
    graph_from_dict,
    graph_to_dict,
    load_graph,
    population_from_dict,
    population_to_dict,
    save_graph,
)

__all__ = [
    "CheckpointError",
    "FormatError",
    "checkpoint_path",
    "graph_from_dict",
    "graph_to_dict",
    "latest_checkpoint",
    "list_checkpoints",
    "load_checkpoint",
    "load_graph",
    "population_from_dict",
    "population_to_dict",
    "prune_checkpoints",
    "save_checkpoint",
    "save_graph",
]
