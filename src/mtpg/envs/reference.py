"""Reference scores of the six tasks, the measurements behind them, and normalisation.

``normalise(task, score) = (score - random) / (best - random)`` (paper, Figs. 5-7): 0 is
random play, 1 the reference best.

Conventions (used by the stored figures and by the re-measuring functions):

- Random agent: ``a_d`` uniform on {0, 1, 2} and ``a_c`` uniform on [-bound, bound] each step
  (``ACTION_BOUND``; 0 for discrete tasks, which ignore ``a_c``), over
  ``N_RANDOM_EPISODES`` = 10,000 episodes. Episode ``i`` uses the episode seed
  ``RANDOM_SEED_BASE + i`` (``make_episodes``); the actions come from
  ``np.random.default_rng(RANDOM_ACTION_SEED)``, drawn per block of 1,000 episodes as
  ``a_d = integers(0, 3, (m, T))`` then ``a_c = uniform(-bound, bound, (m, T))``, T the
  time limit.
- Test episodes: seeds ``TEST_SEED_BASE + i`` for i < ``N_TEST_EPISODES`` (1_000_000 ..
  1_000_099). The CartCentering reference best is the mean score of the time-optimal law on
  these episodes.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from mtpg.envs.core import CARTCENTERING
from mtpg.envs.protocol import (  # noqa: F401  (the seed bases live in protocol)
    N_TEST_EPISODES,
    RANDOM_SEED_BASE,
    TEST_SEED_BASE,
    held_out_seeds,
)
from mtpg.envs.registry import TASKS
from mtpg.envs.taskspec import NONE, Reference

#: Seed of the random agent's action generator.
RANDOM_ACTION_SEED = 12345
#: Episodes of the random-agent measurement.
N_RANDOM_EPISODES = 10_000
_CHUNK = 1000


def make_test_seeds(n: int = N_TEST_EPISODES) -> np.ndarray:
    """The test-episode seeds ``TEST_SEED_BASE + i``, i < n.

    Args:
        n: Number of seeds.

    Returns:
        int64 [n] seeds.
    """
    return held_out_seeds(n)


def measure_random(
    task: int,
    n: int = N_RANDOM_EPISODES,
    seed: int = RANDOM_ACTION_SEED,
    seed_base: int = RANDOM_SEED_BASE,
) -> tuple[float, float]:
    """Measures the random agent's mean score (the ``random`` of the normalisation).

    Args:
        task: The task id (a variant's too: its reference scores are measured this way).
        n: Number of episodes.
        seed: Seed of the action generator.
        seed_base: Episode ``i`` uses episode seed ``seed_base + i``.

    Returns:
        (mean, standard deviation) of the episode returns.
    """
    from mtpg.envs.episodes import make_episodes
    from mtpg.envs.rollout import run_episodes
    from mtpg.envs.variants import spec_of, task_params

    spec = spec_of(task)
    limit = spec.max_steps
    bound = spec.bound
    rng = np.random.default_rng(seed)
    returns = np.zeros(n)
    for lo in range(0, n, _CHUNK):
        m = min(_CHUNK, n - lo)
        starts, noise = make_episodes(np.full(m, task), seed_base + lo + np.arange(m))
        a_d = rng.integers(0, 3, (m, limit))
        a_c = rng.uniform(-bound, bound, (m, limit))
        returns[lo : lo + m] = run_episodes(task, task_params(), starts, noise, a_d, a_c)
    return float(returns.mean()), float(returns.std())


def measure_time_optimal_cartcentering(
    seeds: np.ndarray | None = None,
) -> tuple[float, float, int]:
    """Scores Koza's time-optimal law (``-x > v |v|`` -> +F) on CartCentering episodes.

    Args:
        seeds: Episode seeds; the test seeds by default.

    Returns:
        (mean score, mean steps, number of episodes ending by capture).
    """
    from mtpg.envs.episodes import make_episodes
    from mtpg.envs.rollout import run_time_optimal
    from mtpg.envs.tasks import TASK_PARAMS

    seeds = make_test_seeds() if seeds is None else np.asarray(seeds)
    starts, _ = make_episodes(np.full(seeds.shape[0], CARTCENTERING), seeds)
    returns, steps, captured = run_time_optimal(TASK_PARAMS, starts)
    return float(returns.mean()), float(steps.mean()), int(captured.sum())


#: One entry per task id, from the registry (each spec's ``reference``, with its source
#: in ``mtpg.envs.registry``). ``random`` / ``random_std``: measured by this project with
#: ``measure_random(task)`` (10,000 episodes, conventions in the module docstring).
#: Re-measured by ``tests/envs/test_reference.py`` (slow).
REFERENCE: tuple[Reference, ...] = tuple(t.reference for t in TASKS)


_MEASURED: dict[str, tuple[float, float]] = {}
_GIVEN: dict[str, GivenReference] = {}


class GivenReference(NamedTuple):
    """Reference scores of a variant given by the user, with their source.

    Attributes:
        task: The variant's canonical name.
        best: The reference best score (Fig. 6 normalisation).
        source: Where ``best`` comes from (a paper, a leaderboard, a measurement).
        random: The random agent's mean score, or None to measure it on demand.
    """

    task: str
    best: float
    source: str
    random: float | None = None

    def text(self) -> str:
        """The entry as ``evaluation.references`` holds it (:func:`parse_given`)."""
        random = "" if self.random is None else f", random={self.random!r}"
        return f"{self.task}: best={self.best!r}{random}, source={self.source}"


def parse_given(text: str) -> GivenReference:
    """Reads one entry of ``evaluation.references``.

    The entry is ``"TASK: best=NUMBER[, random=NUMBER], source=TEXT"``; ``source`` comes
    last and takes the rest of the entry (commas included). ``TASK`` must be a variant
    spelled canonically: a registered task's reference scores are the registry's.

    Raises:
        ValueError: One line naming the fault.
    """
    from mtpg.envs.variants import canonical, is_variant

    task, sep, rest = (s.strip() for s in text.partition(":"))
    if not sep or not task:
        raise ValueError(f"{text!r}: write TASK: best=NUMBER[, random=NUMBER], source=TEXT")
    if not is_variant(task):
        raise ValueError(f"{task}: a registered task's reference scores are the registry's")
    if canonical(task) != task:
        raise ValueError(f"{task}: spell it {canonical(task)!r}")
    head, sep, source = rest.partition("source=")
    if not sep or not source.strip():
        raise ValueError(f"{task}: needs source=TEXT (where the best score comes from), last")
    values: dict[str, float] = {}
    for item in filter(None, (i.strip() for i in head.split(","))):
        key, eq, raw = (s.strip() for s in item.partition("="))
        if key not in ("best", "random") or not eq:
            raise ValueError(f"{task}: unknown setting {item!r}; allowed: best, random, source")
        if key in values:
            raise ValueError(f"{task}: {key} given twice")
        try:
            values[key] = float(raw)
        except ValueError:
            raise ValueError(f"{task}: {key}: {raw!r} is not a number") from None
        if not np.isfinite(values[key]):
            raise ValueError(f"{task}: {key}: must be finite, got {raw!r}")
    if "best" not in values:
        raise ValueError(f"{task}: needs best=NUMBER")
    if values["best"] == values.get("random"):
        raise ValueError(f"{task}: best equals random; nothing could be normalised")
    return GivenReference(task, values["best"], source.strip(), values.get("random"))


def give_reference(given: GivenReference) -> None:
    """Uses ``given`` as the reference scores of its variant in this process.

    Like variant ids, given references are process-wide, by task name: every run of the
    variant analysed in the process is normalised by them. Giving the same entry again is
    harmless; a different one for the same variant is refused, so two runs never mix.

    Raises:
        ValueError: If the variant already has different given reference scores.
    """
    held = _GIVEN.get(given.task)
    if held is not None and held != given:
        raise ValueError(
            f"{given.task}: reference scores already given differently in this process "
            f"({held.text()!r})"
        )
    _GIVEN[given.task] = given


def reference_of(task: int | str) -> Reference:
    """The reference scores of a task or variant.

    A registered task's are its spec's. A variant's ``best`` is the one given by the user
    (:func:`give_reference`, ``evaluation.references``) with its source, or else the base
    task's reference best, with the source saying so (the variant's own best is not
    known; a changed time limit may allow more). Its ``random`` / ``random_std`` are the
    given ``random`` (standard deviation unknown: NaN) or else measured by
    :func:`measure_random` on the variant itself (its own dynamics and time limit) on
    first use in the process, and kept.

    Args:
        task: A task id or name.
    """
    from mtpg.envs.variants import resolve, spec_of

    spec = spec_of(resolve(task) if isinstance(task, str) else int(task))
    if not spec.base:
        return spec.reference
    given = _GIVEN.get(spec.name)
    if given is not None and given.random is not None:
        random = (given.random, NONE)
    else:
        if spec.name not in _MEASURED:
            _MEASURED[spec.name] = measure_random(resolve(spec.name))
        random = _MEASURED[spec.name]
    how = "random given" if given is not None and given.random is not None else "random measured"
    if given is not None:
        return Reference(*random, given.best, NONE, f"{how}; best given: {given.source}")
    base = spec_of(spec.base).reference
    return Reference(*random, base.best, base.solved, f"{how}; best of {spec.base}: {base.source}")


def normalise(
    task: int, score: float | np.ndarray, best: float | None = None
) -> float | np.ndarray:
    """Normalises a score: ``(score - random) / (best - random)``.

    Args:
        task: The task id.
        score: A score, or an array of scores.
        best: The best score to normalise against (e.g. the best single-task agent of the
            run, Figs. 5 and 7); the reference best (Fig. 6) when None.

    Returns:
        0 for random play, 1 for ``best``; same shape as ``score``.

    Raises:
        ValueError: If ``best`` equals the random score.
    """
    from mtpg.envs.variants import spec_of

    ref = reference_of(int(task))
    top = ref.best if best is None else float(best)
    span = top - ref.random
    if span == 0:
        raise ValueError(f"best equals the random score of {spec_of(int(task)).name}")
    if isinstance(score, np.ndarray):
        return (score - ref.random) / span
    return (float(score) - ref.random) / span
