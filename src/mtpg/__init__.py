"""mtpg: Tangled Program Graphs with temporal memory for multi-task reinforcement learning.

The public API is this package's top level (``import mtpg``; docs/api.md)::

    config = mtpg.preset("demo", tasks=["CartPole", "MountainCar"], generations=10)
    run = mtpg.train(config, out="runs/api-demo")
    print(mtpg.evaluate(run))

Each name is imported on first use, so ``import mtpg`` stays light; everything else stays
importable from its module (``mtpg.config``, ``mtpg.evolve.session``, ...).
"""

from __future__ import annotations

from typing import Any

__version__ = "0.1.0"

# Importing changes no file: the kernel cache is checked by the programs that run kernels
# (mtpg._kernel_cache.refresh, called by the command line before every command and by the
# functions below before they run kernels).
import mtpg.envs  # noqa: F401  (registers the Gymnasium ids mtpg/<Task>-v0; numba loads lazily)

#: Public name -> the module defining it (imported when the name is first used).
_PUBLIC = {
    "Champion": "mtpg.api",
    "CompiledTask": "mtpg.envs.specs.compiled_task",
    "Config": "mtpg.config",
    "ConfigError": "mtpg.config",
    "Evaluation": "mtpg.api_evaluation",
    "Policy": "mtpg.policy",
    "Run": "mtpg.api",
    "evaluate": "mtpg.api",
    "load": "mtpg.api",
    "preset": "mtpg.api_config",
    "resume": "mtpg.api",
    "train": "mtpg.api",
}
#: Names that differ from the defining module's.
_RENAMED = {"Config": "RunConfig"}

__all__ = sorted(_PUBLIC)


def __getattr__(name: str) -> Any:
    """The public names, imported on first use (``import mtpg`` stays light)."""
    if name not in _PUBLIC:
        raise AttributeError(f"module 'mtpg' has no attribute {name!r}")
    import importlib

    value = getattr(importlib.import_module(_PUBLIC[name]), _RENAMED.get(name, name))
    globals()[name] = value  # later look-ups skip this function
    return value


def __dir__() -> list[str]:
    return sorted([*globals(), *_PUBLIC])
