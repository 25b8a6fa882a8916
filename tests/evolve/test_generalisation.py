"""Validation episodes and resampled training episodes (beyond the paper).

``evaluation.validation_episodes`` / ``validation_top_k``: champions chosen among each
subset's best training roots on validation episodes; ``evaluation.resample_interval``:
training episodes redrawn every G generations with every survivor evaluated again. Both
are off in ``paper`` and ``demo``; test episodes never reach any choice.
"""

from __future__ import annotations

import numpy as np
import pytest

from mtpg.config import ConfigError, RunConfig, build_config, from_dict, to_dict, to_toml
from mtpg.envs.taskset.episode_seeds import (
    TEST_SEED_BASE,
    held_out_seeds,
    resampled_training_seeds,
    training_seeds,
    validation_seeds,
)
from mtpg.envs.taskset.reference_scores import REFERENCE
from mtpg.evolve import heldout_test as heldout_test_module
from mtpg.evolve.columns import TIMING_COLUMNS, metric_columns
from mtpg.evolve.persist import (
    config_differences,
    identity_fields,
    run_identity,
    state_from_payload,
    state_to_payload,
)
from mtpg.evolve.selection import candidates, rankings
from mtpg.evolve.trainer import Trainer
from mtpg.evolve.validation import choose, validation_fitness

TINY = [
    "team.root_size=12",
    "team.n_elite=2",
    "team.init_team_size=3",
    "evaluation.train_episodes=2",
    "evaluation.test_episodes=3",
    'evaluation.tasks=["CartPole", "CartCentering"]',
]
ON = ["evaluation.validation_episodes=3", "evaluation.validation_top_k=3"]
RESAMPLE = ["evaluation.resample_interval=2"]
MEAN = [*RESAMPLE, "evaluation.resample_mean=true"]
NEW_FIELDS = ("validation_episodes", "validation_top_k", "resample_interval", "resample_mean")


def tiny(*extra: str) -> RunConfig:
    return build_config("paper", overrides=[*TINY, *extra])


# -- configuration ------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("override", "field"),
    [
        ("evaluation.validation_episodes=-1", "evaluation.validation_episodes"),
        ("evaluation.validation_episodes=100001", "evaluation.validation_episodes"),
        ("evaluation.validation_top_k=0", "evaluation.validation_top_k"),
        ("evaluation.validation_top_k=100001", "evaluation.validation_top_k"),
        ("evaluation.resample_interval=-1", "evaluation.resample_interval"),
        ("evaluation.resample_interval=1.5", "evaluation.resample_interval"),
        ('evaluation.validation_episodes="many"', "evaluation.validation_episodes"),
        ("evaluation.resample_mean=true", "evaluation.resample_mean"),  # needs an interval
        ("evaluation.resample_mean=1", "evaluation.resample_mean"),
    ],
)
def test_bad_values_are_refused_naming_the_field(override: str, field: str) -> None:
    with pytest.raises(ConfigError, match=field.replace(".", r"\.")) as info:
        build_config("paper", overrides=[override])
    assert "\n" not in str(info.value)


@pytest.mark.parametrize("preset", ["paper", "demo"])
def test_the_options_are_off_in_the_presets(preset: str) -> None:
    ev = build_config(preset).evaluation
    assert (ev.validation_episodes, ev.resample_interval, ev.resample_mean) == (0, 0, False)


def test_the_options_are_in_config_toml_and_read_back() -> None:
    cfg = tiny(*ON, *RESAMPLE)
    text = to_toml(cfg)
    assert "validation_episodes = 3" in text and "resample_interval = 2" in text
    assert from_dict(to_dict(cfg)) == cfg


def test_old_configurations_without_the_fields_load_with_them_off() -> None:
    data = to_dict(build_config("paper"))
    for name in NEW_FIELDS:
        del data["evaluation"][name]
    assert from_dict(data) == build_config("paper")


def test_off_options_leave_the_run_identity_as_before() -> None:
    paper = build_config("paper")
    assert not set(NEW_FIELDS) & set(identity_fields(paper)["evaluation"])
    on = build_config("paper", overrides=["evaluation.validation_episodes=10"])
    assert run_identity(on) != run_identity(paper)
    assert config_differences(paper, on) == ["evaluation.validation_episodes"]
    shuffled = build_config("paper", overrides=["evaluation.resample_interval=5"])
    assert config_differences(on, shuffled) == [
        "evaluation.validation_episodes",
        "evaluation.resample_interval",
    ]


def test_metrics_columns_are_added_only_when_an_option_is_on() -> None:
    paper = build_config("paper").evaluation
    assert metric_columns(paper.tasks, paper) == metric_columns(paper.tasks)
    cols = metric_columns(paper.tasks, tiny(*ON, *RESAMPLE).evaluation)
    extra = [c for c in cols if c not in metric_columns(paper.tasks)]
    assert extra == ["validated_roots", "validation_decisions", "reevaluated_roots"]


