"""Scores averaged over training blocks (``evaluation.resample_mean``, beyond the paper).

With resampling on, a surviving root is scored again on every new block of training
episodes; with ``resample_mean`` its score is the mean over all blocks it has played
(each weighing alike), not the current block's alone. Checked against the root's returns
replayed block by block, outside the trainer.
"""

from __future__ import annotations

import numpy as np
import pytest

from mtpg.config import build_config
from mtpg.engine.compile import compile_population
from mtpg.evolve.persist import state_from_payload, state_to_payload
from mtpg.evolve.trainer import Trainer
from mtpg.io.serialize import FormatError
from tinyruns import tiny_overrides

TINY = tiny_overrides(
    evaluation__test_episodes=3,
    evaluation__test_interval=0,
    evaluation__tasks='["CartPole", "Pendulum"]',
    evaluation__resample_interval=1,  # a new block every generation
)


def _block_score(tr: Trainer, root: int, gen: int) -> np.ndarray:
    """The root's mean return per task on generation ``gen``'s training block."""
    cp = compile_population(tr.state.population)
    returns, _ = tr.evaluator.evaluate(cp, [root], tr.training_episodes(gen), False)
    return returns.reshape(2, 2).mean(axis=1)


@pytest.mark.parametrize("mean", [False, True])
def test_a_survivors_score_is_the_mean_over_its_blocks_only_when_asked(mean: bool) -> None:
    overrides = [*TINY, f"evaluation.resample_mean={str(mean).lower()}"]
    tr = Trainer(build_config("paper", overrides=overrides))
    played: dict[int, list[np.ndarray]] = {}
    veterans = 0
    for gen in range(1, 6):
        tr.run_generation()
        for root in tr.state.scores:
            played.setdefault(root, []).append(_block_score(tr, root, gen))
        played = {r: rows for r, rows in played.items() if r in tr.state.scores}
        for root, rows in played.items():
            score = tr.state.scores[root]
            if mean:
                assert tr.state.blocks[root][0] == len(rows)
                np.testing.assert_allclose(score, np.mean(rows, axis=0), rtol=1e-12, atol=1e-12)
                veterans += len(rows) > 1 and not np.array_equal(score, rows[-1])
            else:
                assert np.array_equal(score, rows[-1])
                assert not tr.state.blocks
                veterans += len(rows) > 1
    assert veterans, "no root was scored on two blocks"
    tr.close()


def test_a_payload_without_block_counts_is_refused() -> None:
    tr = Trainer(build_config("paper", overrides=[*TINY, "evaluation.resample_mean=true"]))
    tr.run_generation()
    payload = state_to_payload(tr.state)
    assert len(payload["blocks"]) == len(payload["scores"])
    state, _ = state_from_payload(payload)
    assert {r: (n, t.tolist()) for r, (n, t) in state.blocks.items()} == {
        r: (n, t.tolist()) for r, (n, t) in tr.state.blocks.items()
    }
    zero = [[r, 0, t] for r, _, t in payload["blocks"]]
    short = [[r, n, t[:1]] for r, n, t in payload["blocks"]]
    for broken in ([], zero, short):
        with pytest.raises(FormatError, match="block counts"):
            state_from_payload(payload | {"blocks": broken})
    tr.close()
