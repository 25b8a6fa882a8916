"""The tables of ``docs/robust-audit.md``, from the measurements of :mod:`.audit`, and the page.

:func:`render` turns ``{run name: audit_run(...)}`` into the Markdown block the page holds
between its markers; it computes nothing but formats.
"""

from __future__ import annotations

import logging
from pathlib import Path

from mtpg.analysis.results.audit import (
    CLONE,
    COMMAND,
    CONFIRM_OFFSET,
    HOLD,
    PAGE,
    TOP,
    UPRIGHT,
    WINDOW,
    audit_run,
    write_doc,
)
from mtpg.analysis.results.audit_trial import write_trial

_LOG = logging.getLogger(__name__)


def table_lines(head: list[str], rows: list[list[str]]) -> list[str]:
    """A Markdown table."""
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    return lines + ["| " + " | ".join(r) + " |" for r in rows]


def failure_modes(audits: dict[str, dict], episodes: int) -> list[str]:
    """Section (a): Pendulum, CartCentering and a line for each other task."""
    out = [f"### (a) Failure modes of the all-task champion, {episodes} held-out test episodes", ""]
    out += [
        f"Pendulum: *upright* = |wrapped theta| <= {UPRIGHT} rad; *reached* = upright at some "
        f"step; *balanced* = upright at each of the last {HOLD} of 200 steps; *swing-up*: mean "
        "steps before a balanced episode stays upright to its end; *turns*: mean |net rotation| "
        "/ 2 pi. Return share: the mean return split by outcome (the three add up to the mean).",
        "",
    ]
    rows = []
    for name, au in audits.items():
        p = au["a"]["Pendulum"]
        rows.append([
            name, f"{p['mean']:.0f} ({p['norm']:.2f})", str(p["reached"]), str(p["balanced"]),
            str(p["reached"] - p["balanced"]), str(p["episodes"] - p["reached"]),
            f"{p['upright']:.2f}", f"{p['swing_up']:.0f}", f"{p['turns']:.1f}",
            f"{p['ret_balanced']:.0f} / {p['ret_lost']:.0f} / {p['ret_never']:.0f}",
        ])  # fmt: skip
    out += table_lines(
        ["run", "return (norm.)", "reached", "balanced", "reached, lost", "never reached",
         "steps upright", "swing-up", "turns", "return share: balanced / lost / never"], rows,
    )  # fmt: skip
    out += [
        "",
        "CartCentering: how each episode ends (|x| > 1.5 m: off the track, left x < 0, right "
        "x > 0; *start side*: off on the side it started on; *time limit*: neither captured nor "
        "off after 500 steps); capture time: mean steps of the captured episodes (in brackets: "
        "the time-optimal law on the same episodes, every one captured).",
        "",
    ]
    rows = []
    for name, au in audits.items():
        c = au["a"]["CartCentering"]
        rows.append([
            name, f"{c['mean']:.3f} ({c['norm']:.2f})", str(c["captured"]),
            f"{c['left']} / {c['right']}", str(c["start_side"]), str(c["timeout"]),
            f"{c['capture_steps']:.0f} ({c['optimal_steps']:.0f})",
            f"{c['ret_captured']:.3f} / {c['ret_off']:.3f} / {c['ret_timeout']:.3f}",
        ])  # fmt: skip
    out += table_lines(
        ["run", "return (norm.)", "captured", "off track left / right", "off on start side",
         "time limit", "capture steps", "return share: captured / off / time limit"], rows,
    )  # fmt: skip
    others = list(next(iter(audits.values()))["a"]["other"])
    out += ["", "The other tasks, from the same test's returns and steps:", ""]
    return out + table_lines(
        ["run", *others], [[k, *au["a"]["other"].values()] for k, au in audits.items()]
    )


def rising(audits: dict[str, dict]) -> list[str]:
    """Section (b): the slopes, train / test, per run and task."""
    out = [f"### (b) Still rising? Slopes over the last {WINDOW} generations", ""]
    out += [
        "Least-squares slope in reference-normalised score per 100 generations (in raw return: "
        "times best - random of the task), ± 1.96 standard errors (the points are "
        "autocorrelated, so the interval is too narrow rather than too wide). *train*: "
        "`best_TASK` of `metrics.csv`, the best root's training score on that task, every "
        "generation (its episodes are redrawn every 10); *test*: the all-task champion's test "
        f"score in `tests.csv`, every 5 generations. Window: generations {WINDOW} before the "
        "last to the last, both included.",
        "",
    ]
    tasks = list(next(iter(audits.values()))["b"])
    rows = [
        [k, *(f"{s[0].text()} / {s[1].text()}" for s in au["b"].values())]
        for k, au in audits.items()
    ]
    return out + table_lines(["run: train / test", *tasks], rows)


