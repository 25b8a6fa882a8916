"""The generation loop and its reporters: call order, stop requests, stop points, metas."""

from __future__ import annotations

import pytest

from mtpg.config import build_config
from mtpg.evolve import reporters as reporters_module
from mtpg.evolve import trainer as trainer_module
from mtpg.evolve.reporters import Reporter, train
from mtpg.evolve.session import Session
from mtpg.evolve.trainer import Trainer
from mtpg.io.checkpoint import checkpoint_path
from mtpg.io.serialize import load_graph


def tiny(*extra: str):
    return build_config(
        "paper",
        overrides=[
            "team.root_size=8",
            "team.n_elite=2",
            "team.init_team_size=2",
            "evaluation.train_episodes=1",
            "evaluation.test_episodes=1",
            'evaluation.tasks=["CartPole", "MountainCar"]',
            *extra,
        ],
    )


class Recorder(Reporter):
    def __init__(self) -> None:
        self.calls: list[tuple] = []

    def start(self, trainer: Trainer) -> None:
        self.calls.append(("start", trainer))

    def generation(self, gen, trainer: Trainer) -> None:
        self.calls.append(("generation", gen.number, gen.tests is not None, trainer))

    def end(self, trainer: Trainer) -> None:
        self.calls.append(("end", trainer))


def test_train_reports_every_generation_to_every_reporter_in_order() -> None:
    trainer = Trainer(tiny("generations=3", "evaluation.test_interval=2"))
    first, second = Recorder(), Recorder()
    assert train(trainer, [first, second]) is True
    want = [
        ("start", trainer),
        ("generation", 1, False, trainer),
        ("generation", 2, True, trainer),  # the interval
        ("generation", 3, True, trainer),  # the last generation
        ("end", trainer),
    ]
    assert first.calls == want and second.calls == want
    assert trainer.state.generation == 3
    assert train(trainer, [first]) is True  # done: no generation runs
    assert first.calls[-2:] == [("start", trainer), ("end", trainer)]


def test_train_stops_when_asked_before_a_generation() -> None:
    trainer = Trainer(tiny("generations=5", "evaluation.test_interval=0"))
    rec = Recorder()
    asked = []

    def should_stop() -> bool:
        asked.append(trainer.state.generation)
        return trainer.state.generation >= 2

    assert train(trainer, [rec], should_stop) is False
    assert asked == [0, 1, 2]
    assert [c[1] for c in rec.calls if c[0] == "generation"] == [1, 2]
    assert rec.calls[-1] == ("end", trainer)
    assert trainer.state.generation == 2


def test_stop_points_fire_at_the_documented_moments(tmp_path, monkeypatch) -> None:
    """The robustness tests stop runs at these points; each must fire where documented."""
    import mtpg.io.checkpoint as checkpoint_module

    run = tmp_path / "run"
    seen: list[tuple[str, int, bool]] = []

    def record(phase: str, generation: int) -> None:
        # for "checkpoint": the data is written but the checkpoint not yet in place
        seen.append((phase, generation, checkpoint_path(run, generation).exists()))

    monkeypatch.setattr(reporters_module, "point", record)
    monkeypatch.setattr(trainer_module, "point", record)
    monkeypatch.setattr(checkpoint_module, "point", record)  # passes "checkpoint"
    cfg = tiny("generations=3", "evaluation.test_interval=2", "checkpoint_interval=2")
    Session(run, cfg).run_all()
    phases = [(p, g) for p, g, _ in seen if p != "vary"]
    assert phases == [
        ("evaluate", 1),
        ("select", 1),
        ("metrics", 1),
        ("evaluate", 2),
        ("select", 2),
        ("metrics", 2),
        ("test", 2),
        ("commit", 2),
        ("checkpoint", 2),
        ("committed", 2),
        ("evaluate", 3),
        ("select", 3),
        ("metrics", 3),
        ("test", 3),
        ("commit", 3),
        ("checkpoint", 3),
        ("committed", 3),
    ]
    assert [g for p, g, _ in seen if p == "vary"] == [2, 3]
    exists = {(p, g): e for p, g, e in seen}
    assert not exists[("commit", 2)] and not exists[("checkpoint", 2)]
    assert exists[("committed", 2)]


@pytest.mark.parametrize("no_memory", [False, True])
def test_graph_files_record_the_memory_ablation(tmp_path, no_memory: bool) -> None:
    run = tmp_path / "run"
    flag = str(no_memory).lower()
    cfg = tiny("generations=1", "evaluation.test_interval=1", f"evaluation.no_memory={flag}")
    Session(run, cfg).run_all()
    for path in (
        run / "champions" / "CartPole.json",
        run / "tests" / "gen-000001" / "CartPole.json",
    ):
        _, _, meta = load_graph(path)
        assert meta["no_memory"] is no_memory


def test_the_vary_point_comes_after_half_of_the_subsets_bred(monkeypatch) -> None:
    cfg = tiny("generations=2", 'evaluation.tasks=["CartPole", "MountainCar", "Pendulum"]')
    trainer = Trainer(cfg)
    bred = []

    def record(phase: str, generation: int) -> None:
        if phase == "vary":
            st = trainer.state
            bred.append(len([r for r in st.population.roots() if r not in st.scores]))

    monkeypatch.setattr(trainer_module, "point", record)
    trainer.run_generation()
    trainer.run_generation()
    # 7 subsets: subsets 0, 1 and 2 have bred their 2 children each when subset 3 starts
    assert bred == [3 * cfg.elites_per_subset] and cfg.elites_per_subset == 2
