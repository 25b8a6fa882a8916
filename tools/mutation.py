"""Mutation testing of mtpg: mutmut for the pure-Python modules, hand mutants for kernels.

Two commands (run from the repository root with the project's virtual environment)::

    python tools/mutation.py mutmut model evolve config io analysis
    python tools/mutation.py hand [NAME ...]

``mutmut`` runs the mutmut tool once per module in its own scratch copy of the tree
(``build/mutation/<module>/``): only that module is mutated and only the test files listed
for it in :data:`MODULES` run (mutmut then runs, per mutant, only those tests that call the
mutated function). Each module's summary is written to ``build/mutation/<module>.json`` and
printed; ``mutmut results`` / ``mutmut show NAME`` inside the scratch copy list and show the
surviving mutants.

``hand`` applies each hand-written mutant of :data:`HAND_MUTANTS` (Numba kernels and task
files, which mutmut does not mutate because they are decorated) to a fresh scratch copy of
``src/`` (``build/mutation/hand/``), runs the tests named with it, and reports whether the
tests killed it. Nothing in the working tree is changed.

Mutation runs are CPU-heavy and not part of the test suite. See ``docs/testing.md``.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SCRATCH = ROOT / "build" / "mutation"
PYTHON = sys.executable
MUTMUT = str(Path(PYTHON).with_name("mutmut"))

#: Per module: the files mutmut mutates and the test files that run against it.
MODULES: dict[str, tuple[list[str], list[str]]] = {
    "model": (
        ["src/mtpg/model/*"],
        [
            "tests/model",
            "tests/evolve/test_variation.py",
            "tests/evolve/test_variation_oracles.py",
            "tests/io/test_io_serialize.py",
        ],
    ),
    "evolve": (
        ["src/mtpg/evolve/*"],
        ["tests/evolve", "tests/io/test_io_checkpoint.py"],
    ),
    "config": (
        ["src/mtpg/config/sections.py", "src/mtpg/config/resolve.py"],
        ["tests/test_config.py", "tests/evolve/test_selection_oracles.py"],
    ),
    "io": (["src/mtpg/io/*"], ["tests/io"]),
    "analysis": (["src/mtpg/analysis/*"], ["tests/analysis", "tests/cli/test_evaluate_cli.py"]),
}


def _copy_tree(dest: Path) -> None:
    """Copies what a test run needs (src, tests, pyproject.toml) into ``dest``."""
    if dest.exists():
        shutil.rmtree(dest)
    dest.mkdir(parents=True)
    ignore = shutil.ignore_patterns("__pycache__", "*.nbi", "*.nbc", ".hypothesis")
    for name in ("src", "tests"):
        shutil.copytree(ROOT / name, dest / name, ignore=ignore)
    (dest / "pyproject.toml").write_text(_without_mutmut_table(ROOT / "pyproject.toml"))


def _without_mutmut_table(path: Path) -> str:
    """The file's text without its ``[tool.mutmut]`` table (each run writes its own)."""
    out, skipping = [], False
    for line in path.read_text(encoding="utf-8").splitlines(keepends=True):
        if line.startswith("["):
            skipping = line.strip() == "[tool.mutmut]"
        if not skipping:
            out.append(line)
    return "".join(out)


def _toml_list(items: list[str]) -> str:
    return "[" + ", ".join(json.dumps(i) for i in items) + "]"


