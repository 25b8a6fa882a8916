"""Where new roots are evaluated: this machine's threads or a Dask cluster.

An :class:`Evaluator` plays every episode of a table with every given root of a compiled
population and returns the outcomes in root-major order. Every backend returns the very
same numbers: each job (root x episode) runs on its own with a fresh memory state, so
neither the number of threads nor the number or placement of worker processes changes a
bit of the result. Evaluation is pure (the same arguments always give the same result),
which is what lets a cluster recompute a batch lost with a worker.

Backends:

* ``local`` (:class:`LocalEvaluator`, default): the engine's Numba threads.
* ``dask`` (:class:`mtpg.engine.dask_backend.DaskEvaluator`): batches of roots on the
  worker processes of a Dask cluster, either an existing one (``address``) or a local one
  started for the run (``dask_workers``). Needs the optional ``dask`` extra.

Which backend a run uses is read from its configuration by
:func:`mtpg.evolve.backend.make_evaluator`; the engine knows nothing of configurations.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np

from mtpg.engine.batch import BatchResult, Episodes, evaluate_roots
from mtpg.engine.compile import CompiledPopulation


class BackendLost(RuntimeError):
    """The evaluation backend went away; the run stops at a generation boundary."""


class BackendError(ValueError):
    """A backend cannot be set up as asked (e.g. its scheduler cannot be reached).

    The message is one line and names the setting at fault (``address: ...``).
    """


class Evaluator(Protocol):
    """Plays episodes with roots of a compiled population."""

    def evaluate(
        self,
        cp: CompiledPopulation,
        root_ids: list[int],
        episodes: Episodes,
        no_memory: bool | None = None,
    ) -> tuple[np.ndarray, BatchResult]:
        """Plays every episode of ``episodes`` with every root.

        Args:
            cp: The compiled population.
            root_ids: Model ids of the teams to evaluate.
            episodes: The episode table.
            no_memory: Deprecated: the ablation is ``cp``'s (``no_memory`` of
                :func:`~mtpg.engine.compile.compile_population`); a bool overrides it.

        Returns:
            ``returns`` float64 ``[n_roots, n_episodes]`` and the flat per-job result
            (root-major), exactly as :func:`mtpg.engine.batch.evaluate_roots`.
        """
        ...

    def check(self) -> None:
        """Raises :class:`BackendLost` when the backend was lost since the last call."""
        ...

    def close(self) -> None:
        """Releases the backend's resources (idempotent)."""
        ...


class LocalEvaluator:
    """Evaluates on this machine's Numba threads.

    Args:
        threads: Numba threads (1: the serial kernel, no thread pool).
    """

    def __init__(self, threads: int = 1) -> None:
        if threads < 1:
            raise ValueError(f"threads must be >= 1, got {threads}")
        self.threads = threads

    def evaluate(
        self,
        cp: CompiledPopulation,
        root_ids: list[int],
        episodes: Episodes,
        no_memory: bool | None = None,
    ) -> tuple[np.ndarray, BatchResult]:
        """See :meth:`Evaluator.evaluate`."""
        return evaluate_roots(cp, root_ids, episodes, self.threads, no_memory)

    def check(self) -> None:
        """A local backend is never lost."""

    def close(self) -> None:
        """Nothing to release."""
