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
from mtpg.io.rundir import (
    MetricsWriter,
    RunDir,
    RunDirError,
    champion_filename,
    init_run_dir,
    is_run_dir,
    read_champions,
    write_champions,
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
    "MetricsWriter",
    "RunDir",
    "RunDirError",
    "champion_filename",
    "checkpoint_path",
    "graph_from_dict",
    "graph_to_dict",
    "init_run_dir",
    "is_run_dir",
    "latest_checkpoint",
    "list_checkpoints",
    "load_checkpoint",
    "load_graph",
    "population_from_dict",
    "population_to_dict",
    "prune_checkpoints",
    "read_champions",
    "save_checkpoint",
    "save_graph",
    "write_champions",
]