def run_mutmut(module: str) -> dict:
    """Runs mutmut on one module in its scratch copy and returns its counts."""
    mutate, tests = MODULES[module]
    work = SCRATCH / module
    _copy_tree(work)
    tests = [t for t in tests if (work / t).exists()]
    with open(work / "pyproject.toml", "a", encoding="utf-8") as fh:
        fh.write(
            "\n[tool.mutmut]\n"
            'source_paths = ["src"]\n'
            f"only_mutate = {_toml_list(mutate)}\n"
            f"pytest_add_cli_args_test_selection = {_toml_list(tests)}\n"
            'pytest_add_cli_args = ["-p", "no:cacheprovider", "-q", "-x"]\n'
            # the machine may be shared: generous timeouts, so a slow run is not a timeout
            "timeout_multiplier = 10.0\n"
            "timeout_constant = 20.0\n"
        )
    start = time.perf_counter()
    log = work / "mutmut.log"
    with open(log, "w", encoding="utf-8") as out:
        subprocess.run(
            [MUTMUT, "run", "--max-children", "1"], cwd=work, stdout=out, stderr=out, check=False
        )
    stats = summarize(module)
    stats["seconds"] = round(time.perf_counter() - start)
    (SCRATCH / f"{module}.json").write_text(json.dumps(stats, indent=2) + "\n")
    return stats


def summarize(module: str) -> dict:
    """Counts of a finished (or interrupted) mutmut run of ``module`` and its non-killed."""
    work = SCRATCH / module
    subprocess.run([MUTMUT, "export-cicd-stats"], cwd=work, capture_output=True, check=True)
    stats = json.loads((work / "mutants" / "mutmut-cicd-stats.json").read_text())
    results = subprocess.run(
        [MUTMUT, "results"], cwd=work, capture_output=True, text=True, check=True
    ).stdout
    rows = [line.rsplit(":", 1) for line in results.splitlines() if ":" in line]
    stats["not_killed"] = {name.strip(): status.strip() for name, status in rows}
    stats["tests"] = MODULES[module][1]
    return stats


def recheck(module: str, tests: list[str], names: list[str]) -> dict[str, str]:
    """Re-tests the non-killed mutants of a finished mutmut run against the current tests.

    The current ``tests/`` replace the copy inside the run's ``mutants/`` directory; then
    one process imports the mutated package once and, per mutant, forks a child that
    activates the mutant (mutmut's own switch) and runs ``tests`` (default: the module's
    test files) with ``-x``. Used after adding tests, without redoing the whole run.
    """
    work = SCRATCH / module
    stats = summarize(module)
    alive = ("survived", "suspicious", "timeout", "no tests", "segfault")
    todo = names or [n for n, status in stats["not_killed"].items() if status in alive]
    ignore = shutil.ignore_patterns("__pycache__", "*.nbi", "*.nbc", ".hypothesis")
    shutil.rmtree(work / "mutants" / "tests")
    shutil.copytree(ROOT / "tests", work / "mutants" / "tests", ignore=ignore)
    args = ["-q", "-x", "-p", "no:cacheprovider", *(tests or MODULES[module][1])]
    script = (
        "import json, os, signal, sys\n"
        "import pytest, mtpg.evolve.trainer, mtpg.engine.batch\n"
        "from mutmut.mutation.trampoline import set_mutant_under_test\n"
        "names, args = json.loads(sys.argv[1]), json.loads(sys.argv[2])\n"
        "for name in names:\n"
        "    pid = os.fork()\n"
        "    if pid == 0:\n"
        "        set_mutant_under_test(name)\n"
        "        signal.alarm(120)  # a mutant that loops is a timeout\n"
        "        sys.stdout = sys.stderr = open(os.devnull, 'w')\n"
        "        os._exit(int(pytest.main(args)))\n"
        "    _, status = os.waitpid(pid, 0)\n"
        "    code = os.waitstatus_to_exitcode(status)\n"
        "    print(json.dumps([name, code]), flush=True)\n"
    )
    verdicts = {}
    env = dict(os.environ)
    env["PYTHONPATH"] = "src"  # the mutants' copy of the package, not the installed one
    proc = subprocess.Popen(
        [PYTHON, "-c", script, json.dumps(todo), json.dumps(args)],
        cwd=work / "mutants",
        stdout=subprocess.PIPE,
        text=True,
        env=env,
    )
    assert proc.stdout is not None
    for line in proc.stdout:
        name, code = json.loads(line)
        verdicts[name] = {0: "survived", 1: "killed", -14: "timeout"}.get(code, f"error {code}")
        print(f"{name}: {verdicts[name]}", flush=True)
    proc.wait()
    (SCRATCH / f"{module}-recheck.json").write_text(json.dumps(verdicts, indent=2) + "\n")
    return verdicts


