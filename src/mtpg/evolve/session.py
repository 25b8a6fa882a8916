"""A training run bound to a run directory: one run, one process, exact resume.

Guarantees (see ``docs/runs.md``):

* **One run per directory.** Checkpoints record the run's identity and generation; a
  checkpoint of another run, or one whose content disagrees with its file name, is
  refused before anything is written.
* **One process per directory.** The directory's lock (:mod:`mtpg.io.lock`) is held
  from before the first write to the end; a second process is refused at once.
* **Generations are transactions.** The checkpoint is the commit point (written by
  :class:`mtpg.evolve.reporters.CheckpointReporter`, never from a half-made
  generation). On resume everything after the last checkpoint is rolled back: rows of
  later generations dropped, their test folders and temporary files removed, champions
  rewritten from the checkpoint. The generations are then run again, reproducing the
  uninterrupted run exactly (all but the timing columns), because the checkpoint holds
  the whole state including the generator.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import replace
from pathlib import Path

from mtpg._faults import check_stop_at
from mtpg.config import ConfigError, RunConfig, to_toml
from mtpg.engine.evaluator import BackendLost
from mtpg.evolve.backend import make_evaluator
from mtpg.evolve.persist import (
    RESUMABLE_CHANGES,
    config_differences,
    run_identity,
    state_from_payload,
)
from mtpg.evolve.reporters import (
    TESTS_FILE,
    CallbackReporter,
    CheckpointReporter,
    MetricsReporter,
    TestsReporter,
    champion_graphs,
)
from mtpg.evolve.state import TrainerState
from mtpg.evolve.trainer import Reporter, Trainer, train
from mtpg.io.checkpoint import (
    CheckpointError,
    checkpoint_generation,
    latest_checkpoint,
    load_checkpoint,
)
from mtpg.io.lock import DirLock, lock_dir
from mtpg.io.runconfig import read_run_config
from mtpg.io.rundir import (
    champion_filename,
    check_new_run_dir,
    check_resumable,
    init_run_dir,
    roll_back,
    write_champions,
)
from mtpg.io.serialize import FormatError
from mtpg.limits import check_training_fits

__all__ = ["RESUMABLE_CHANGES", "TESTS_FILE", "Session", "read_run_config"]

Callback = Callable[[dict[str, float], Trainer], None]


def load_state(
    run_dir: str | Path, config: RunConfig, ckpt: Path | None = None
) -> TrainerState | None:
    """Loads the last checkpoint of a run and checks that it belongs to it.

    Writes nothing.

    Args:
        run_dir: The run directory.
        config: The run's configuration (its ``config.toml``, with resumable changes).
        ckpt: The checkpoint file (default: the run's latest).

    Returns:
        The state of the last committed generation, or None when there is none.

    Raises:
        CheckpointError: Naming the file: unreadable, invalid, of another run, or holding
            another generation than its name says.
    """
    ckpt = ckpt or latest_checkpoint(run_dir)
    if ckpt is None:
        return None
    payload = load_checkpoint(ckpt)
    try:
        state, stored = state_from_payload(payload)
    except FormatError as exc:
        raise CheckpointError(f"{ckpt}: not a valid run state: {exc}") from exc
    named = checkpoint_generation(ckpt)
    if state.generation != named:
        raise CheckpointError(
            f"{ckpt}: holds generation {state.generation} but its name says {named}; "
            "refusing it (nothing was changed)"
        )
    if run_identity(stored) != run_identity(config):
        diff = ", ".join(config_differences(stored, config)) or "identity"
        raise CheckpointError(
            f"{ckpt}: belongs to another run (differs from this run's config.toml in {diff}); "
            "refusing it (nothing was changed)"
        )
    state.config = config
    return state


class Session:
    """Runs a :class:`Trainer` inside a run directory.

    Everything is checked before the first write: the directory, the configuration's
    memory and work (:func:`mtpg.limits.check_training_fits`) and, on resume, the last
    checkpoint. Then the directory is locked, created or rolled back to its last
    committed generation. Call :meth:`run_all` (or :meth:`close`) to release it.

    Args:
        run_dir: The run directory.
        config: Configuration of a new run; for a resumed run, None or a configuration
            that differs from the stored one only in :data:`RESUMABLE_CHANGES`.
        resume: Continue the run in ``run_dir`` from its last checkpoint.
        scheduler_wait: Seconds the Dask backend waits for its scheduler (not stored with
            the run); None: ``$MTPG_SCHEDULER_WAIT`` or the default.

    Raises:
        ConfigError, RunDirError, CheckpointError, BudgetError: Bad input; nothing
            was changed.
        LockedError: Another process uses the directory; nothing was changed.
    """

    def __init__(
        self,
        run_dir: str | Path,
        config: RunConfig | None = None,
        resume: bool = False,
        scheduler_wait: float | None = None,
    ) -> None:
        path = Path(run_dir)
        if resume:
            check_resumable(path)
            stored = read_run_config(path)
            if config is not None:
                _check_compatible(stored, config)
                stored = replace(stored, **{k: getattr(config, k) for k in RESUMABLE_CHANGES})
            config = stored
        elif config is None:
            raise ConfigError("a new run needs a configuration")
        else:
            check_new_run_dir(path)
        check_training_fits(config)
        check_stop_at()  # a bad MTPG_TEST_STOP_AT (fault-injection points) is refused here
        ckpt = latest_checkpoint(path) if resume else None
        state = load_state(path, config, ckpt) if ckpt else None
        # an unreachable scheduler stops the run here
        evaluator = make_evaluator(config, scheduler_wait)
        # -- first write --------------------------------------------------------------
        self.lock: DirLock | None = None
        self.metrics: MetricsReporter | None = None
        self.tests: TestsReporter | None = None
        try:
            path.mkdir(parents=True, exist_ok=True)
            self.lock = lock_dir(path, "the run directory")
            if resume and latest_checkpoint(path) != ckpt:  # committed before our lock
                ckpt = latest_checkpoint(path)
                state = load_state(path, config, ckpt) if ckpt else None
            self.lock.claim()
            self.run = init_run_dir(path, to_toml(config), resume=resume)
            self.config = config
            self.trainer = Trainer(config, state, evaluator)
            self._roll_back()
        except BaseException:
            self.close()
            evaluator.close()  # e.g. stops a local Dask cluster started for the run
            raise
        self.checkpoints = CheckpointReporter(
            self.run.path, config.checkpoint_interval, self.trainer.state.generation
        )

    def _roll_back(self) -> None:
        """Makes the directory hold exactly the last committed generation."""
        gen = self.trainer.state.generation
        tasks = self.config.evaluation.tasks
        roll_back(self.run.path, gen)
        self.metrics = MetricsReporter(self.run.metrics, tasks, self.config.evaluation)
        self.metrics.writer.truncate_after(gen)
        self.tests = TestsReporter(self.run.path, tasks)
        self.tests.writer.truncate_after(gen)
        graphs = champion_graphs(self.trainer) if gen > 0 else {}
        write_champions(self.run.path, graphs)
        keep = {champion_filename(names) for names in graphs}
        for entry in self.run.champions.glob("*.json"):
            if entry.name not in keep:
                entry.unlink()

    def run_all(
        self,
        on_generation: Callback | None = None,
        should_stop: Callable[[], bool] | None = None,
        reporters: Sequence[Reporter] = (),
    ) -> bool:
        """Runs the remaining generations, then releases the directory.

        A lost evaluation backend (a Dask cluster whose scheduler went away) stops the run
        the same way, at the boundary after the generation it was lost in: that
        generation is committed, then :class:`~mtpg.engine.evaluator.BackendLost` is
        raised, and ``resume`` continues the run from there.

        Args:
            on_generation: Called with each metrics row and the trainer (e.g. progress).
            should_stop: Asked before each generation; True ends the run there, after
                committing the last completed generation.
            reporters: More observers of each committed generation, after the run's own
                (e.g. :class:`mtpg.evolve.tensorboard.TensorBoardReporter`).

        Returns:
            True when every configured generation has run, False when stopped early.

        Raises:
            BackendLost: The backend was lost; the last generation is committed.
        """
        observers: list[Reporter] = [self.metrics, self.tests, self.checkpoints, *reporters]
        if on_generation is not None:
            observers.append(CallbackReporter(on_generation))
        lost: list[BackendLost] = []

        def stop_here() -> bool:
            if should_stop is not None and should_stop():
                return True
            try:
                self.trainer.evaluator.check()
            except BackendLost as exc:
                lost.append(exc)
                return True
            return False

        try:
            finished = train(self.trainer, observers, stop_here)
        finally:
            self.close()
        if lost:
            raise lost[0]
        return finished

    def checkpoint(self) -> Path:
        """Commits the current generation now (champions, then the checkpoint)."""
        return self.checkpoints.commit(self.trainer)

    @property
    def saved_generation(self) -> int:
        """The last committed generation."""
        return self.checkpoints.saved_generation

    def close(self) -> None:
        """Closes the files and releases the directory's lock."""
        for reporter in (self.metrics, self.tests):
            if reporter is not None:
                reporter.close()
        if self.lock is not None:
            self.lock.release()
            self.lock = None


def _check_compatible(stored: RunConfig, given: RunConfig) -> None:
    diff = config_differences(stored, given)
    if diff:
        raise ConfigError(
            f"cannot resume with a different configuration (differs in {', '.join(diff)}); "
            f"only {', '.join(RESUMABLE_CHANGES)} may change"
        )
