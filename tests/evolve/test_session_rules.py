"""A run bound to its directory: the order of checks, the lock, roll back on resume.

Hand-made situations for each rule of :class:`mtpg.evolve.session.Session` (see
``docs/runs.md``): a refused resume never takes the lock, a checkpoint committed while
waiting for the lock is the one resumed from, champion files are rewritten from the
checkpoint (none before the first), and a run that fails after taking the lock releases
it.
"""

from __future__ import annotations

import shutil

import pytest

from mtpg.config import ConfigError, build_config
from mtpg.evolve import session as session_module
from mtpg.evolve.session import Session
from mtpg.io.checkpoint import CheckpointError, checkpoint_path, list_checkpoints
from mtpg.io.lock import LockedError, lock_dir
from mtpg.io.serialize import load_graph

CHAMPIONS = ["CartPole+MountainCar.json", "CartPole.json", "MountainCar.json"]


def tiny(*extra: str):
    return build_config(
        "paper",
        overrides=[
            "team.root_size=8",
            "team.n_elite=2",
            "team.init_team_size=2",
            "evaluation.train_episodes=1",
            "evaluation.test_episodes=1",
            "evaluation.test_interval=0",
            'evaluation.tasks=["CartPole", "MountainCar"]',
            "checkpoint_interval=1",
            "generations=2",
            *extra,
        ],
    )


@pytest.fixture(scope="module")
def two_generations(tmp_path_factory):
    """A finished two-generation run with checkpoints of generations 1 and 2."""
    run = tmp_path_factory.mktemp("session") / "run"
    Session(run, tiny()).run_all()
    assert [g for g, _ in list_checkpoints(run)] == [1, 2]
    return run


def copy_run(src, tmp_path):
    run = tmp_path / "run"
    shutil.copytree(src, run)
    return run


def champion_generations(run) -> dict[str, int]:
    return {p.name: load_graph(p)[2]["generation"] for p in (run / "champions").glob("*.json")}


def test_a_new_run_creates_missing_parent_directories(tmp_path) -> None:
    run = tmp_path / "a" / "b" / "run"
    Session(run, tiny("generations=1")).run_all()
    assert [g for g, _ in list_checkpoints(run)] == [1]


def test_a_refused_resume_never_takes_the_lock(two_generations, tmp_path, monkeypatch) -> None:
    run = copy_run(two_generations, tmp_path)
    shutil.copy(checkpoint_path(run, 1), checkpoint_path(run, 3))  # named 3, holds 1

    def no_lock(*args, **kwargs):
        raise AssertionError("the lock was taken before the checkpoint was checked")

    monkeypatch.setattr(session_module, "lock_dir", no_lock)
    with pytest.raises(CheckpointError, match="holds generation 1 but its name says 3"):
        Session(run, resume=True)


def test_a_checkpoint_committed_while_taking_the_lock_is_used(
    two_generations, tmp_path, monkeypatch
) -> None:
    run = copy_run(two_generations, tmp_path)
    newest = checkpoint_path(run, 2)
    aside = tmp_path / "aside.json.gz"
    shutil.move(newest, aside)
    real = session_module.lock_dir

    def commit_then_lock(*args, **kwargs):
        shutil.move(aside, newest)  # the other process commits generation 2, then exits
        return real(*args, **kwargs)

    monkeypatch.setattr(session_module, "lock_dir", commit_then_lock)
    session = Session(run, tiny("generations=3"), resume=True)
    assert session.trainer.state.generation == 2 and session.saved_generation == 2
    session.close()


def test_resume_rewrites_the_champions_of_the_checkpoint(two_generations, tmp_path) -> None:
    run = copy_run(two_generations, tmp_path)
    assert champion_generations(run) == dict.fromkeys(CHAMPIONS, 2)
    checkpoint_path(run, 2).unlink()  # as if stopped after generation 2's champions
    session = Session(run, resume=True)
    assert session.trainer.state.generation == 1
    assert champion_generations(run) == dict.fromkeys(CHAMPIONS, 1)
    session.close()


def test_resume_before_the_first_checkpoint_removes_every_champion(
    two_generations, tmp_path
) -> None:
    run = copy_run(two_generations, tmp_path)
    for _, path in list_checkpoints(run):
        path.unlink()  # as if stopped between generation 1's champions and its checkpoint
    (run / "champions" / "Stray.json").write_text("{}")
    session = Session(run, resume=True)
    assert session.trainer.state.generation == 0
    assert sorted(p.name for p in (run / "champions").iterdir()) == []
    session.close()


def test_a_busy_run_directory_names_itself(two_generations) -> None:
    with lock_dir(two_generations):
        with pytest.raises(LockedError) as err:
            Session(two_generations, resume=True)
    assert str(err.value).startswith(f"{two_generations}: the run directory is in use by ")


def test_a_backend_refused_at_the_start_leaves_nothing_behind(tmp_path) -> None:
    run = tmp_path / "run"
    # backend dask without an address or workers is refused before the first write
    with pytest.raises(ConfigError, match="^backend 'dask' needs either address"):
        Session(run, tiny("backend=dask"))
    assert not run.exists()


def test_a_run_failing_after_the_lock_releases_it_and_closes_its_backend(
    tmp_path, monkeypatch
) -> None:
    import mtpg.evolve.session as session_module
    from mtpg.engine.evaluator import LocalEvaluator

    closed = []

    class Backend(LocalEvaluator):
        def close(self) -> None:
            closed.append(True)

    def failing_trainer(*args) -> None:
        raise RuntimeError("no trainer")

    monkeypatch.setattr(session_module, "make_evaluator", lambda cfg, wait=None: Backend(1))
    monkeypatch.setattr(session_module, "Trainer", failing_trainer)
    run = tmp_path / "run"
    with pytest.raises(RuntimeError, match="no trainer"):
        Session(run, tiny())
    assert closed == [True]
    lock_dir(run).release()  # free again


def test_run_all_asks_should_stop_before_each_generation(tmp_path) -> None:
    run = tmp_path / "run"
    session = Session(run, tiny("generations=3"))
    asked = []

    def should_stop() -> bool:
        asked.append(session.trainer.state.generation)
        return session.trainer.state.generation >= 1

    assert session.run_all(should_stop=should_stop) is False
    assert asked == [0, 1] and session.saved_generation == 1
    assert [g for g, _ in list_checkpoints(run)] == [1]
    session.close()  # closing again (run_all closed it) is harmless
    lock_dir(run).release()


def test_a_lost_backend_commits_the_generation_it_was_lost_in(tmp_path, monkeypatch):
    """``run_all`` commits the last generation, then raises, even between checkpoints."""
    import mtpg.evolve.session as session_module
    from mtpg.engine.evaluator import BackendLost
    from standins import losing_backend

    monkeypatch.setattr(
        session_module, "make_evaluator", lambda cfg, wait=None: losing_backend(2)(1)
    )
    run = tmp_path / "run"
    session = Session(run, tiny("checkpoint_interval=10", "generations=4"))
    with pytest.raises(BackendLost, match="gone"):
        session.run_all()
    assert [g for g, _ in list_checkpoints(run)] == [2]
    assert session.lock is None  # released
    monkeypatch.undo()
    resumed = Session(run, tiny("checkpoint_interval=10", "generations=4"), resume=True)
    assert resumed.trainer.state.generation == 2
    assert resumed.run_all()