@dataclass(frozen=True)
class HandMutant:
    """One hand-written mutant: replace ``old`` (which must occur once) by ``new``."""

    name: str
    path: str
    old: str
    new: str
    tests: tuple[str, ...]


_OBS = ("tests/envs/test_observations.py",)
_PARITY = ("tests/envs/test_gym_parity.py",)
_OPS = ("tests/engine/test_ops_table.py",)
_ENGINE = ("tests/engine/test_parity.py", "tests/engine/test_trace.py")
_SELECTION = (
    "tests/evolve/test_selection.py",
    "tests/evolve/test_selection_oracles.py",
    "tests/evolve/test_selection_rules.py",
    "tests/evolve/test_generalisation.py",
)

#: Hand-written mutants of the compiled kernels and the task files.
HAND_MUTANTS: tuple[HandMutant, ...] = (
    # observation encodings (one per task; bug class 1)
    HandMutant(
        "cartpole-obs-theta-scale",
        "src/mtpg/envs/dynamics/cartpole.py",
        "obs[1] = clip_obs(s[2] / p[THETA_THRESHOLD])",
        "obs[1] = clip_obs(s[3] / p[THETA_THRESHOLD])",
        _OBS,
    ),
    HandMutant(
        "acrobot-obs-swapped",
        "src/mtpg/envs/dynamics/acrobot.py",
        "obs[1] = clip_obs(s[1] / _PI)",
        "obs[1] = clip_obs(s[0] / _PI)",
        _OBS,
    ),
    HandMutant(
        "cartcentering-obs-scale",
        "src/mtpg/envs/dynamics/cartcentering.py",
        "obs[0] = clip_obs(s[0] / p[X_BOUND])",
        "obs[0] = clip_obs(s[0] / p[MAX_SPEED])",
        _OBS,
    ),
    HandMutant(
        "pendulum-obs-unwrapped",
        "src/mtpg/envs/dynamics/pendulum.py",
        "obs[0] = clip_obs(angle_normalize(s[0]) / _PI)",
        "obs[0] = clip_obs(s[0] / _PI)",
        _OBS,
    ),
    HandMutant(
        "mountaincar-obs-offset",
        "src/mtpg/envs/dynamics/mountaincar.py",
        "obs[0] = clip_obs(2.0 * (s[0] - lo) / (p[MAX_POSITION] - lo) - 1.0)",
        "obs[0] = clip_obs(2.0 * (s[0] + lo) / (p[MAX_POSITION] - lo) - 1.0)",
        _OBS,
    ),
    HandMutant(
        "noise-not-observed",
        "src/mtpg/envs/dynamics/mountaincar.py",
        "obs[1] = clip_obs(noise)",
        "obs[1] = clip_obs(0.5)",
        _OBS,
    ),
    HandMutant(
        "clip-obs-nan-passes",
        "src/mtpg/envs/dynamics/numeric.py",
        "    if x != x:\n        return 0.0\n    return clip(x, -1.0, 1.0)",
        "    return clip(x, -1.0, 1.0)",
        _OBS,
    ),
    # dynamics and task data
    HandMutant(
        "cartpole-euler-order",
        "src/mtpg/envs/dynamics/cartpole.py",
        "theta = theta + tau * theta_dot\n    theta_dot = theta_dot + tau * thetaacc",
        "theta_dot = theta_dot + tau * thetaacc\n    theta = theta + tau * theta_dot",
        _PARITY,
    ),
    HandMutant(
        "repeat-action-zero-force",
        "src/mtpg/envs/dynamics/numeric.py",
        "        return -magnitude\n    return previous",
        "        return -magnitude\n    return 0.0",
        _PARITY + ("tests/envs/test_cartcentering.py",),
    ),
    HandMutant(
        "acrobot-velocity-clip",
        "src/mtpg/envs/dynamics/acrobot.py",
        "s[3] = clip(n3, -p[MAX_VEL_2], p[MAX_VEL_2])",
        "s[3] = clip(n3, -p[MAX_VEL_1], p[MAX_VEL_1])",
        _PARITY,
    ),
    HandMutant(
        "mountaincar-wall-elastic",
        "src/mtpg/envs/dynamics/mountaincar.py",
        "if position == p[MIN_POSITION] and velocity < 0:",
        "if position == p[MIN_POSITION] and velocity < -1.0:",
        _PARITY,
    ),
    HandMutant(
        "cartcentering-capture-box",
        "src/mtpg/envs/dynamics/cartcentering.py",
        "terminated = (abs(x) <= cap and abs(v) <= cap) or abs(x) > xb",
        "terminated = (abs(x) <= cap or abs(v) <= cap) or abs(x) > xb",
        ("tests/envs/test_cartcentering.py",),
    ),
    HandMutant(
        "nonfinite-action-kept",
        "src/mtpg/envs/dynamics/numeric.py",
        "    if not np.isfinite(a_c):\n        return 0.0\n",
        "",
        ("tests/envs/test_robustness.py",),
    ),
    # protected operations (bug class 2)
    HandMutant(
        "div-threshold",
        "src/mtpg/engine/ops.py",
        "return a if abs(b) < DIV_EPS else a / b",
        "return a if abs(b) < 1e-9 else a / b",
        _OPS,
    ),
    HandMutant(
        "div-threshold-inclusive",
        "src/mtpg/engine/ops.py",
        "return a if abs(b) < DIV_EPS else a / b",
        "return a if abs(b) <= DIV_EPS else a / b",
        _OPS,
    ),
    HandMutant(
        "saturation-constant",
        "src/mtpg/model/instructions.py",
        "\nBIG = 1e10\n",
        "\nBIG = 1e9\n",
        _OPS,
    ),
    HandMutant(
        "pow-underflow-threshold",
        "src/mtpg/model/instructions.py",
        "\nLOG_TINY = -700.0\n",
        "\nLOG_TINY = -600.0\n",
        _OPS,
    ),
    HandMutant(
        "exp-cap-inclusive",
        "src/mtpg/engine/ops.py",
        "    if b > LOG_BIG:\n        return BIG",
        "    if b >= LOG_BIG - 1e-6:\n        return BIG",
        _OPS,
    ),
    HandMutant(
        "ln-zero-guard",
        "src/mtpg/engine/ops.py",
        "return 0.0 if b == 0.0 else math.log(abs(b))",
        "return -BIG if b == 0.0 else math.log(abs(b))",
        _OPS,
    ),
    HandMutant(
        "if-lt-nonstrict",
        "src/mtpg/engine/ops.py",
        "v = -d if a < b else d",
        "v = -d if a <= b else d",
        _OPS,
    ),
    # the five bug classes of issue 14, planted in pure-Python code
    HandMutant(
        "bug-crossover-sorted",
        "src/mtpg/evolve/variation.py",
        "return [p for p in order if p in kept]",
        "return sorted(kept)",
        ("tests/evolve/test_variation_oracles.py",),
    ),
    HandMutant(
        "bug-parent-from-all-roots",
        "src/mtpg/evolve/trainer.py",
        "pool = elites or roots",
        "pool = roots",
        ("tests/evolve/test_selection_oracles.py",),
    ),
    HandMutant(
        "bug-min-elite-rounds-down",
        "src/mtpg/config/sections.py",
        "-(-self.team.min_elite_total // n)",
        "self.team.min_elite_total // n",
        ("tests/evolve/test_selection_oracles.py", "tests/test_config.py"),
    ),
    # the production decision kernel (bug classes: wrong winner, memory, output)
    HandMutant(
        "kernel-tie-to-later-program",
        "src/mtpg/engine/bid_rule.py",
        "marks[at] != stamp) and bid > best",
        "marks[at] != stamp) and bid >= best",
        _ENGINE,
    ),
    HandMutant(
        "kernel-no-memory-ignored",
        "src/mtpg/engine/episode_kernels.py",
        "if no_memory or bank_stamp[bank] != episode:",
        "if bank_stamp[bank] != episode:",
        _ENGINE,
    ),
    HandMutant(
        "kernel-memory-reset-every-decision",
        "src/mtpg/engine/episode_kernels.py",
        "                bank_stamp[bank] = episode\n",
        "",
        _ENGINE,
    ),
    HandMutant(
        "kernel-time-limit-one-late",
        "src/mtpg/envs/dynamics/dispatch.py",
        "truncated = (not terminated) and state[STEP_SLOT] >= p[P_MAX_STEPS]",
        "truncated = (not terminated) and state[STEP_SLOT] > p[P_MAX_STEPS]",
        _ENGINE,
    ),
    HandMutant(
        "kernel-dispatch-swaps-tasks",
        "src/mtpg/envs/dynamics/dispatch.py",
        "reward, terminated = mountaincar.step_discrete(p, state, a_d)",
        "reward, terminated = mountaincar.step_continuous(p, state, a_c)",
        ("tests/envs/test_dispatch.py", "tests/envs/test_gym_parity.py"),
    ),
    # the batch kernel's job queue (every block taken exactly once)
    HandMutant(
        "queue-fetch-add-not-atomic",
        "src/mtpg/engine/episode_kernels.py",
        'return builder.atomic_rmw("add", ptr, one, "monotonic")',
        "old = builder.load(ptr)\n        builder.store(builder.add(old, one), ptr)\n"
        "        return old",
        ("tests/engine/test_job_queue.py",),
    ),
    HandMutant(
        "queue-skips-first-block",
        "src/mtpg/engine/episode_kernels.py",
        "first = _fetch_add(next_block) * block",
        "first = (_fetch_add(next_block) + 1) * block",
        _ENGINE,
    ),
    HandMutant(
        "kernel-continuous-output-register",
        "src/mtpg/engine/episode_kernels.py",
        "return -1 - act, np.int64(u_base + np.uint64(prog_bank[np.uint64(best_p)]) * u_m)",
        "return -1 - act, np.int64(u_base + np.uint64(prog_bank[np.uint64(best_p)]) * u_m + one)",
        _ENGINE,
    ),
    # the paper's selection rule (section 4.1) and the validated champion choice
    HandMutant(
        "selection-mean-not-min",
        "src/mtpg/evolve/selection.py",
        "fitness = norm[:, list(subset)].min(axis=1)",
        "fitness = norm[:, list(subset)].mean(axis=1)",
        _SELECTION,
    ),
    HandMutant(
        "selection-max-not-min",
        "src/mtpg/evolve/selection.py",
        "fitness = norm[:, list(subset)].min(axis=1)",
        "fitness = norm[:, list(subset)].max(axis=1)",
        _SELECTION,
    ),
    HandMutant(
        "selection-raw-not-normalised",
        "src/mtpg/evolve/selection.py",
        "    norm = min_max_over_roots(scores)\n    out = []",
        "    norm = scores\n    out = []",
        _SELECTION,
    ),
    HandMutant(
        "selection-normalise-without-shift",
        "src/mtpg/evolve/selection.py",
        "out[:, varied] = (scores[:, varied] - lo[varied]) / span[varied]",
        "out[:, varied] = scores[:, varied] / span[varied]",
        _SELECTION,
    ),
    HandMutant(
        "validation-mean-not-min",
        "src/mtpg/evolve/validation.py",
        "return norm.min(axis=1)",
        "return norm.mean(axis=1)",
        _SELECTION,
    ),
)


