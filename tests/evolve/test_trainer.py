import csv

import numpy as np
import pytest

from mtpg.config import build_config
from mtpg.evolve.columns import TIMING_COLUMNS
from mtpg.evolve.session import Session
from mtpg.evolve.trainer import Trainer
from mtpg.model.graph import check_invariants

TINY = [
    "team.root_size=24",
    "team.n_elite=3",
    "team.init_team_size=3",
    "evaluation.train_episodes=2",
    'evaluation.tasks=["CartPole", "MountainCar"]',
    "team.p_atomic=0.7",
]


def tiny(*extra, generations=6):
    return build_config("paper", overrides=[*TINY, f"generations={generations}", *extra])


def strip_timing(rows):
    return [{k: v for k, v in r.items() if k not in TIMING_COLUMNS} for r in rows]


def run_rows(config):
    trainer = Trainer(config)
    rows = []
    while not trainer.done:
        rows.append(trainer.run_generation())
        check_invariants(trainer.state.population)
        pop = trainer.state.population
        # the roots are exactly the scored survivors; every subset's elites are roots
        assert set(pop.roots()) == set(trainer.state.scores)
        assert all(set(e) <= set(trainer.state.scores) for e in trainer.state.elites)
    return rows, trainer


def test_same_seed_same_run_on_one_and_two_workers():
    a, ta = run_rows(tiny("workers=1"))
    b, tb = run_rows(tiny("workers=2"))
    assert strip_timing(a) == strip_timing(b)
    assert ta.state.champions == tb.state.champions
    c, _ = run_rows(tiny("seed=1"))
    assert strip_timing(a) != strip_timing(c)


def test_selection_keeps_n_elite_per_subset():
    rows, trainer = run_rows(tiny())
    assert all(r["roots"] <= 3 * 3 for r in rows)
    assert len(trainer.state.elites) == 3 and len(trainer.state.champions) == 3


def read_csv(path):
    with open(path) as fh:
        return strip_timing(list(csv.DictReader(fh)))


def read_champions(run_dir):
    return {p.name: p.read_bytes() for p in sorted((run_dir / "champions").glob("*.json"))}


def test_resumed_run_equals_uninterrupted(tmp_path):
    full = tmp_path / "full"
    Session(full, tiny(generations=7)).run_all()
    part = tmp_path / "part"
    Session(part, tiny("checkpoint_interval=2", generations=3)).run_all()
    # a longer run continues from the generation-3 checkpoint
    Session(part, tiny("checkpoint_interval=2", generations=7), resume=True).run_all()
    assert read_csv(full / "metrics.csv") == read_csv(part / "metrics.csv")
    assert read_champions(full) == read_champions(part)
    assert len(read_csv(full / "metrics.csv")) == 7


@pytest.mark.parametrize(
    ("switch", "field", "value"),
    [
        ("--no-crossover", ("team", "p_crossover"), 0.0),
        ("--no-memory", ("evaluation", "no_memory"), True),
        ("--no-hierarchy", ("team", "p_atomic"), 1.0),
    ],
)
def test_ablation_switches_change_exactly_what_they_name(switch, field, value):
    from mtpg.cli.common import overrides
    from mtpg.cli.main import build_parser
    from mtpg.config import to_dict

    args = build_parser().parse_args(["train", switch])
    base = to_dict(build_config("paper"))
    changed = to_dict(build_config("paper", overrides=overrides(args)))
    diffs = {
        (s, k)
        for s in base
        if isinstance(base[s], dict)
        for k in base[s]
        if base[s][k] != changed[s][k]
    }
    assert diffs == {field}
    assert changed[field[0]][field[1]] == value


def test_no_memory_flag_reaches_the_engine(monkeypatch):
    import mtpg.engine.evaluator as evaluator_module

    seen = []
    real = evaluator_module.evaluate_roots

    def spy(*args, **kwargs):
        seen.append(args[0].no_memory)  # the compiled graph carries the ablation
        return real(*args, **kwargs)

    monkeypatch.setattr(evaluator_module, "evaluate_roots", spy)
    run_rows(tiny("evaluation.no_memory=true", generations=2))
    run_rows(tiny(generations=2))
    assert seen == [True, True, False, False]


def test_no_hierarchy_keeps_graphs_flat():
    _, flat = run_rows(tiny("team.p_atomic=1.0", "team.p_action=0.8", generations=8))
    assert all(p.is_atomic for p in flat.state.population.programs.values())
    _, deep = run_rows(tiny("team.p_atomic=0.3", "team.p_action=0.8", generations=8))
    assert any(not p.is_atomic for p in deep.state.population.programs.values())


def test_scores_are_means_over_training_episodes():
    from mtpg.engine.batch import Episodes, evaluate_roots
    from mtpg.engine.compile import compile_population

    _, trainer = run_rows(tiny(generations=2))
    st = trainer.state
    roots = sorted(st.scores)
    eps = Episodes.grid([0, 4], [0, 1])
    returns, _ = evaluate_roots(compile_population(st.population), roots, eps)
    means = returns.reshape(len(roots), 2, 2).mean(axis=2)
    assert np.array_equal(means, np.array([st.scores[r] for r in roots]))
