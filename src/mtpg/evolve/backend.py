"""The evaluation backend a run configuration asks for.

The engine's backends (:mod:`mtpg.engine.evaluator`, :mod:`mtpg.engine.dask_backend`)
know nothing of run configurations; this module reads ``backend``, ``address``,
``dask_workers`` and ``workers`` and builds one. A training session builds it before it
writes anything (:class:`mtpg.evolve.session.Session`), so a scheduler that cannot be
reached leaves no run directory behind.
"""

from __future__ import annotations

from mtpg.config import ConfigError, RunConfig
from mtpg.engine.evaluator import BackendError, Evaluator, LocalEvaluator


def make_evaluator(config: RunConfig, scheduler_wait: float | None = None) -> Evaluator:
    """The evaluator a run configuration asks for.

    Args:
        config: The run configuration (``backend``, ``address``, ``dask_workers``,
            ``workers``).
        scheduler_wait: Seconds a Dask evaluator waits for its scheduler (``mtpg train
            --scheduler-wait``; not part of the run); None: ``$MTPG_SCHEDULER_WAIT`` or the
            default (:func:`mtpg.engine.dask_backend.scheduler_wait`).

    Returns:
        A :class:`~mtpg.engine.evaluator.LocalEvaluator` or a connected
        :class:`~mtpg.engine.dask_backend.DaskEvaluator`.

    Raises:
        ConfigError: One line: the dask backend is asked for without an address or
            workers (or with both), its packages are not installed, its scheduler cannot
            be reached or its workers cannot import mtpg.
    """
    if config.backend == "local":
        return LocalEvaluator(config.workers)
    if bool(config.address) == (config.dask_workers > 0):
        raise ConfigError(
            "backend 'dask' needs either address (a running cluster's scheduler, "
            f"tcp://HOST:PORT) or dask_workers >= 1 (a local cluster), got address "
            f"{config.address!r} and dask_workers {config.dask_workers}"
        )
    try:
        import distributed  # noqa: F401
    except ImportError as exc:
        raise ConfigError(
            "backend 'dask' needs the packages dask and distributed, which are not "
            "installed; install them with: pip install 'mtpg[dask]'"
        ) from exc
    from mtpg.engine.dask_backend import DaskEvaluator

    try:
        return DaskEvaluator(
            address=config.address or None,
            n_workers=config.dask_workers,
            fallback_threads=config.workers,
            timeout=scheduler_wait,
        )
    except BackendError as exc:
        raise ConfigError(str(exc)) from exc