def run_hand(names: list[str]) -> list[dict[str, object]]:
    """Applies each selected hand mutant in a scratch copy and runs its tests."""
    chosen = [m for m in HAND_MUTANTS if not names or m.name in names]
    unknown = set(names) - {m.name for m in HAND_MUTANTS}
    if unknown:
        raise SystemExit(f"unknown hand mutant(s): {', '.join(sorted(unknown))}")
    work = SCRATCH / ("hand-selected" if names else "hand")
    _copy_tree(work)
    rows = []
    for mutant in chosen:
        target = work / mutant.path
        original = (ROOT / mutant.path).read_text(encoding="utf-8")
        if original.count(mutant.old) != 1:
            raise SystemExit(f"{mutant.name}: the text to replace must occur once in {mutant.path}")
        target.write_text(original.replace(mutant.old, mutant.new), encoding="utf-8")
        start = time.perf_counter()
        proc = subprocess.run(
            [PYTHON, "-m", "pytest", "-q", "-x", "-p", "no:cacheprovider", *mutant.tests],
            cwd=work,
            capture_output=True,
            text=True,
            env=_env(work, mutant.name),
            check=False,
        )
        target.write_text(original, encoding="utf-8")
        verdict = {0: "survived", 1: "killed"}.get(proc.returncode, f"error {proc.returncode}")
        tail = proc.stdout.strip().splitlines()[-1:] if proc.stdout.strip() else [""]
        row = {
            "name": mutant.name,
            "path": mutant.path,
            "verdict": verdict,
            "seconds": round(time.perf_counter() - start, 1),
            "pytest": tail[0],
        }
        print(f"{row['name']:32s} {verdict:9s} {row['seconds']:6.1f}s  {row['pytest']}", flush=True)
        rows.append(row)
    work.with_suffix(".json").write_text(json.dumps(rows, indent=2) + "\n")
    return rows


