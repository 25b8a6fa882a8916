"""Aggregate statistics over runs: interquartile mean, stratified bootstrap CIs, profiles.

The definitions are those of Agarwal et al., *Deep Reinforcement Learning at the Edge of the
Statistical Precipice* (NeurIPS 2021) and their ``rliable`` library, computed with SciPy:

- **IQM** (interquartile mean): ``scipy.stats.trim_mean(scores, 0.25)`` over all entries
  of the (runs x tasks) score matrix, i.e. the mean of the middle 50% after discarding
  ``floor(0.25 n)`` entries at each end (``rliable.metrics.aggregate_iqm`` exactly).
- **95% stratified bootstrap confidence interval**: each task is a stratum; a bootstrap
  sample redraws, with replacement, as many runs as there are within every task
  independently; the interval is the 2.5th and 97.5th percentile of the statistic over the
  resamples (``scipy.stats.bootstrap`` with one sample per task, ``paired=False``,
  ``method="percentile"``, as rliable's default).
- **Performance profile**: the fraction of (run, task) scores above each threshold tau,
  with a stratified bootstrap band at each tau.
- **Probability of improvement** of group X over group Y: the chance that a run of X
  scores higher than a run of Y on a task, ties counting one half, averaged over tasks:
  ``mean_t mean_{i,j} S(x_it, y_jt)`` with ``S = 1, 0.5, 0`` for ``>, =, <`` (the
  Mann-Whitney U statistic over ``n m`` per task; ``rliable.metrics.probability_of_improvement``).
  Its interval resamples the runs of both groups within every task independently.

SciPy rather than ``rliable`` itself: rliable needs ``arch``, ``pandas``, ``seaborn`` and
``absl-py`` for the three functions used here, while SciPy's bootstrap is well kept and
implements the same resampling; the definitions above are rliable's, so numbers agree.

A score matrix with fewer than two runs has no interval: the bounds are NaN and the
figures and tables say "n/a".
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Confidence level of every interval.
CONFIDENCE = 0.95
#: Bootstrap resamples (rliable uses 50,000 for aggregates, 2,000 for profiles).
N_RESAMPLES = 20_000
#: Resamples per threshold of a performance profile.
N_RESAMPLES_PROFILE = 2_000
#: Seed of the bootstrap generator, so a report is reproducible.
BOOTSTRAP_SEED = 0


@dataclass(frozen=True)
class Estimate:
    """A point estimate with its confidence interval.

    Attributes:
        value: The statistic on the observed scores.
        low: Lower bound of the 95% interval (NaN with fewer than two runs).
        high: Upper bound of the 95% interval (NaN with fewer than two runs).
        runs: Number of runs behind it.
    """

    value: float
    low: float
    high: float
    runs: int

    def text(self, digits: int = 2) -> str:
        """``"0.53 [0.41, 0.66]"``, or ``"0.53 [n/a: 1 run]"``."""
        if np.isnan(self.low):
            return f"{self.value:.{digits}f} [n/a: {self.runs} run]"
        return f"{self.value:.{digits}f} [{self.low:.{digits}f}, {self.high:.{digits}f}]"


def iqm(scores: np.ndarray) -> float:
    """Interquartile mean of all entries (``scipy.stats.trim_mean(x, 0.25)``)."""
    from scipy.stats import trim_mean

    return float(trim_mean(np.asarray(scores, dtype=float), 0.25, axis=None))


def _check(scores: np.ndarray) -> np.ndarray:
    scores = np.asarray(scores, dtype=float)
    if scores.ndim != 2 or scores.size == 0:
        raise ValueError(f"scores must be a non-empty (runs x tasks) matrix, got {scores.shape}")
    if not np.isfinite(scores).all():
        raise ValueError("scores must be finite (normalise against the reference best)")
    return scores


def _bootstrap(scores: np.ndarray, statistic, n_resamples: int, seed: int) -> tuple[float, float]:
    """Stratified bootstrap percentile interval of ``statistic(matrix)`` (strata = columns)."""
    from scipy.stats import bootstrap

    if scores.shape[0] < 2:
        return float("nan"), float("nan")

    def stat(*columns: np.ndarray, axis: int = -1) -> np.ndarray:
        return statistic(np.stack(columns, axis=-1))

    res = bootstrap(
        tuple(scores.T),
        stat,
        n_resamples=n_resamples,
        confidence_level=CONFIDENCE,
        method="percentile",
        paired=False,
        vectorized=True,
        rng=np.random.default_rng(seed),
    )
    return float(res.confidence_interval.low), float(res.confidence_interval.high)


def _iqm_rows(matrix: np.ndarray) -> np.ndarray:
    """IQM of the trailing (runs x tasks) axes of a batch of matrices."""
    from scipy.stats import trim_mean

    flat = matrix.reshape(*matrix.shape[:-2], -1)
    return trim_mean(flat, 0.25, axis=-1)


def aggregate_iqm(
    scores: np.ndarray, n_resamples: int = N_RESAMPLES, seed: int = BOOTSTRAP_SEED
) -> Estimate:
    """IQM over all runs and tasks with a 95% stratified bootstrap interval.

    Args:
        scores: (runs x tasks) normalised scores.
        n_resamples: Bootstrap resamples.
        seed: Seed of the bootstrap generator.

    Returns:
        The estimate.
    """
    scores = _check(scores)
    low, high = _bootstrap(scores, _iqm_rows, n_resamples, seed)
    return Estimate(iqm(scores), low, high, scores.shape[0])


def per_task_iqm(
    scores: np.ndarray, n_resamples: int = N_RESAMPLES, seed: int = BOOTSTRAP_SEED
) -> list[Estimate]:
    """IQM over runs of each task (column) with a 95% bootstrap interval over runs."""
    scores = _check(scores)
    return [aggregate_iqm(scores[:, [k]], n_resamples, seed) for k in range(scores.shape[1])]


def performance_profile(
    scores: np.ndarray,
    taus: np.ndarray,
    n_resamples: int = N_RESAMPLES_PROFILE,
    seed: int = BOOTSTRAP_SEED,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Fraction of (run, task) scores above each threshold, with 95% stratified bands.

    Args:
        scores: (runs x tasks) normalised scores.
        taus: Thresholds.
        n_resamples: Bootstrap resamples per threshold.
        seed: Seed of the bootstrap generator.

    Returns:
        ``(fraction, low, high)``, each of the shape of ``taus`` (bands NaN with one run).
    """
    scores = _check(scores)
    taus = np.asarray(taus, dtype=float)
    frac = np.array([np.mean(scores > t) for t in taus])
    low = np.full(taus.shape, np.nan)
    high = np.full(taus.shape, np.nan)
    for k, tau in enumerate(taus):

        def above(matrix: np.ndarray, tau: float = tau) -> np.ndarray:
            return (matrix > tau).mean(axis=(-2, -1))

        low[k], high[k] = _bootstrap(scores, above, n_resamples, seed)
    return frac, low, high


