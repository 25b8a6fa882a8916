"""mtpg: Tangled Program Graphs with temporal memory for multi-task reinforcement learning."""

__version__ = "0.1.0"

from mtpg._kernel_cache import refresh as _refresh_kernel_cache

_refresh_kernel_cache()  # before any kernel loads: a cache older than the sources goes

import mtpg.envs  # noqa: E402, F401  (registers the Gymnasium ids mtpg/<Task>-v0; numba loads lazily)