def _env(work: Path, name: str) -> dict[str, str]:
    """Environment in which ``import mtpg`` resolves to the scratch copy's ``src``.

    Every mutant gets its own empty Numba cache: Numba does not invalidate a cached
    kernel when a kernel it calls (in another file) changes.
    """
    env = dict(os.environ)
    env["PYTHONPATH"] = str(work / "src") + os.pathsep + env.get("PYTHONPATH", "")
    cache = work / "numba-cache" / name
    shutil.rmtree(cache, ignore_errors=True)
    env["NUMBA_CACHE_DIR"] = str(cache)
    return env


def main(argv: list[str] | None = None) -> int:
    """Command-line entry point."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    mm = sub.add_parser("mutmut", help="run mutmut on pure-Python modules")
    mm.add_argument("modules", nargs="+", choices=sorted(MODULES))
    summary = sub.add_parser("summary", help="summarise finished mutmut runs")
    summary.add_argument("modules", nargs="+", choices=sorted(MODULES))
    again = sub.add_parser("recheck", help="re-test non-killed mutants with the current tests")
    again.add_argument("module", choices=sorted(MODULES))
    again.add_argument("names", nargs="*", help="mutant names (default: every non-killed)")
    again.add_argument("--tests", nargs="+", default=[], help="test files (default: module's)")
    hand = sub.add_parser("hand", help="run the hand-written kernel and task mutants")
    hand.add_argument("names", nargs="*", help="mutant names (default: all)")
    args = parser.parse_args(argv)
    if args.command == "recheck":
        verdicts = recheck(args.module, args.tests, args.names)
        alive = [n for n, v in verdicts.items() if v != "killed"]
        print(f"{len(verdicts) - len(alive)}/{len(verdicts)} killed by the current tests")
        return 1 if alive else 0
    if args.command == "hand":
        rows = run_hand(args.names)
        survived = [r["name"] for r in rows if r["verdict"] != "killed"]
        print(f"{len(rows) - len(survived)}/{len(rows)} hand mutants killed")
        return 1 if survived else 0
    for module in args.modules:
        stats = run_mutmut(module) if args.command == "mutmut" else summarize(module)
        killed, survived = stats["killed"], stats["survived"]
        print(
            f"{module}: {killed} killed, {survived} survived, {stats['no_tests']} without tests, "
            f"{stats['timeout']} timeouts, {stats['suspicious']} suspicious, of {stats['total']}",
            flush=True,
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
