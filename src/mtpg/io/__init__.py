"""Persistence: graph files, run checkpoints and the run-directory layout (no pickle)."""

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
    "FormatError",
    "graph_from_dict",
    "graph_to_dict",
    "load_graph",
    "population_from_dict",
    "population_to_dict",
    "save_graph",
]
