"""Why Pendulum and CartCentering lag in TPG-robust: the audit of issue 52, item 3.

One command, from the repository root with the project's environment::

    .venv/bin/mtpg report --results results --page robust-audit

For each run ``results/runs/TPG-robust-seed*`` at its final generation, deterministically,
on the held-out episodes (:func:`mtpg.envs.taskset.episode_seeds.held_out_seeds`): (a) the
failure modes of the all-task champion (:func:`mtpg.analysis.runs.champions.run_champion`)
traced step by step (:func:`mtpg.engine.trace.trace_episode`); (b) slopes over the last
200 generations of ``metrics.csv`` and ``tests.csv``; (c) near-clones among the top 25
roots of the checkpoint; (d) every root of the checkpoint on the lagging tasks; (e) the
noise of a training score. It writes the tables between the markers of
``docs/robust-audit.md`` (:mod:`~mtpg.analysis.results.audit_page`; the prose around them is
written by hand) and writes nothing into the runs. The definitions are the constants below.
"""

from __future__ import annotations

import csv
from dataclasses import dataclass
from pathlib import Path

import numpy as np

#: The page, in ``docs/`` beside the results folder, and the command its block names.
PAGE = "robust-audit.md"
COMMAND = ".venv/bin/mtpg report --results results --page robust-audit"
BEGIN, END = "<!-- audit:begin -->", "<!-- audit:end -->"
#: Pendulum is *upright* when ``|wrapped theta| <= UPRIGHT`` rad (about 17 degrees).
UPRIGHT = 0.3
#: A Pendulum episode is *balanced* when upright at each of its last ``HOLD`` steps.
HOLD = 50
#: Generations of the slope window (the last ones of the run, both ends included).
WINDOW = 200
#: Roots ranked for the near-clone count, and the Jaccard similarity of the reachable
#: program sets (program ids) from which two roots are near-clones.
TOP, CLONE = 25, 0.9
#: The two lagging tasks of the oracle (d).
WORST = ("CartCentering", "Pendulum")
#: Test-point offset of the re-scoring block of (d) (the page's re-score uses it too).
CONFIRM_OFFSET = 500_000


@dataclass(frozen=True)
class Slope:
    """A least-squares slope per 100 generations and its 95% half-width (1.96 SE)."""

    raw: float
    norm: float
    half: float  # of ``norm``

    def text(self) -> str:
        """``+0.012 ± 0.004`` (normalised per 100 generations)."""
        return f"{self.norm:+.3f} ± {self.half:.3f}"


def slope(gens: np.ndarray, values: np.ndarray, span: float) -> Slope:
    """Least-squares slope of ``values`` over ``gens``, per 100 generations.

    Args:
        gens: Generations.
        values: Raw scores, one per generation.
        span: ``best - random`` of the task (the normalised slope is ``raw / span``).

    Returns:
        The slope in raw units and in reference-normalised units, with the half-width of
        the normalised slope's 95% interval (OLS standard error; the points are
        autocorrelated, so the interval is too narrow rather than too wide).
    """
    x, y = np.asarray(gens, float), np.asarray(values, float)
    (b, a), cov = np.polyfit(x, y, 1, cov="unscaled")
    resid = y - (a + b * x)
    se = float(np.sqrt(cov[0, 0] * resid @ resid / max(len(x) - 2, 1)))
    return Slope(float(100 * b), float(100 * b / span), 1.96 * 100 * se / abs(span))


