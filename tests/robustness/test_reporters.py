"""The generation loop and reporters: training without a run directory, stopping at boundaries."""

import pytest

from mtpg.config import build_config
from mtpg.evolve.columns import TIMING_COLUMNS
from mtpg.evolve.reporters import CallbackReporter, Reporter, generations, train
from mtpg.evolve.session import Session
from mtpg.evolve.trainer import Trainer

SETTINGS = [
    "team.root_size=12",
    "team.n_elite=2",
    "team.init_team_size=3",
    "team.min_elite_total=0",
    "evaluation.train_episodes=2",
    "evaluation.test_interval=2",
    "evaluation.test_episodes=2",
    'evaluation.tasks=["CartPole", "MountainCar"]',
    "generations=4",
]


def config():
    return build_config("demo", None, SETTINGS)


def strip(row):
    return {k: v for k, v in row.items() if k not in TIMING_COLUMNS}


class Recorder(Reporter):
    def __init__(self):
        self.calls = []

    def start(self, trainer):
        self.calls.append(("start", trainer.state.generation))

    def generation(self, gen, trainer):
        self.calls.append(("generation", gen.number, gen.tests is not None))

    def end(self, trainer):
        self.calls.append(("end", trainer.state.generation))


def test_training_without_a_run_directory_equals_a_session(tmp_path):
    rows = []
    rec = Recorder()
    assert train(Trainer(config()), [rec, CallbackReporter(lambda r, t: rows.append(r))])
    assert rec.calls == [
        ("start", 0),
        ("generation", 1, False),
        ("generation", 2, True),
        ("generation", 3, False),
        ("generation", 4, True),
        ("end", 4),
    ]
    session_rows = []
    assert Session(tmp_path / "run", config()).run_all(lambda r, t: session_rows.append(r))
    assert [strip(r) for r in rows] == [strip(r) for r in session_rows]
    assert not list(tmp_path.glob("*.csv"))  # nothing written outside the run directory


def test_stop_request_ends_at_a_boundary_and_commits_it(tmp_path):
    asked = []

    def stop():
        asked.append(1)
        return len(asked) > 2  # stop before the third generation

    session = Session(tmp_path / "run", config())
    assert session.run_all(should_stop=stop) is False
    assert session.saved_generation == 2
    assert (tmp_path / "run" / "checkpoints" / "gen-000002.json.gz").is_file()


def test_an_error_mid_run_commits_nothing_half_done(tmp_path):
    class Boom(Reporter):
        def generation(self, gen, trainer):
            if gen.number == 3:
                raise RuntimeError("boom")

    trainer = Trainer(config())
    rec = Recorder()
    with pytest.raises(RuntimeError):
        train(trainer, [rec, Boom()])
    assert rec.calls[-1] == ("generation", 3, False)  # end() was not called
    assert [g.number for g in generations(Trainer(config()), lambda: False)] == [1, 2, 3, 4]
