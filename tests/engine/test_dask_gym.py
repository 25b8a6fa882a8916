"""Gymnasium tasks on the dask backend: the local results, and one line when a worker
cannot import the user's environment module."""

import os
import sys
import textwrap

import numpy as np
import pytest

pytest.importorskip("distributed")

from mtpg.engine.batch import Episodes, evaluate_roots
from mtpg.engine.compile import compile_population
from mtpg.engine.dask_backend import DaskEvaluator
from mtpg.engine.random_populations import tangled_population
from mtpg.envs.specs.gym_task import GymTaskError
from mtpg.envs.taskset.task_table import TaskTable

MODULE = textwrap.dedent(
    '''
    """A point on a line; with WORKERS_LACK_IT set it imports in the main process only."""
    import multiprocessing
    import os

    import gymnasium as gym
    import numpy as np
    from gymnasium import spaces

    WORKER = multiprocessing.current_process().name != "MainProcess"
    if os.environ.get("WORKERS_LACK_IT") and WORKER:
        raise ImportError("not installed on this worker")


    class Line(gym.Env):
        def __init__(self):
            self.observation_space = spaces.Box(-2.0, 2.0, (2,), dtype=np.float64)
            self.action_space = spaces.Discrete(3)

        def reset(self, *, seed=None, options=None):
            super().reset(seed=seed)
            self.x = float(self.np_random.uniform(-1.0, 1.0))
            return np.array([self.x, 0.0]), {}

        def step(self, action):
            self.x = float(np.clip(self.x + 0.1 * (int(action) - 1), -2.0, 2.0))
            return np.array([self.x, 0.0]), -abs(self.x), False, False, {}


    gym.register("Line-v0", entry_point=Line, max_episode_steps=12)
    '''
)


@pytest.fixture(scope="module")
def cluster(tmp_path_factory):
    """A two-worker local cluster whose workers find the user's modules on PYTHONPATH."""
    folder = tmp_path_factory.mktemp("usercode")
    (folder / "daskline.py").write_text(MODULE)
    (folder / "daskline_local.py").write_text(MODULE.replace("Line-v0", "LineLocal-v0"))
    with pytest.MonkeyPatch.context() as mp:
        mp.syspath_prepend(str(folder))
        mp.setenv("PYTHONPATH", os.pathsep.join([str(folder), os.environ.get("PYTHONPATH", "")]))
        ev = DaskEvaluator(n_workers=2, min_roots=1)
        try:
            yield ev
        finally:
            ev.close()
    for name in ("daskline", "daskline_local"):
        sys.modules.pop(name, None)


def test_gymnasium_batches_on_dask_equal_the_local_engine(cluster):
    pop = tangled_population(np.random.default_rng(5), 30, 80, 8, 12)
    cp = compile_population(pop)
    roots = sorted(pop.teams)[::3]
    table = TaskTable.from_names(["CartPole", "gym:CartPole-v1", "gym:daskline:Line-v0"])
    eps = Episodes.grid(list(table.ids), [0, 1], table)
    want, w = evaluate_roots(cp, roots, eps, 1)
    got, g = cluster.evaluate(cp, roots, eps)
    assert np.array_equal(want, got)
    for a, b in zip(w, g, strict=True):
        assert np.array_equal(a, b)


def test_a_worker_without_the_users_module_is_one_line(cluster, monkeypatch):
    monkeypatch.setenv("WORKERS_LACK_IT", "1")  # read at import, on the workers too
    # a lambda travels by value (a bound method of os.environ would set a copy's item)
    cluster.client.run(lambda: os.environ.__setitem__("WORKERS_LACK_IT", "1"))
    try:
        pop = tangled_population(np.random.default_rng(5), 10, 20, 4, 6)
        cp = compile_population(pop)
        table = TaskTable.from_names(["gym:daskline_local:LineLocal-v0"])  # imports here
        eps = Episodes.grid(list(table.ids), [0], table)
        with pytest.raises(GymTaskError) as caught:
            cluster.evaluate(cp, sorted(pop.teams)[:2], eps)
    finally:
        cluster.client.run(lambda: os.environ.pop("WORKERS_LACK_IT", None))
    text = str(caught.value)
    assert "\n" not in text and text.startswith("on dask worker (pid ")
    assert "module 'daskline_local' does not import (not installed on this worker)" in text
    assert text.endswith("every dask worker must import it (on its PYTHONPATH, or installed)")