# -- seeds --------------------------------------------------------------------------------


def test_validation_and_resampled_seeds_are_disjoint_from_training_and_test() -> None:
    val = set(validation_seeds(100_000).tolist())
    test = set(held_out_seeds(1_000_000).tolist())
    train = set(training_seeds(100_000).tolist())
    assert not val & test and not val & train
    for block in (1, 2, 37):
        drawn = resampled_training_seeds(7, block, 50)
        assert len(set(drawn.tolist())) == 50
        assert drawn.min() >= 2**32 and not set(drawn.tolist()) & (val | test | train)
        assert np.array_equal(drawn, resampled_training_seeds(7, block, 50))
    assert not np.array_equal(resampled_training_seeds(7, 1, 5), resampled_training_seeds(8, 1, 5))
    assert np.array_equal(resampled_training_seeds(7, 0, 5), training_seeds(5))


# -- the validated champion choice: hand-worked -------------------------------------------


def _raw(task: int, normalised: float) -> float:
    ref = REFERENCE[task]
    return ref.random + normalised * (ref.best - ref.random)


#: CartPole (task 0) and Pendulum (task 3), reference-normalised validation scores:
#:   root  CartPole  Pendulum  min   mean
#:   10    1.0       0.2       0.2   0.6
#:   11    0.5       0.5       0.5   0.5
#:   12    0.3       0.9       0.3   0.6
VALID = {
    10: np.array([_raw(0, 1.0), _raw(3, 0.2)]),
    11: np.array([_raw(0, 0.5), _raw(3, 0.5)]),
    12: np.array([_raw(0, 0.3), _raw(3, 0.9)]),
}


def test_validation_fitness_is_the_minimum_reference_normalised_score() -> None:
    scores = np.array([VALID[r] for r in (10, 11, 12)])
    assert np.allclose(validation_fitness(scores, (0, 1), [0, 3]), [0.2, 0.5, 0.3])
    assert np.allclose(validation_fitness(scores, (0,), [0, 3]), [1.0, 0.5, 0.3])


def test_each_subset_takes_its_best_validated_candidate() -> None:
    cands = [[10, 11, 12], [11, 10, 12], [12, 11, 10]]
    subsets = [(0,), (1,), (0, 1)]
    assert choose(cands, VALID, subsets, [0, 3]) == [10, 12, 11]  # mean would give 12/10


def test_ties_in_validation_go_to_the_better_training_root() -> None:
    same = {1: np.array([50.0, -500.0]), 2: np.array([50.0, -500.0])}
    assert choose([[2, 1], [1, 2]], same, [(0,), (0, 1)], [0, 3]) == [2, 1]


# -- in a run -----------------------------------------------------------------------------


def _state(tr: Trainer) -> tuple:
    st = tr.state
    return (
        st.generation,
        {r: s.tolist() for r, s in st.scores.items()},
        st.elites,
        st.champions,
        {r: s.tolist() for r, s in st.validation.items()},
        {r: (n, t.tolist()) for r, (n, t) in st.blocks.items()},
        st.rng.bit_generator.state,
    )


def _run(config: RunConfig, generations: int, record: list | None = None):
    tr = Trainer(config)
    phase = ["train"]
    real = tr.evaluator.evaluate

    def spy(cp, roots, table):
        if record is not None:
            record.append((phase[0], set(table.seeds.tolist())))
        return real(cp, roots, table)

    tr.evaluator.evaluate = spy
    rows, tests = [], []
    for _ in range(generations):
        rows.append(tr.run_generation())
        phase[0] = "test"
        tests.append(tr.held_out_scores())
        phase[0] = "train"
    tr.close()
    return tr, rows, tests


def test_champions_are_the_best_validated_of_each_subsets_candidates() -> None:
    tr, rows, _ = _run(tiny(*ON), 4)
    st = tr.state
    ids = np.array(sorted(st.scores), dtype=np.int64)
    scores = np.array([st.scores[int(r)] for r in ids])
    cands = candidates(ids, rankings(ids, scores, tr.subsets), set(st.scores), 3)
    assert st.champions == choose(cands, st.validation, tr.subsets, tr.task_ids)
    assert set(st.validation) <= set(st.scores)
    assert all(r["validation_decisions"] > 0 for r in rows[:1])
    assert sum(r["validated_roots"] for r in rows) >= len(st.validation)


