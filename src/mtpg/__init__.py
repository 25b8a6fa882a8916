"""mtpg: Tangled Program Graphs with temporal memory for multi-task reinforcement learning."""

__version__ = "0.1.0"

# Importing changes no file: the kernel cache is checked by the programs that run kernels
# (mtpg._kernel_cache.refresh, called by the command line before every command).
import mtpg.envs  # noqa: F401  (registers the Gymnasium ids mtpg/<Task>-v0; numba loads lazily)

__all__ = ["Policy"]


def __getattr__(name: str):
    """The public names, imported on first use (``import mtpg`` stays light)."""
    if name == "Policy":
        from mtpg.policy import Policy

        return Policy
    raise AttributeError(f"module 'mtpg' has no attribute {name!r}")
