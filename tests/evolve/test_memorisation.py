"""The memorisation probe's episodes and scores, on hand-built graphs and a trainer.

A graph that never reads the noise input scores exactly the same on its training episodes
and on the same start states with the noise redrawn; a graph that recognises its training
episodes by their first noise value (and plays well only then) loses most of its score
when the noise is redrawn. (a) is the training score the trainer itself gave the champion,
including in a run that redraws its training episodes.
"""

from __future__ import annotations

import numpy as np
import pytest

from mtpg.config import build_config
from mtpg.engine.batch import Episodes
from mtpg.envs.taskset.task_table import TaskTable
from mtpg.evolve.memorisation import (
    champion_training_seeds,
    fresh_noise_episodes,
    observes_noise,
    probe_graph,
    training_block,
)
from mtpg.evolve.trainer import Trainer
from mtpg.model.graph import Population, atomic
from mtpg.model.instructions import (
    OP_ADD,
    OP_DIV,
    OP_IF_GT,
    OP_MUL,
    OP_SUB,
    RegisterLayout,
)
from tinyruns import tiny_overrides

L = RegisterLayout()
R0, R1, R7 = 0, 1, 7  # private registers (r[7] is never written: always 0)
M1, M2 = L.mem_start + 1, L.mem_start + 2
S0, S1 = L.obs_start, L.obs_start + 1  # the observation: s[1] is the noise input
CM09, C01, C04, C09 = (L.const_start + k for k in (0, 9, 12, 17))  # -0.9, 0.1, 0.4, 0.9
SIX = ["CartPole", "Acrobot", "CartCentering", "Pendulum", "MountainCar", "MountainCarContinuous"]
PUSH_RIGHT, PUSH_LEFT = 0, 2  # CartCentering: +1 N, -1 N


def code(*rows):
    return np.array(rows, dtype=np.int32)


def centring(pop: Population, bank) -> list[int]:
    """Pushes towards the centre, reading s[0] only: +F bids -s[0], -F bids s[0]."""
    right = pop.add_program(code([OP_SUB, R0, R7, S0]), atomic(PUSH_RIGHT), bank)
    left = pop.add_program(code([OP_ADD, R0, R7, S0]), atomic(PUSH_LEFT), bank)
    return [right.id, left.id]


def ignores_noise() -> tuple[Population, int]:
    """One team that never reads s[1]."""
    pop = Population(layout=L)
    bank = pop.new_bank()
    return pop, pop.add_team(centring(pop, bank)).id


def memoriser() -> tuple[Population, int]:
    """Plays towards the centre only in episodes whose first noise value exceeds 4/9.

    K keeps ``m1 = 0.9 * s[1]`` of the first step (``m2`` flags that it was taken) and bids
    -9; +F bids -s[0]; -F bids s[0], less 18 unless ``m1 > 0.4``. So with the key the
    graph centres the cart, without it it always pushes right and leaves the track.
    """
    pop = Population(layout=L)
    bank = pop.new_bank()
    key = pop.add_program(
        code(
            [OP_SUB, R1, C09, M2],
            [OP_MUL, R1, R1, S1],
            [OP_ADD, M1, M1, R1],
            [OP_ADD, M2, C09, R7],
            [OP_DIV, R0, CM09, C01],
        ),
        atomic(PUSH_RIGHT),
        bank,
    )
    right = pop.add_program(code([OP_SUB, R0, R7, S0]), atomic(PUSH_RIGHT), bank)
    left = pop.add_program(
        code(
            [OP_ADD, R0, R7, S0],
            [OP_ADD, R1, CM09, R7],
            [OP_IF_GT, R1, M1, C04],
            [OP_SUB, R1, R1, C09],
            [OP_DIV, R1, R1, C01],
            [OP_ADD, R0, R0, R1],
        ),
        atomic(PUSH_LEFT),
        bank,
    )
    return pop, pop.add_team([key.id, right.id, left.id]).id


def keyed_seeds(n: int) -> np.ndarray:
    """The first ``n`` episode seeds whose first CartCentering noise value exceeds 4/9."""
    seeds = np.arange(200, dtype=np.int64)
    table = Episodes.grid([TaskTable.from_names(["CartCentering"]).ids[0]], seeds)
    return seeds[table.noise[:, 0] > 4 / 9 + 1e-3][:n]