def _improvement(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Probability of improvement of batches of (runs x tasks) matrices ``x`` over ``y``."""
    wins = x[..., :, None, :] > y[..., None, :, :]
    ties = x[..., :, None, :] == y[..., None, :, :]
    per_task = (wins + 0.5 * ties).mean(axis=(-3, -2))
    return per_task.mean(axis=-1)


def probability_of_improvement(
    x: np.ndarray, y: np.ndarray, n_resamples: int = N_RESAMPLES, seed: int = BOOTSTRAP_SEED
) -> Estimate:
    """P(X > Y): how often a run of group X beats a run of group Y on a task, over tasks.

    Args:
        x: (runs x tasks) scores of group X.
        y: (runs x tasks) scores of group Y, on the same tasks.
        n_resamples: Bootstrap resamples.
        seed: Seed of the bootstrap generator.

    Returns:
        The estimate (0.5: neither better), with a 95% stratified bootstrap percentile
        interval: every resample redraws, with replacement, the runs of each group within
        every task independently (rliable's ``StratifiedIndependentBootstrap``). A group of
        one run is redrawn as itself; with one run in both groups there is no interval.
        ``runs`` is the larger group's size.
    """
    x, y = _check(x), _check(y)
    if x.shape[1] != y.shape[1]:
        raise ValueError(f"the groups have {x.shape[1]} and {y.shape[1]} tasks")
    value = float(_improvement(x, y))
    runs = max(x.shape[0], y.shape[0])
    if runs < 2:
        return Estimate(value, float("nan"), float("nan"), runs)
    rng = np.random.default_rng(seed)
    stats = np.empty(n_resamples)
    tasks = np.arange(x.shape[1])
    for start in range(0, n_resamples, 2_000):  # in blocks: bounded memory
        b = min(2_000, n_resamples - start)
        ix = rng.integers(0, x.shape[0], size=(b, x.shape[0], x.shape[1]))
        iy = rng.integers(0, y.shape[0], size=(b, y.shape[0], y.shape[1]))
        stats[start : start + b] = _improvement(x[ix, tasks], y[iy, tasks])
    low, high = np.percentile(stats, [50 * (1 - CONFIDENCE), 50 * (1 + CONFIDENCE)])
    return Estimate(value, float(low), float(high), runs)
