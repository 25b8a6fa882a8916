"""Steps per second of the compiled task kernels next to Gymnasium's own environments.

Usage: ``python benchmarks/bench_envs.py [--steps N] [--gym-steps M] [--repeats R]``

For every task: the compiled loop (``env_step`` + ``env_observe`` with pre-drawn random
actions, automatic reset to the next pre-drawn episode) inside one njit function; the
Gymnasium environment of the same name, both as ``gymnasium.make`` returns it (with its
default wrappers) and unwrapped, stepping pre-sampled actions; and this project's
Gymnasium class ``mtpg/<Task>-v0``. Each figure is the median of R timed repeats, after
one warm-up run.
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import time

import gymnasium
import numba
import numpy as np
from numba import njit

from mtpg.envs import (
    ACTION_BOUND,
    GYM_IDS,
    MAX_STEPS,
    N_OBS,
    STATE_SIZE,
    TASK_NAMES,
    TASK_PARAMS,
    env_observe,
    env_reset,
    env_step,
    make_episodes,
)

STOCK_IDS = {
    0: "CartPole-v1",
    1: "Acrobot-v1",
    3: "Pendulum-v1",
    4: "MountainCar-v0",
    5: "MountainCarContinuous-v0",
}


@njit(cache=True, error_model="numpy")
def compiled_loop(task, params, starts, noise, a_d, a_c):
    """Plays len(a_d) steps, resetting to the next start when an episode ends."""
    state = np.zeros(STATE_SIZE)
    obs = np.zeros(N_OBS)
    episode = 0
    t = 0
    env_reset(task, params, starts[0], state)
    env_observe(task, params, state, noise[0, 0], obs)
    acc = 0.0
    for i in range(a_d.shape[0]):
        reward, terminated, truncated = env_step(task, params, state, a_d[i], a_c[i])
        acc += reward + obs[0]
        if terminated or truncated:
            episode = (episode + 1) % starts.shape[0]
            t = 0
            env_reset(task, params, starts[episode], state)
        else:
            t += 1
        env_observe(task, params, state, noise[episode, t], obs)
    return acc


def time_compiled(task: int, steps: int, repeats: int) -> float:
    n_eps = 2000
    starts, noise = make_episodes(np.full(n_eps, task), np.arange(n_eps))
    rng = np.random.default_rng(0)
    a_d = rng.integers(0, 3, steps)
    bound = ACTION_BOUND[task]
    a_c = rng.uniform(-bound, bound, steps)
    compiled_loop(task, TASK_PARAMS, starts, noise, a_d[:1000], a_c[:1000])
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        compiled_loop(task, TASK_PARAMS, starts, noise, a_d, a_c)
        times.append(time.perf_counter() - t0)
    return steps / statistics.median(times)


def time_gym(env: gymnasium.Env, actions: list, repeats: int) -> float:
    def run() -> None:
        env.reset(seed=0)
        for a in actions:
            _, _, terminated, truncated, _ = env.step(a)
            if terminated or truncated:
                env.reset()

    run()
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        run()
        times.append(time.perf_counter() - t0)
    return len(actions) / statistics.median(times)


def stock_rates(task: int, steps: int, repeats: int) -> tuple[float, float]:
    env = gymnasium.make(STOCK_IDS[task])
    env.action_space.seed(0)
    actions = [env.action_space.sample() for _ in range(steps)]
    wrapped = time_gym(env, actions, repeats)
    raw_env = env.unwrapped
    limit = env.spec.max_episode_steps

    class Raw:  # the unwrapped env with the time limit applied by hand
        def __init__(self) -> None:
            self.t = 0

        def reset(self, **kw):
            self.t = 0
            return raw_env.reset(**kw)

        def step(self, a):
            self.t += 1
            obs, r, te, tr, info = raw_env.step(a)
            return obs, r, te, tr or self.t >= limit, info

    raw = time_gym(Raw(), actions, repeats)  # type: ignore[arg-type]
    return wrapped, raw


def mtpg_gym_rate(task: int, steps: int, repeats: int) -> float:
    env = gymnasium.make(GYM_IDS[task]).unwrapped
    rng = np.random.default_rng(0)
    actions = [
        (int(d), np.array([c]))
        for d, c in zip(rng.integers(0, 3, steps), rng.uniform(-2, 2, steps), strict=True)
    ]
    return time_gym(env, actions, repeats)


def machine() -> str:
    cpu = "unknown"
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    return (
        f"{platform.platform()}; CPU {cpu}; {os.cpu_count()} logical cores; "
        f"Python {platform.python_version()}, numpy {np.__version__}, numba {numba.__version__}, "
        f"gymnasium {gymnasium.__version__}"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=2_000_000, help="compiled steps per run")
    parser.add_argument("--gym-steps", type=int, default=20_000, help="Gymnasium steps per run")
    parser.add_argument("--repeats", type=int, default=5, help="timed runs; median reported")
    args = parser.parse_args()
    print(f"machine: {machine()}")
    print(f"numba threads: {numba.get_num_threads()} (the loops are single-threaded)")
    print(
        f"steps/s, median of {args.repeats}; compiled {args.steps:,} steps/run, "
        f"Gymnasium {args.gym_steps:,} steps/run"
    )
    head = ("task", "limit", "compiled", "gym make", "gym raw", "mtpg gym env", "compiled/raw")
    print("| " + " | ".join(head) + " |")
    print("|" + "|".join("---" for _ in head) + "|")
    for task, name in enumerate(TASK_NAMES):
        comp = time_compiled(task, args.steps, args.repeats)
        ours = mtpg_gym_rate(task, args.gym_steps, args.repeats)
        if task in STOCK_IDS:
            wrapped, raw = stock_rates(task, args.gym_steps, args.repeats)
            cols = (f"{wrapped:,.0f}", f"{raw:,.0f}", f"{comp / raw:,.0f}x")
        else:
            cols = ("n/a", "n/a", "n/a")
        limit = int(MAX_STEPS[task])
        print(
            f"| {name} | {limit} | {comp:,.0f} | {cols[0]} | {cols[1]} | {ours:,.0f} | {cols[2]} |"
        )


if __name__ == "__main__":
    from mtpg._kernel_cache import refresh

    refresh()  # before the first kernel: a Numba cache older than the sources goes
    main()
