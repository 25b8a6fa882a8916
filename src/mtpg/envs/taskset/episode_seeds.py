"""The evaluation protocol: which episode seeds train, which test, which measure random play.

One home for the seed bases and the held-out seeds, used by the trainer, the reference
measurements, ``mtpg evaluate`` and the report alike. Episode seed ``s`` always draws the
same start state and noise (:func:`mtpg.envs.taskset.episodes.make_episodes`), so these ranges fix
what every reported number was measured on:

- training episode ``k`` of every task: seed ``TRAIN_SEED_BASE + k`` (0, 1, 2, ...), the
  same for every root in every generation;
- held-out test episode ``k``: seed ``TEST_SEED_BASE + offset + k`` (1,000,000, ...);
  an offset moves to another block of unseen episodes; training never reaches these seeds
  (a run would need a million training episodes per task);
- random-agent measurement episode ``i``: seed ``RANDOM_SEED_BASE + i`` (2,000,000, ...);
- validation episode ``k`` (``evaluation.validation_episodes``, beyond the paper): seed
  ``VALIDATION_SEED_BASE + k`` (3,000,000, ...), the same for every root of the run;
- resampled training episodes (``evaluation.resample_interval``, beyond the paper): from
  the run's second training block on, seeds drawn without replacement from
  ``[RESAMPLE_SEED_BASE, RESAMPLE_SEED_BASE + RESAMPLE_SPAN)`` (2**32 and up) by a
  generator of the run seed and the block number (:func:`resampled_training_seeds`).

Every range is disjoint from every other as long as the episode counts stay within their
hard limits (:data:`mtpg.limits.LIMITS`), so neither validation nor resampled training
episodes can ever be test episodes.

The module lives in ``envs`` (not ``evolve``) because the reference scores of the tasks are
measured on the same held-out seeds and ``envs`` must not depend on training code.
"""

from __future__ import annotations

import numpy as np

#: Training episode ``k`` of every task uses episode seed ``TRAIN_SEED_BASE + k``.
TRAIN_SEED_BASE = 0
#: First episode seed of the held-out test episodes.
TEST_SEED_BASE = 1_000_000
#: Number of held-out test episodes per task of the paper's protocol (and of ``evaluate``
#: on a graph file).
N_TEST_EPISODES = 100
#: First episode seed of the random-agent measurement.
RANDOM_SEED_BASE = 2_000_000
#: First episode seed of the validation episodes.
VALIDATION_SEED_BASE = 3_000_000
#: First episode seed of resampled training episodes, and the width of their range.
RESAMPLE_SEED_BASE = 1 << 32
RESAMPLE_SPAN = 1 << 32
#: First element of the ``SeedSequence`` spawn key of a resampled block (ASCII "rsmp"):
#: no other generator of a run is spawned with it.
RESAMPLE_SPAWN_TAG = 0x72736D70


def training_seeds(episodes: int) -> np.ndarray:
    """Seeds of the training episodes: ``TRAIN_SEED_BASE + k`` for k < ``episodes``.

    Args:
        episodes: Training episodes per task.

    Returns:
        int64 [episodes] seeds.
    """
    return TRAIN_SEED_BASE + np.arange(episodes, dtype=np.int64)


def held_out_seeds(episodes: int, offset: int = 0) -> np.ndarray:
    """Seeds of held-out test episodes: ``TEST_SEED_BASE + offset + k``, never training seeds.

    Args:
        episodes: Test episodes per task.
        offset: First seed relative to ``TEST_SEED_BASE`` (0 for the run's own test points).

    Returns:
        int64 [episodes] seeds.

    Raises:
        ValueError: If ``offset`` is negative.
    """
    if offset < 0:
        raise ValueError(f"test seed offset must be >= 0, got {offset}")
    return TEST_SEED_BASE + offset + np.arange(episodes, dtype=np.int64)


def describe_held_out(episodes: int, offset: int = 0) -> str:
    """Human-readable description of a block of held-out episodes, for figures and tables."""
    first = TEST_SEED_BASE + offset
    return f"{episodes} held-out episodes per task (seeds {first:,}..{first + episodes - 1:,})"


def validation_seeds(episodes: int) -> np.ndarray:
    """Seeds of the validation episodes: ``VALIDATION_SEED_BASE + k`` for k < ``episodes``.

    Args:
        episodes: Validation episodes per task.

    Returns:
        int64 [episodes] seeds, disjoint from training, test and random-agent seeds.
    """
    return VALIDATION_SEED_BASE + np.arange(episodes, dtype=np.int64)


def resampled_training_seeds(run_seed: int, block: int, episodes: int) -> np.ndarray:
    """Training seeds of training block ``block`` of a run with resampled episodes.

    Block 0 is the ordinary training block (:func:`training_seeds`). Block ``b >= 1``
    draws ``episodes`` distinct seeds from ``[RESAMPLE_SEED_BASE, RESAMPLE_SEED_BASE +
    RESAMPLE_SPAN)`` with a generator of ``SeedSequence(run_seed, spawn_key=(tag, b))``:
    a pure function of the run seed and the block, independent of the run's own generator
    (whose stream it leaves untouched), so a resumed run redraws exactly the same block.

    Args:
        run_seed: The run seed.
        block: The training block (0, 1, ...).
        episodes: Training episodes per task.

    Returns:
        int64 [episodes] seeds.

    Raises:
        ValueError: If ``block`` is negative.
    """
    if block < 0:
        raise ValueError(f"training block must be >= 0, got {block}")
    if block == 0:
        return training_seeds(episodes)
    seq = np.random.SeedSequence(run_seed, spawn_key=(RESAMPLE_SPAWN_TAG, block))
    drawn = np.random.default_rng(seq).choice(RESAMPLE_SPAN, size=episodes, replace=False)
    return RESAMPLE_SEED_BASE + np.asarray(drawn, dtype=np.int64)
