"""Measures how well champions hold up on unseen episodes, per training setting.

Every (scenario, setting, seed) is an ordinary ``mtpg train`` run in its own directory
``OUT/<scenario>/<setting>/seed<k>``; rerunning the command skips finished runs and resumes
unfinished ones (:mod:`mtpg.evolve.experiment`). Each run tests its final champions once, at
its last generation, on ``--test-episodes`` held-out episodes per task (seeds 1,000,000 +
k, never used by training, validation or any choice). Then the report::

    python tools/generalisation.py run --out results/generalisation
    python tools/generalisation.py report --out results/generalisation

Scenarios (``demo`` preset): ``cartpole`` and ``pendulum`` (one task, 5 seeds) and ``six``
(all six tasks, 3 seeds), 1,000 generations each. Settings: the paper's protocol and the
options beyond it (:data:`SETTINGS`). Scores are reference-normalised test scores of each
run's final champion (one task: the task's champion; six tasks: the all-task champion on
every task, and each single-task champion on its own task); the report gives their IQM with
a 95% stratified bootstrap interval over seeds (:mod:`mtpg.analysis.runs.statistics`, tasks as
strata) and the cost of each setting: decisions played (training and validation, summed
over the run) and the run's total wall time (``t_total`` summed, seconds).
"""

from __future__ import annotations

import argparse
import csv
import json
import sys
from dataclasses import dataclass
from pathlib import Path

#: Training settings compared: name -> ``--set`` overrides on top of the scenario.
SETTINGS: dict[str, list[str]] = {
    "paper": [],
    "validation": ["evaluation.validation_episodes=10", "evaluation.validation_top_k=5"],
    "resampling": ["evaluation.resample_interval=10"],
    "more-episodes": ["evaluation.train_episodes=9"],
    "lexicase": ["team.parent_selection=lexicase"],
    "combined": [
        "evaluation.validation_episodes=10",
        "evaluation.validation_top_k=5",
        "evaluation.resample_interval=10",
    ],
    "resampling-6ep": ["evaluation.resample_interval=10", "evaluation.train_episodes=6"],
    "combined-6ep": [
        "evaluation.validation_episodes=10",
        "evaluation.validation_top_k=5",
        "evaluation.resample_interval=10",
        "evaluation.train_episodes=6",
    ],
    "resampling-12ep": ["evaluation.resample_interval=10", "evaluation.train_episodes=12"],
    "resampling-20": ["evaluation.resample_interval=20"],
    "resampling-5": ["evaluation.resample_interval=5"],
    "resampling-1": ["evaluation.resample_interval=1"],
    "lexicase-resampling-6ep": [
        "team.parent_selection=lexicase",
        "evaluation.resample_interval=10",
        "evaluation.train_episodes=6",
    ],
    "resampling-mean": ["evaluation.resample_interval=10", "evaluation.resample_mean=true"],
    "resampling-mean-6ep": [
        "evaluation.resample_interval=10",
        "evaluation.resample_mean=true",
        "evaluation.train_episodes=6",
    ],
}


@dataclass(frozen=True)
class Scenario:
    """Tasks, seeds and generations of one comparison."""

    tasks: str
    seeds: int
    generations: int


SCENARIOS: dict[str, Scenario] = {
    "cartpole": Scenario("CartPole", 5, 1000),
    "pendulum": Scenario("Pendulum", 5, 1000),
    "six": Scenario(
        "CartPole,Acrobot,CartCentering,Pendulum,MountainCar,MountainCarContinuous", 3, 1000
    ),
}