def slopes(run_dir: Path, window: int = WINDOW) -> dict[str, tuple[Slope, Slope]]:
    """Per task: slope of the best training score and of the all-task champion's test score."""
    from mtpg.analysis.runs.loading import load_run
    from mtpg.envs.taskset.reference_scores import reference_of

    run = load_run(run_dir)
    with open(run_dir / "metrics.csv", encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    last = run.final_generation
    out = {}
    for task in run.tasks:
        ref = reference_of(task, run.task_table)
        span = ref.best - ref.random
        m = [(int(r["generation"]), float(r[f"best_{task}"])) for r in rows]
        m = np.array([p for p in m if p[0] >= last - window])
        g, v = run.curve(run.full_set, task)
        keep = g >= last - window
        out[task] = (slope(m[:, 0], m[:, 1], span), slope(g[keep], v[keep], span))
    return out


def trace_states(pop, root: int, task: str, table, episodes: int) -> list[tuple[np.ndarray, float]]:
    """``(states, return)`` of each of the first ``episodes`` held-out test episodes.

    ``states``: the task state before each step and after the last
    (:attr:`mtpg.engine.trace.Trace.states`).
    """
    from mtpg.engine.compile import compile_population
    from mtpg.engine.trace import trace_episode
    from mtpg.envs.taskset.episode_seeds import held_out_seeds
    from mtpg.envs.taskset.episodes import draw_episodes

    cp = compile_population(pop, fold_constants=False)
    tid = table.id_of(task)
    seeds = held_out_seeds(episodes)
    starts, noise, obs_noise = draw_episodes(np.full(episodes, tid), seeds, table)
    out = []
    for e in range(episodes):
        extra = obs_noise[e] if obs_noise.shape[1] else None
        tr = trace_episode(cp, root, tid, starts[e], noise[e], obs_noise=extra, params=table.params)
        out.append((tr.states, float(tr.rewards.sum())))
    return out


def pendulum_modes(traced: list) -> dict[str, float]:
    """Swing-up reached (ever upright), balanced at the end, lost; time upright; turns.

    ``swing_up``: mean steps before a balanced episode stays upright to its end.
    """
    from mtpg.envs.dynamics.pendulum import angle_normalize

    n = len(traced)
    reached = balanced = 0
    upright = turns = 0.0
    swing: list[int] = []
    ret = {"never": 0.0, "lost": 0.0, "balanced": 0.0}
    for states, r in traced:
        theta = np.array([angle_normalize(t) for t in states[1:, 0]])
        up = np.abs(theta) <= UPRIGHT
        held = bool(up[-HOLD:].all())
        reached += bool(up.any())
        balanced += held
        if held:
            swing.append(len(up) - int(np.argmin(up[::-1])) if not up.all() else 0)
        upright += float(up.mean()) / n
        turns += float(abs(states[-1, 0] - states[0, 0])) / (2 * np.pi) / n
        ret["balanced" if held else "lost" if up.any() else "never"] += r / n
    return {
        "reached": reached, "balanced": balanced, "upright": upright, "turns": turns,
        "episodes": n, "swing_up": float(np.mean(swing)) if swing else float("nan"),
        **{f"ret_{k}": v for k, v in ret.items()},
    }  # fmt: skip


def cartcentering_modes(traced: list, starts_x: np.ndarray) -> dict[str, float]:
    """Captured, off the track (left / right, on the start's side), time limit; steps."""
    from mtpg.envs.dynamics.cartcentering import PARAMS, X_BOUND, is_captured

    n = len(traced)
    out = dict.fromkeys(("captured", "left", "right", "start_side", "timeout"), 0)
    ret = dict.fromkeys(("captured", "off", "timeout"), 0.0)
    cap_steps = []
    for (states, r), x0 in zip(traced, starts_x, strict=True):
        x, v, steps = states[-1, 0], states[-1, 1], len(states) - 1
        if is_captured(x, v):
            out["captured"] += 1
            cap_steps.append(steps)
            ret["captured"] += r / n
        elif abs(x) > PARAMS[X_BOUND]:
            out["left" if x < 0 else "right"] += 1
            out["start_side"] += bool(np.sign(x) == np.sign(x0))
            ret["off"] += r / n
        else:
            out["timeout"] += 1
            ret["timeout"] += r / n
    steps = float(np.mean(cap_steps)) if cap_steps else float("nan")
    return out | {"episodes": n, "capture_steps": steps} | {f"ret_{k}": v for k, v in ret.items()}


def other_modes(played, table) -> dict[str, str]:
    """One line per task other than ``WORST``, from the champion's test returns and steps."""
    out = {}
    for k, task in enumerate(table.names):
        if task in WORST:
            continue
        ret, steps = played.returns[0, k], played.steps[0, k]
        limit = int(table.spec(task).max_steps)
        if task == "CartPole":
            out[task] = (
                f"{steps.mean():.0f} steps balanced, {int((steps >= limit).sum())} at {limit}"
            )
        elif task == "Acrobot":  # -1 a step, 0 on the step that reaches the goal
            ok = int((ret > -steps).sum())
            out[task] = f"goal in {ok}, mean {steps.mean():.0f} steps"
        else:
            ok = int((steps < limit).sum())
            out[task] = f"goal in {ok} before step {limit}, mean {steps.mean():.0f} steps"
    return out


def noise(played, train: np.ndarray, table, n_train: int) -> dict[str, tuple[float, ...]]:
    """Per task: the champion's training and test score and the noise of a training score.

    Returns:
        ``(training, test, se)`` reference-normalised: its score on its last training
        block (the one selection used), its mean over the test episodes, and the standard
        error of a mean over ``n_train`` episodes (the test episodes' standard deviation
        / sqrt(n_train)).
    """
    from mtpg.envs.taskset.reference_scores import normalise

    out = {}
    for k, task in enumerate(table.names):
        ret = normalise(task, played.returns[0, k], table=table)
        se = float(np.std(ret)) / np.sqrt(n_train)
        out[task] = (float(normalise(task, train[k], table=table)), float(ret.mean()), se)
    return out


def reachable_programs(pop, root: int) -> frozenset[int]:
    """Ids of every program of every team reachable from ``root``."""
    return frozenset(p for t in pop.reachable(root) for p in pop.teams[t].programs)


def top_roots(state, k: int = TOP) -> tuple[list[int], int]:
    """The ``k`` best roots by the all-task selection score, best first; the champion's rank.

    The score is selection's (:func:`mtpg.evolve.selection.rankings`: the minimum over
    tasks of the min-max normalised training score), recomputed over the checkpoint's
    surviving roots. The children deleted at that generation are not in the checkpoint
    and lowered the minima selection used, so the recomputed order differs from the
    run's: the run's champion (``state.champions[-1]``, first in the run's order) is put
    first and the other ``k - 1`` follow in the recomputed order.

    Returns:
        The roots, and the champion's rank in the recomputed order (1 = first).
    """
    from mtpg.evolve.selection import rankings

    ids = np.array(sorted(state.scores), dtype=np.int64)
    scores = np.array([state.scores[int(r)] for r in ids])
    order = [int(ids[i]) for i in rankings(ids, scores, [tuple(range(scores.shape[1]))])[0]]
    champion = state.champions[-1]
    rest = [r for r in order if r != champion]
    return [champion, *rest[: k - 1]], order.index(champion) + 1


def clones(pop, roots: list[int]) -> dict[str, float]:
    """Near-clones among ``roots``, the champion first (Jaccard of program sets >= ``CLONE``).

    ``identical`` / ``near``: other roots whose set equals / is a near-clone of the
    champion's; ``groups``: roots grouped greedily in rank order (a root joins the first
    earlier leader it is a near-clone of), so ``len(roots) - groups`` roots are
    near-clones of a better-ranked one; ``median_pair``: median Jaccard over all pairs.
    """
    champion = roots[0]
    sets = {r: reachable_programs(pop, r) for r in roots}

    def jac(a: int, b: int) -> float:
        return len(sets[a] & sets[b]) / len(sets[a] | sets[b])

    leaders: list[int] = []
    for r in roots:  # greedy groups in rank order: a root joins the first leader near it
        if not any(jac(r, lead) >= CLONE for lead in leaders):
            leaders.append(r)
    pairs = [jac(a, b) for i, a in enumerate(roots) for b in roots[i + 1 :]]
    return {
        "identical": sum(sets[r] == sets[champion] for r in roots[1:]),
        "near": sum(jac(r, champion) >= CLONE for r in roots[1:]),
        "groups": len(leaders),
        "median_pair": float(np.median(pairs)) if pairs else float("nan"),
    }


def oracle(state, table, top: list[int], episodes: int, threads: int = 1) -> dict[str, dict]:
    """Every root on ``episodes`` held-out episodes of each lagging task; best vs champion.

    For each task: the champion (``top[0]``), the best root of the population and the
    best other root of ``top`` on those episodes, the three re-scored on 100 other
    held-out episodes of every task (offset ``CONFIRM_OFFSET``). ``"clones"``: roots of
    ``top`` whose returns equal the champion's on every episode played here.
    """
    from mtpg.engine.batch import Episodes, evaluate_roots
    from mtpg.engine.compile import compile_population
    from mtpg.envs.taskset.episode_seeds import held_out_seeds
    from mtpg.envs.taskset.reference_scores import normalise

    cp = compile_population(state.population, no_memory=state.config.evaluation.no_memory)
    roots = sorted(state.scores)
    where = {r: i for i, r in enumerate(roots)}
    names = [t for t in WORST if t in table.names]
    grid = Episodes.grid([table.id_of(t) for t in names], held_out_seeds(episodes), table)
    returns, _ = evaluate_roots(cp, roots, grid, threads)
    means = returns.reshape(len(roots), len(names), episodes).mean(axis=2)
    confirm = Episodes.grid(list(table.ids), held_out_seeds(100, CONFIRM_OFFSET), table)
    champion, pool = top[0], [where[r] for r in top[1:]]
    same = sum(np.array_equal(returns[where[r]], returns[where[champion]]) for r in top[1:])
    out: dict[str, dict] = {"clones": {"same_returns": int(same)}}
    for k, task in enumerate(names):
        scores = normalise(task, means[:, k], table=table)
        best, best_top = int(np.argmax(scores)), pool[int(np.argmax(scores[pool]))]
        again, _ = evaluate_roots(cp, [champion, roots[best], roots[best_top]], confirm, threads)
        norm = np.array(
            [normalise(t, again[:, i * 100 : (i + 1) * 100].mean(axis=1), table=table)
             for i, t in enumerate(table.names)]
        )  # fmt: skip
        j = table.names.index(task)
        champ = float(scores[where[champion]])
        out[task] = {
            "roots": len(roots), "champion": champ, "best": float(scores[best]),
            "better": int((scores > champ).sum()), "top": float(scores[best_top]),
            "confirm": [float(x) for x in norm[j]], "min6": [float(x) for x in norm.min(axis=0)],
        }  # fmt: skip
    return out


def audit_run(
    run_dir: Path, episodes: int = 100, oracle_episodes: int = 20, threads: int = 1
) -> dict[str, object]:
    """Every measurement of one run: ``{"a": ..., "b": ..., "c": ..., "d": ..., "e": ...}``.

    Raises:
        ValueError: When the run has no test results, its checkpoint's champion is not
            the tested graph, or the replayed scores are not those ``tests.csv`` holds.
    """
    from mtpg.analysis.runs.champions import run_champion, tested_run
    from mtpg.envs.taskset.episode_seeds import held_out_seeds
    from mtpg.envs.taskset.episodes import draw_episodes
    from mtpg.envs.taskset.reference_scores import measure_time_optimal_cartcentering, normalise
    from mtpg.evolve.heldout_test import play_test
    from mtpg.evolve.persist import state_from_payload
    from mtpg.io.checkpoint import checkpoint_path, load_checkpoint
    from mtpg.io.serialize import load_graph

    run = tested_run(run_dir)
    if run is None:
        raise ValueError(f"{run_dir}: no test results")
    gen, table = run.final_generation, run.task_table
    pop, root, meta = load_graph(run_champion(run_dir))
    state, _ = state_from_payload(load_checkpoint(checkpoint_path(run_dir, gen)))
    if state.champions[-1] != root:
        raise ValueError(f"{run_dir}: the checkpoint's champion is not the tested one")
    played = play_test(pop, [root], list(table.ids), episodes, table=table)
    tested = run.row(run.full_set)
    for k, task in enumerate(table.names):
        mean = float(played.returns[0, k].mean())
        if episodes == run.test_episodes and not np.isclose(mean, tested[f"test_{task}"]):
            raise ValueError(f"{run_dir}: {task}: mean {mean} is not the tested one")
    a: dict[str, object] = {"other": other_modes(played, table)}
    for task in WORST:
        traced = trace_states(pop, root, task, table, episodes)
        mean = float(np.mean([r for _, r in traced]))
        if not np.allclose([r for _, r in traced], played.returns[0, table.names.index(task)]):
            raise ValueError(f"{run_dir}: the traced {task} returns are not the played ones")
        if task == "Pendulum":
            a[task] = pendulum_modes(traced)
        else:
            seeds = held_out_seeds(episodes)
            starts, _, _ = draw_episodes(np.full(episodes, table.id_of(task)), seeds, table)
            a[task] = cartcentering_modes(traced, starts[:, 0])
            a[task]["optimal_steps"] = measure_time_optimal_cartcentering(seeds)[1]
        a[task]["mean"] = mean
        a[task]["norm"] = float(normalise(task, mean, table=table))
    top, rank = top_roots(state)
    d = oracle(state, table, top, oracle_episodes, threads)
    c = clones(state.population, top) | d.pop("clones") | {"champion_rank": rank}
    n_train = state.config.evaluation.train_episodes
    e = noise(played, state.scores[root], table, n_train)
    out = {"generation": gen, "train_episodes": n_train, "a": a, "b": slopes(run_dir)}
    return out | {"c": c, "d": d, "e": e}


def write_doc(doc: Path, block: list[str]) -> None:
    """Replaces the block between the markers of ``doc`` (creating the page if missing)."""
    text = doc.read_text(encoding="utf-8") if doc.is_file() else f"# Audit\n\n{BEGIN}\n{END}\n"
    head, rest = text.split(BEGIN, 1)
    tail = rest.split(END, 1)[1]
    doc.write_text(head + BEGIN + "\n" + "\n".join(block) + "\n" + END + tail, encoding="utf-8")
