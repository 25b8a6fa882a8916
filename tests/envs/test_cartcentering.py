from __future__ import annotations

import numpy as np
import pytest

from mtpg.envs import CARTCENTERING, STATE_SIZE, TASK_PARAMS, env_reset, env_step, sample_start
from mtpg.envs.dynamics.cartcentering import is_captured
from mtpg.envs.dynamics.rollout import run_time_optimal
from mtpg.envs.taskset.episodes import make_episodes

TAU = 0.02
MASS = 2.0


def fresh(x: float, v: float) -> np.ndarray:
    start = np.zeros(STATE_SIZE)
    start[0], start[1] = x, v
    state = np.zeros(STATE_SIZE)
    env_reset(CARTCENTERING, TASK_PARAMS, start, state)
    return state


def step(state: np.ndarray, a_d: int) -> tuple[float, bool, bool]:
    return env_step(CARTCENTERING, TASK_PARAMS, state, a_d, 0.0)


def test_koza_update_by_hand() -> None:
    s = fresh(0.5, -0.2)
    # a_d 0: +1 N. x uses the old v; v += tau * F / m.
    assert step(s, 0) == (0.0, False, False)
    assert s[0] == pytest.approx(0.5 + TAU * -0.2, abs=1e-15)
    assert s[1] == pytest.approx(-0.2 + TAU * 1.0 / MASS, abs=1e-15)
    # a_d 1 repeats +1 N.
    step(s, 1)
    assert s[0] == pytest.approx(0.496 + TAU * -0.19, abs=1e-15)
    assert s[1] == pytest.approx(-0.18, abs=1e-15)
    # a_d 2: -1 N.
    step(s, 2)
    assert s[0] == pytest.approx(0.4922 + TAU * -0.18, abs=1e-15)
    assert s[1] == pytest.approx(-0.19, abs=1e-15)
    # an out-of-range a_d repeats the previous force (-1 N).
    step(s, 7)
    assert s[1] == pytest.approx(-0.2, abs=1e-15)


def test_first_repeat_is_plus_force() -> None:
    s = fresh(0.3, 0.0)
    step(s, 1)
    assert s[1] == pytest.approx(TAU * 1.0 / MASS, abs=1e-15)


def test_velocity_clip() -> None:
    s = fresh(0.0, 5.999)
    step(s, 0)
    assert s[1] == 6.0


def test_capture_reward() -> None:
    s = fresh(0.005, 0.0)
    reward, terminated, truncated = step(s, 2)
    assert terminated and not truncated
    assert s[1] == pytest.approx(-0.01, abs=1e-15)
    assert reward == pytest.approx(-(0.005 / 1.5 + 0.01 / 12 + 0.1 * 1 / 500), abs=1e-15)


def test_out_of_bounds_reward() -> None:
    s = fresh(1.499, 0.75)
    reward, terminated, truncated = step(s, 0)
    assert terminated and not truncated
    x, v = 1.499 + TAU * 0.75, 0.75 + TAU / MASS
    assert reward == pytest.approx(-(x / 1.5 + v / 12 + 0.1 * 1 / 500), abs=1e-15)


def test_time_limit_reward() -> None:
    s = fresh(-0.5, 0.0)
    for t in range(499):  # alternating +F/-F: the cart stays near x = -0.5
        reward, terminated, truncated = step(s, 2 * (t % 2))
        assert reward == 0.0 and not terminated and not truncated
    # 500th step: truncated, the terminal penalty includes 0.1 * 500 / 500.
    s2 = fresh(-0.5, 0.0)
    s2[5] = 499.0
    reward, terminated, truncated = step(s2, 1)
    assert truncated and not terminated
    x, v = -0.5, TAU / MASS
    assert reward == pytest.approx(-(abs(x) / 1.5 + v / 12 + 0.1), abs=1e-15)


def test_start_redrawn_when_captured() -> None:
    class FakeRng:
        def __init__(self) -> None:
            self.draws = [np.array([0.001, -0.005]), np.array([0.4, 0.1])]

        def uniform(self, low: float, high: float, size: tuple[int]) -> np.ndarray:
            return self.draws.pop(0)

    start = sample_start(CARTCENTERING, FakeRng())  # type: ignore[arg-type]
    assert tuple(start[:2]) == (0.4, 0.1)


def test_time_optimal_captures_every_start() -> None:
    starts, _ = make_episodes(np.full(1000, CARTCENTERING), np.arange(1000))
    assert not any(is_captured(x, v) for x, v in starts[:, :2])
    assert np.abs(starts[:, :2]).max() <= 0.75
    returns, steps, captured = run_time_optimal(TASK_PARAMS, starts)
    assert captured.all()
    assert steps.max() < 500
    assert (returns < 0).all() and returns.min() > -0.2