def near_clones(audits: dict[str, dict], oracle_episodes: int) -> list[str]:
    """Section (c): near-clones among the top roots."""
    out = [f"### (c) Near-clones among the top {TOP} roots of the checkpoint", ""]
    out += [
        f"The champion and the next {TOP - 1} roots by the all-task selection score (the "
        "minimum over tasks of the min-max normalised training score), recomputed over the "
        "checkpoint's roots: the children deleted at that generation are not in it, so the "
        "champion's rank in the recomputed order is shown (1 = the run's own order). "
        "*Reachable program set*: the ids of the programs of every team reachable from the "
        f"root (a child shares its parent's programs until they mutate). *Near-clone*: Jaccard "
        f"similarity of the sets >= {CLONE}. *Groups*: roots grouped greedily in rank order, a "
        f"root joining the first better-ranked leader it is a near-clone of ({TOP} - groups "
        "roots are near-clones of a better one). *Same returns*: roots whose returns equal the "
        f"champion's on all 2 x {oracle_episodes} episodes of (d).",
        "",
    ]
    rows = [
        [k, str(c["champion_rank"]), str(c["identical"]), str(c["near"]), str(c["same_returns"]),
         str(c["groups"]), str(TOP - c["groups"]), f"{c['median_pair']:.2f}"]
        for k, c in ((k, au["c"]) for k, au in audits.items())
    ]  # fmt: skip
    return out + table_lines(
        ["run", "champion's recomputed rank", "same set as champion", "near-clones of champion",
         "same returns as champion", "groups", "near-clones of a better root",
         "median pairwise Jaccard"], rows,
    )  # fmt: skip


def oracle_table(audits: dict[str, dict], oracle_episodes: int) -> list[str]:
    """Section (d): the best root on each lagging task against the champion."""
    out = ["### (d) Is another root better on the lagging tasks?", ""]
    out += [
        f"Every root of the checkpoint on the first {oracle_episodes} held-out test episodes, "
        "normalised against the reference best (0 = random play). The best root of the "
        f"population (*best*) and the best other root of the top {TOP} of (c) (*top*) are "
        "chosen on those episodes, so their figures there are biased upward; *re-scored*: "
        "champion / best / top on 100 other held-out episodes (offset "
        f"{CONFIRM_OFFSET:,}), on the task and, in *min of 6*, on their worst task of six.",
        "",
    ]
    rows = []
    for k, au in audits.items():
        for task, d in au["d"].items():
            rows.append([
                k, task, str(d["roots"]), f"{d['champion']:.2f}", f"{d['best']:.2f}",
                f"{d['top']:.2f}", str(d["better"]),
                " / ".join(f"{x:.2f}" for x in d["confirm"]),
                " / ".join(f"{x:.2f}" for x in d["min6"]),
            ])  # fmt: skip
    return out + table_lines(
        ["run", "task", "roots", "champion", "best", "top", "roots above champion",
         "re-scored: champion / best / top", "min of 6: champion / best / top"], rows,
    )  # fmt: skip


def noise_table(audits: dict[str, dict], train_episodes: int) -> list[str]:
    """Section (e): how far a champion's training score is from its test score."""
    out = [f"### (e) How noisy is a {train_episodes}-episode training score?", ""]
    out += [
        "The all-task champion, normalised: *train*, its score on the last training block "
        f"({train_episodes} episodes, the score selection chose it by); *test*, on the 100 test "
        f"episodes; *SE*, the standard error of a {train_episodes}-episode mean (the test "
        f"episodes' standard deviation / sqrt({train_episodes})): train - test is the champion's "
        "luck on its block, SE how large that luck can be.",
        "",
    ]
    tasks = list(next(iter(audits.values()))["e"])
    rows = [
        [k, *(f"{tr:.2f} / {te:.2f} / {se:.2f}" for tr, te, se in au["e"].values())]
        for k, au in audits.items()
    ]
    return out + table_lines(["run: train / test / SE", *tasks], rows)


def render(
    audits: dict[str, dict], command: str, episodes: int, oracle_episodes: int, train: int
) -> list[str]:
    """The measured block of the page (the prose around it is written by hand)."""
    head = [
        f"Written by `{command}` (deterministic: it plays fixed held-out episodes and draws "
        "nothing random; it reads the runs and writes only this block).",
        "",
    ]
    return (
        head
        + failure_modes(audits, episodes)
        + [""]
        + rising(audits)
        + [""]
        + near_clones(audits, oracle_episodes)
        + [""]
        + oracle_table(audits, oracle_episodes)
        + [""]
        + noise_table(audits, train)
    )


def write(
    results: Path,
    out: Path | None = None,
    prefix: str = "TPG-robust-seed",
    episodes: int = 100,
    oracle_episodes: int = 20,
    threads: int = 1,
) -> Path:
    """Measures the runs and rewrites the block of ``docs/robust-audit.md``; its path.

    Args:
        results: The results folder (the page is ``docs/`` beside it).
        out: The results folder written to (default: ``results``; the page goes to
            ``docs/`` beside it).
        prefix: Run folder names start with it.
        episodes: Traced test episodes.
        oracle_episodes: Episodes of (d).
        threads: Numba threads.

    Raises:
        ValueError: No run folder starts with ``prefix``.
    """
    runs = sorted((results / "runs").glob(prefix + "*"), key=lambda p: p.name)
    if not runs:
        raise ValueError(f"no run folder {prefix}* in {results / 'runs'}")
    audits = {}
    for run in runs:
        audits[run.name] = audit_run(run, episodes, oracle_episodes, threads)
        _LOG.info(f"{run.name}: done")
    train = next(iter(audits.values()))["train_episodes"]
    block = render(audits, COMMAND, episodes, oracle_episodes, train)
    source = results.parent / "docs" / PAGE
    page = (results if out is None else out).parent / "docs" / PAGE
    page.parent.mkdir(parents=True, exist_ok=True)
    if source != page and source.is_file():
        page.write_text(source.read_text(encoding="utf-8"), encoding="utf-8")
    write_doc(page, block)
    write_trial(results, page)  # the demo-scale test of the recommendation, stored scores
    return page