def test_a_graph_that_ignores_the_noise_scores_the_same_with_fresh_noise():
    pop, root = ignores_noise()
    probe = probe_graph(pop, root, SIX, np.arange(5), 10, redraws=4)
    for t in SIX:
        p = probe[t]
        assert p.fresh_noise == p.train, t
        assert p.redraw_means == (p.train,) * 4, t
        assert p.drops(p.raw())["noise"] == 0.0
    cc = probe["CartCentering"].normalised()
    assert cc["train"] > 0.3, "the centring rule learns something of CartCentering"


def test_a_graph_that_keys_on_its_training_noise_drops_when_it_is_redrawn():
    pop, root = memoriser()
    seeds = keyed_seeds(3)
    probe = probe_graph(pop, root, ["CartCentering", "CartPole"], seeds, 20, redraws=20)
    cc = probe["CartCentering"]
    honest = probe_graph(*ignores_noise(), ["CartCentering"], seeds, 20, redraws=1)
    assert cc.train == honest["CartCentering"].train, "keyed: plays the centring rule"
    norm = cc.normalised()
    assert norm["train"] - norm["fresh_noise"] > 0.3, norm
    assert min(cc.redraw_means) < cc.train  # some redraws miss the key
    assert cc.fresh_noise < cc.train
    # CartPole's second input is the pole angle, not the noise: nothing changes
    cp = probe["CartPole"]
    assert cp.fresh_noise == cp.train and not cp.observes_noise and cc.observes_noise


def test_fresh_noise_keeps_start_states_and_redraws_only_the_noise():
    tasks = ["Pendulum", "CartCentering", "Pendulum[noise=0.1]"]
    seeds = np.array([0, 3, 7], dtype=np.int64)
    fresh = fresh_noise_episodes(tasks, seeds, noise_seed=5, redraws=2)
    table = TaskTable.from_names(tasks)
    trained = Episodes.grid(list(table.ids), np.tile(seeds, 2), table)
    assert np.array_equal(fresh.starts, trained.starts)
    assert np.array_equal(fresh.obs_noise, trained.obs_noise)
    assert np.array_equal(fresh.tasks, trained.tasks)
    widths = {"Pendulum": 201, "CartCentering": 501, "Pendulum[noise=0.1]": 201}
    for i, t in enumerate(np.repeat(tasks, 6)):
        row, old = fresh.noise[i], trained.noise[i]
        k = widths[str(t)]
        assert np.all((row[:k] >= 0) & (row[:k] < 1)) and not np.any(row[k:])
        assert not np.any(row[:k] == old[:k])
    # the two redraws of one episode differ; a task's rows do not depend on the others
    assert not np.array_equal(fresh.noise[0], fresh.noise[3])
    alone = fresh_noise_episodes(["CartCentering"], seeds, noise_seed=5, redraws=3)
    assert np.array_equal(alone.noise[:6, :501], fresh.noise[6:12, :501])
    other = fresh_noise_episodes(["CartCentering"], seeds, noise_seed=6, redraws=2)
    assert not np.array_equal(other.noise, alone.noise[:6])
    with pytest.raises(ValueError, match="redraws must be >= 1"):
        fresh_noise_episodes(tasks, seeds, 0, 0)
    with pytest.raises(ValueError, match="noise seed must be >= 0"):
        fresh_noise_episodes(tasks, seeds, -1, 1)


def test_which_tasks_observe_the_noise_input():
    assert [observes_noise(t) for t in SIX] == [False, False, True, True, True, True]
    assert observes_noise("CartPole[observe=x]")
    assert not observes_noise("Pendulum[observe=theta+theta_dot]")


@pytest.mark.parametrize("interval", [0, 2])
def test_train_is_the_score_the_trainer_gave_the_champion(interval):
    overrides = tiny_overrides(
        evaluation__test_interval=0,
        evaluation__tasks='["CartCentering", "Pendulum"]',
        evaluation__resample_interval=interval,
    )
    config = build_config("paper", overrides=overrides)
    tr = Trainer(config)
    full = next(k for k, s in enumerate(tr.subsets) if len(s) == 2)
    for gen in range(1, 6):
        tr.run_generation()
        seeds = champion_training_seeds(config, gen)
        assert np.array_equal(seeds, tr.training_episodes(gen).seeds[: len(seeds)])
        assert training_block(config, gen) == (0 if interval == 0 else (gen - 1) // interval)
        root = tr.state.champions[full]
        probe = probe_graph(tr.state.population, root, config.evaluation.tasks, seeds, 2)
        trained = tr.state.scores[root]
        assert [probe[t].train for t in config.evaluation.tasks] == list(trained), gen
    if interval:
        assert not np.array_equal(champion_training_seeds(config, 5), np.arange(2))
    tr.close()
