"""mtpg: Tangled Program Graphs with temporal memory for multi-task reinforcement learning."""

__version__ = "0.1.0"

import mtpg.envs  # noqa: F401  (registers the Gymnasium ids mtpg/<Task>-v0; numba loads lazily)