@pytest.mark.parametrize("options", [ON + RESAMPLE, ON + MEAN])
def test_test_episodes_never_reach_selection_or_the_champion_choice(monkeypatch, options) -> None:
    calls: list = []
    config = tiny(*options)
    ref, rows, tests = _run(config, 5, calls)
    test_seeds = set(held_out_seeds(3).tolist())
    assert {p for p, _ in calls} == {"train", "test"}
    for phase, seeds in calls:
        assert (seeds == test_seeds) == (phase == "test")
        if phase == "train":  # training (block 0 or redrawn) and validation episodes
            assert not any(TEST_SEED_BASE <= s < TEST_SEED_BASE + 1_000_000 for s in seeds)
    # other test episodes (other outcomes): the same run, other test rows
    other = held_out_seeds(3, offset=500)
    monkeypatch.setattr(heldout_test_module, "held_out_seeds", lambda n, offset=0: other)
    moved, rows2, tests2 = _run(config, 5)
    assert _state(moved) == _state(ref)
    assert [r["root"] for t in tests2 for r in t] == [r["root"] for t in tests for r in t]
    assert tests2 != tests


def test_resampling_evaluates_every_survivor_again_on_the_new_block() -> None:
    config = tiny(*RESAMPLE)
    tr = Trainer(config)
    rows = [tr.run_generation() for _ in range(2)]
    survivors = set(tr.state.scores)
    assert [tr.training_block(g) for g in (1, 2, 3, 4, 5)] == [0, 0, 1, 1, 2]
    rows.append(tr.run_generation())  # generation 3: block 1
    assert [r["reevaluated_roots"] for r in rows] == [0, 0, len(survivors)]
    assert rows[2]["new_roots"] == rows[1]["new_roots"]  # children only
    block = tr.training_episodes(3)
    assert set(block.seeds.tolist()) == set(resampled_training_seeds(0, 1, 2).tolist())
    from mtpg.engine.compile import compile_population

    kept = sorted(survivors & set(tr.state.scores))
    assert kept
    returns, _ = tr.evaluator.evaluate(compile_population(tr.state.population), kept, block, False)
    means = returns.reshape(len(kept), 2, 2).mean(axis=2)
    for root, row in zip(kept, means, strict=True):
        assert np.array_equal(tr.state.scores[root], row)
    tr.close()


def test_without_resampling_a_root_is_scored_once_for_life() -> None:
    tr = Trainer(tiny())
    tr.run_generation()
    before = {r: s.copy() for r, s in tr.state.scores.items()}
    for _ in range(3):
        tr.run_generation()
    for root, s in tr.state.scores.items():
        if root in before:
            assert np.array_equal(s, before[root])
    assert "reevaluated_roots" not in tr.run_generation()
    tr.close()


@pytest.mark.parametrize("options", [ON, RESAMPLE, ON + RESAMPLE, MEAN, ON + MEAN])
def test_a_run_continued_from_its_payload_equals_the_uninterrupted_one(options) -> None:
    config = tiny(*options)
    whole, rows, _ = _run(config, 5)
    first = Trainer(config)
    for _ in range(3):
        first.run_generation()
    payload = state_to_payload(first.state)
    assert ("validation" in payload) == (config.evaluation.validation_episodes > 0)
    state, stored = state_from_payload(payload)
    assert stored == config
    second = Trainer(config, state)
    again = [second.run_generation() for _ in range(2)]
    assert _state(second) == _state(whole)
    timing = TIMING_COLUMNS
    strip = [{k: v for k, v in r.items() if k not in timing} for r in again]
    assert strip == [{k: v for k, v in r.items() if k not in timing} for r in rows[3:]]
    first.close()
    second.close()


def test_a_paper_payload_has_no_validation_key() -> None:
    tr = Trainer(tiny())
    tr.run_generation()
    assert "validation" not in state_to_payload(tr.state)
    tr.close()


def test_champion_files_record_their_validation_scores() -> None:
    from mtpg.evolve.reporters import champion_graphs

    tr = Trainer(tiny(*ON))
    tr.run_generation()
    for names, (_, root, meta) in champion_graphs(tr).items():
        cols = [tr.config.evaluation.tasks.index(t) for t in names]
        assert meta["validation_scores"] == {
            t: float(tr.state.validation[root][c]) for t, c in zip(names, cols, strict=True)
        }
    tr.close()
    paper = Trainer(tiny())
    paper.run_generation()
    assert all("validation_scores" not in m for _, _, m in champion_graphs(paper).values())
    paper.close()


def test_the_work_estimate_counts_validation_and_reevaluation() -> None:
    from mtpg.limits import training_estimate

    base = training_estimate(build_config("paper"))["decisions"]
    val = training_estimate(build_config("paper", overrides=["evaluation.validation_episodes=50"]))
    resampled = training_estimate(build_config("paper", overrides=RESAMPLE))
    assert val["decisions"] > base and resampled["decisions"] > base


def test_with_every_option_on_one_or_two_workers_give_the_same_run() -> None:
    every = [*ON, *RESAMPLE, 'team.parent_selection="lexicase"']
    one, _, tests_one = _run(tiny(*every, "workers=1"), 4)
    two, _, tests_two = _run(tiny(*every, "workers=2"), 4)
    assert _state(one) == _state(two) and tests_one == tests_two
    assert {r: t.tolist() for r, t in one.state.returns.items()} == {
        r: t.tolist() for r, t in two.state.returns.items()
    }
