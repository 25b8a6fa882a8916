"""The SLURM recipe of examples/slurm/, run here with the scheduler's signals simulated.

SLURM runs the batch script with ``SLURM_JOB_ID`` set, sends USR1 to the script alone
300 s before the time limit (``--signal=B:USR1@300``) and SIGTERM to every process of the
job on scancel, preemption or at the limit; ``scontrol requeue`` runs the same script
again. Here a stand-in ``scontrol`` records the requeue, the test sends the signals, and
"requeueing" is running the script again.
"""

import csv
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from stopruns import run_files
from tinyruns import tiny_args

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "slurm"
SCRIPT = EXAMPLES / "train.sbatch"
GENERATIONS = 12
#: A run of a few seconds whose generations last long enough to be signalled in between.
ARGS = [
    *tiny_args(
        "CartPole,MountainCar",
        root_size=100,
        n_elite=60,
        evaluation__train_episodes=3,
        evaluation__test_interval=2,
        evaluation__test_episodes=3,
        checkpoint_interval=5,
    ),
    "--generations",
    str(GENERATIONS),
]


def slurm_env(tmp_path, run, **more):
    """The environment of a batch job, with a stand-in ``scontrol`` first on PATH."""
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir(parents=True, exist_ok=True)
    fake = bin_dir / "scontrol"
    fake.write_text(f'#!/bin/sh\necho "$@" >> "{tmp_path}/scontrol.log"\n')
    fake.chmod(0o755)
    env = {k: v for k, v in os.environ.items() if not k.startswith("MTPG_TEST")}
    env.update(
        PATH=f"{bin_dir}:{env['PATH']}",
        SLURM_JOB_ID="4242",
        SLURM_CPUS_PER_TASK="1",
        RUN=str(run),
        MTPG=f"{sys.executable} -m mtpg",
        MTPG_ARGS=" ".join(ARGS),
    )
    env.update(more)
    return env


def rows(run):
    try:
        with open(Path(run) / "metrics.csv") as fh:
            return sum(1 for _ in csv.DictReader(fh))
    except FileNotFoundError:
        return 0


def job(script, env, cwd, signal_after=None, sig=signal.SIGUSR1, whole_job=False):
    """Runs the batch script; sends ``sig`` once ``signal_after`` generations are done."""
    proc = subprocess.Popen(
        ["bash", str(script)],
        env=env,
        cwd=cwd,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        start_new_session=True,  # its own process group: "every process of the job"
    )
    if signal_after is not None:
        deadline = time.monotonic() + 120
        while rows(env["RUN"]) < signal_after and proc.poll() is None:
            assert time.monotonic() < deadline, "the run made no progress"
            time.sleep(0.005)
        if whole_job:
            os.killpg(proc.pid, sig)
        else:
            proc.send_signal(sig)
    out, _ = proc.communicate(timeout=300)
    return proc.returncode, out


def requeues(tmp_path):
    log = tmp_path / "scontrol.log"
    return log.read_text().splitlines() if log.exists() else []


def same_results(ref, run):
    """Every file equal (metrics.csv timing aside), checkpoints compared at the end."""
    a, b = run_files(ref), run_files(run)
    last = f"checkpoints/gen-{GENERATIONS:06d}.json.gz"
    for files in (a, b):
        for name in [n for n in files if n.startswith("checkpoints/") and n != last]:
            del files[name]  # which ones are kept depends on where the pieces stopped
    assert sorted(a) == sorted(b)
    for name in a:
        assert a[name] == b[name], name


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    """The same job never signalled: one uninterrupted run."""
    tmp = tmp_path_factory.mktemp("ref")
    code, out = job(SCRIPT, slurm_env(tmp, tmp / "run"), tmp)
    assert code == 0, out
    assert requeues(tmp) == []
    return tmp / "run"


def test_the_batch_scripts_parse():
    for script in EXAMPLES.glob("*.sbatch"):
        subprocess.run(["bash", "-n", str(script)], check=True)
        head = script.read_text().splitlines()
        assert head[0] == "#!/bin/bash"
        assert "#SBATCH --signal=B:USR1@300" in head and "#SBATCH --requeue" in head


def test_a_run_in_three_requeued_pieces_equals_the_uninterrupted_run(tmp_path, reference):
    run = tmp_path / "run"
    env = slurm_env(tmp_path, run)
    code, out = job(SCRIPT, env, tmp_path, signal_after=3)  # piece 1: USR1 after gen 3
    assert code == 143, out
    assert "requeueing job 4242" in out and "(committed)" in out
    first = rows(run)
    assert 3 <= first < GENERATIONS
    code, out = job(SCRIPT, env, tmp_path, signal_after=first + 3)  # piece 2 resumes
    assert code == 143, out
    assert f"generation {first} of {GENERATIONS}" in out
    code, out = job(SCRIPT, env, tmp_path)  # piece 3 resumes and finishes
    assert code == 0, out
    assert requeues(tmp_path) == ["requeue 4242", "requeue 4242"]
    same_results(reference, run)


def test_sigterm_to_every_process_commits_and_does_not_requeue(tmp_path, reference):
    run = tmp_path / "run"
    env = slurm_env(tmp_path, run)
    code, out = job(SCRIPT, env, tmp_path, 3, signal.SIGTERM, whole_job=True)  # scancel
    assert code == 143, out
    assert "stopped by SIGTERM after generation" in out  # one signal: a clean stop
    assert requeues(tmp_path) == []  # a cancelled job stays cancelled
    code, out = job(SCRIPT, env, tmp_path)  # resubmitted by hand
    assert code == 0, out
    same_results(reference, run)