def _parse(argv: list[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("command", choices=["run", "report"])
    parser.add_argument("--out", required=True, type=Path, help="measurement folder")
    parser.add_argument("--scenarios", default=",".join(SCENARIOS), help="comma-separated")
    parser.add_argument("--settings", default=",".join(SETTINGS), help="comma-separated")
    parser.add_argument("--seeds", type=int, help="seeds per scenario (default: its own)")
    parser.add_argument("--first-seed", type=int, default=0, help="first run seed (0)")
    parser.add_argument("--generations", type=int, help="generations (default: 1000)")
    parser.add_argument("--test-episodes", type=int, default=100, help="held-out episodes (100)")
    parser.add_argument("--preset", default="demo", help="configuration preset (demo)")
    parser.add_argument("--parallel", type=int, default=1, help="runs at the same time (1)")
    parser.add_argument("--workers", type=int, default=2, help="threads per run (2)")
    parser.add_argument(
        "--set", action="append", default=[], metavar="SECTION.FIELD=VALUE", help="for every run"
    )
    args = parser.parse_args(argv)
    for kind, known in (("scenarios", SCENARIOS), ("settings", SETTINGS)):
        names = getattr(args, kind).split(",")
        unknown = [n for n in names if n not in known]
        if unknown:
            parser.error(f"--{kind}: unknown {', '.join(unknown)}; choose from {', '.join(known)}")
        setattr(args, kind, names)
    return args


def _plan(args: argparse.Namespace):
    """``(scenario, setting, train_args, generations, runs)`` of every comparison cell."""
    from mtpg.evolve.experiment import PlannedRun

    cells = []
    for name in args.scenarios:
        sc = SCENARIOS[name]
        gens = args.generations or sc.generations
        seeds = args.seeds or sc.seeds
        for setting in args.settings:
            sets = [
                *args.set,
                *SETTINGS[setting],
                f"evaluation.test_episodes={args.test_episodes}",
                f"evaluation.test_interval={gens}",  # one test: the final champions
            ]
            train_args = ["--preset", args.preset, "--tasks", sc.tasks]
            for text in sets:
                train_args += ["--set", text]
            folder = args.out / name / setting
            runs = [
                PlannedRun(folder / f"seed{k}", k, None)
                for k in range(args.first_seed, args.first_seed + seeds)
            ]
            cells.append((name, setting, train_args, gens, runs))
    return cells


def run(args: argparse.Namespace) -> int:
    """Runs (or resumes) every unfinished run, one comparison cell after another."""
    from mtpg.evolve.experiment import execute
    from mtpg.evolve.stopping import GracefulStop, exit_code

    failed = []
    with GracefulStop("generalisation", "the running trainings stop") as stop:
        for name, setting, train_args, gens, runs in _plan(args):
            if stop.signum is not None:
                break
            print(f"== {name} / {setting}", file=sys.stderr)
            failed += execute(
                runs,
                train_args,
                gens,
                args.parallel,
                args.workers,
                log=lambda m: print(m, file=sys.stderr),
                stop=stop,
            )
    if stop.signum is not None:
        print("stopped; rerun the command to resume", file=sys.stderr)
        return exit_code(stop.signum)
    if failed:
        print(f"failed: {', '.join(str(r.path) for r in failed)}", file=sys.stderr)
        return 1
    return report(args)


def _cost(run_dir: Path) -> tuple[float, float]:
    """Decisions (training and validation) and wall seconds summed over a run's generations."""
    decisions = seconds = 0.0
    with open(run_dir / "metrics.csv", encoding="utf-8") as fh:
        for row in csv.DictReader(fh):
            decisions += float(row["decisions"]) + float(row.get("validation_decisions") or 0)
            seconds += float(row["t_total"])
    return decisions, seconds


def _scores(run_dir: Path, generations: int) -> dict[str, list[float]]:
    """Reference-normalised final test scores: ``all`` (full-set champion) and ``single``."""
    from mtpg.analysis.runs.loading import load_run
    from mtpg.envs.specs.contract import TASK_NAMES
    from mtpg.envs.taskset.reference_scores import normalise

    data = load_run(run_dir)
    if data.final_generation != generations:
        raise ValueError(f"{run_dir}: last test at {data.final_generation}, not {generations}")
    tasks = data.tasks
    full = data.row(data.full_set)
    out = {
        "all": [float(normalise(TASK_NAMES.index(t), float(full[f"test_{t}"]))) for t in tasks],
        "single": [
            float(normalise(TASK_NAMES.index(t), float(data.row(t)[f"test_{t}"]))) for t in tasks
        ],
    }
    return out


def report(args: argparse.Namespace) -> int:
    """Writes ``generalisation.json``, ``generalisation.md`` and ``generalisation.png``."""
    import numpy as np

    from mtpg.analysis.runs.statistics import aggregate_iqm

    rows = []
    for name, setting, _, gens, runs in _plan(args):
        done = [r for r in runs if r.state(gens) == "done"]
        if not done:
            continue
        scores = [_scores(r.path, gens) for r in done]
        costs = np.array([_cost(r.path) for r in done])
        row = {"scenario": name, "setting": setting, "seeds": [r.seed for r in done]}
        for kind in ("all", "single") if name == "six" else ("all",):
            matrix = np.array([s[kind] for s in scores])
            est = aggregate_iqm(matrix)
            row[kind] = {
                "iqm": est.value,
                "low": est.low,
                "high": est.high,
                "text": est.text(),
                "per_run": matrix.tolist(),
            }
        row["decisions"] = float(costs[:, 0].mean())
        row["seconds"] = float(costs[:, 1].mean())
        rows.append(row)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "generalisation.json").write_text(json.dumps(rows, indent=1) + "\n")
    (args.out / "generalisation.md").write_text(_markdown(rows, args.test_episodes))
    if rows:
        _figure(rows, args.out / "generalisation.png")
    print(_markdown(rows, args.test_episodes))
    return 0


def _markdown(rows: list[dict], episodes: int) -> str:
    lines = [
        f"Reference-normalised score on {episodes} held-out episodes per task of each run's "
        "final champion: IQM over seeds [95% stratified bootstrap CI]; cost per run: "
        "decisions played (millions) and wall time (t_total summed, minutes).",
        "",
        "| scenario | setting | seeds | score (champion) | six tasks: single-task champions "
        "| decisions (M) | minutes |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        single = r["single"]["text"] if "single" in r else ""
        lines.append(
            f"| {r['scenario']} | {r['setting']} | {len(r['seeds'])} | {r['all']['text']} "
            f"| {single} | {r['decisions'] / 1e6:.1f} | {r['seconds'] / 60:.1f} |"
        )
    return "\n".join(lines) + "\n"


def _figure(rows: list[dict], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    scenarios = list(dict.fromkeys(r["scenario"] for r in rows))
    widths = [max(3, sum(r["scenario"] == n for r in rows)) for n in scenarios]
    fig, axes = plt.subplots(
        1,
        len(scenarios),
        figsize=(0.55 * sum(widths) + 1.5, 4.2),
        squeeze=False,
        gridspec_kw={"width_ratios": widths},
    )  # one bar per setting, each as wide in every panel
    for ax, name in zip(axes[0], scenarios, strict=True):
        mine = [r for r in rows if r["scenario"] == name]
        x = range(len(mine))
        values = [r["all"]["iqm"] for r in mine]
        low = [r["all"]["iqm"] - r["all"]["low"] for r in mine]
        high = [r["all"]["high"] - r["all"]["iqm"] for r in mine]
        errors = [[v if v == v else 0 for v in low], [v if v == v else 0 for v in high]]
        ax.bar(x, values, yerr=errors, capsize=3, color="#4c72b0", label="IQM, 95% CI")
        for i, r in enumerate(mine):  # every run (its mean over tasks), seed by seed
            runs = [sum(s) / len(s) for s in r["all"]["per_run"]]
            ax.plot([i] * len(runs), runs, "o", ms=3, color="black", alpha=0.6)
        ax.plot([], [], "o", ms=3, color="black", alpha=0.6, label="one run")
        labels = [f"{r['setting']} (n={len(r['seeds'])})" for r in mine]
        ax.set_xticks(list(x), labels, rotation=60, ha="right", fontsize=8)
        if ax is axes[0][0]:
            ax.legend(fontsize=7, loc="upper left")
        ax.set_title(name)
        ax.set_ylabel("normalised test score (IQM)")
        ax.axhline(1.0, color="grey", lw=0.8, ls="--")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    """Command-line entry point."""
    args = _parse(argv)
    return run(args) if args.command == "run" else report(args)


if __name__ == "__main__":
    sys.exit(main())
