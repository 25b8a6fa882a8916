"""mtpg: Tangled Program Graphs with temporal memory for multi-task reinforcement learning."""

__version__ = "0.1.0"

# Importing changes no file: the kernel cache is checked by the programs that run kernels
# (mtpg._kernel_cache.refresh, called by the command line before every command).
import mtpg.envs  # noqa: F401  (registers the Gymnasium ids mtpg/<Task>-v0; numba loads lazily)
