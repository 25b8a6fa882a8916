"""The compiled task interface the execution engine calls: reset, observe and step.

:func:`task_observe` and :func:`task_step` are the one dispatch on the task id: an if-chain
to the task modules, with a branch per task of the registry (:mod:`mtpg.envs.specs.registry`).
Every kernel (these, the batch kernel of training, the traced kernel) reaches the task
modules through them. An id without a branch observes NaN and ends its episode at once
with a NaN reward, so a task missing from the chain cannot pass for another task
(``tests/envs/test_dispatch.py`` plays every registered task through every kernel).

The dispatch branches on a row's ``kind`` column (``P_KIND``): a registered task's own id,
or a variant's base task id (:mod:`mtpg.envs.taskset.variants`), so a variant runs its base task's
kernels on its own parameter row; a row whose ``P_OBS`` column is set is observed by
:func:`variant_observe`. State lives in a float64 array of ``STATE_SIZE`` slots (see
``mtpg.envs.specs.contract``); parameters are rows of ``TASK_PARAMS`` (see
``mtpg.envs.specs.param_table``) or of the ``params`` of a task table
(:mod:`mtpg.envs.taskset.task_table`).

The dispatch and everything it reaches are compiled without reference counting
(:data:`step_kernel`): they take arrays and allocate none, while a function compiled with
Numba's reference counting pays an atomic increment and decrement per array argument and
call (an IR-inlined one, ``inline="always"``, pays them in its caller): about ten per step
of the batch kernel, measured in docs/engine.md.

Action conventions: a non-finite ``a_c`` is treated as 0 and then clipped to the task's
bound; an ``a_d`` outside {0, 1, 2} is treated as 1 ("repeat the previous force" in
CartPole and CartCentering, "no push" in MountainCar).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from mtpg.envs.dynamics import acrobot, cartcentering, cartpole, mountaincar, pendulum
from mtpg.envs.dynamics.numeric import clip_obs
from mtpg.envs.specs.contract import (
    ACROBOT,
    CARTCENTERING,
    CARTPOLE,
    MOUNTAINCAR,
    MOUNTAINCARCONTINUOUS,
    PENDULUM,
    PREV_FORCE_SLOT,
    STATE_SIZE,
    STEP_SLOT,
)
from mtpg.envs.specs.param_table import (
    OBS_COS,
    OBS_SIN,
    OBS_WRAP,
    P_FORCE,
    P_KIND,
    P_MAX_STEPS,
    P_NOISE_HI,
    P_NOISE_LO,
    P_OBS,
    P_OBS_FN,
    P_OBS_HI,
    P_OBS_LO,
    P_OBS_NOISY,
    P_OBS_OUT_HI,
    P_OBS_OUT_LO,
    P_OBS_SD,
    P_OBS_SLOT,
)

#: Options of the step and observation dispatch, which take arrays and allocate none:
#: compiled without Numba's reference counting (``_nrt=False``, an option of ``njit``
#: exercised by Numba's own tests), so a call passing the state, parameter row and
#: observation costs no atomic reference-count updates. The functions it calls (the task
#: modules') are compiled for it with the same option. A function compiled with it must
#: not create, return or keep an array; ``tests/engine/test_no_refcounts.py`` checks the
#: compiled code.
step_kernel = njit(cache=True, error_model="numpy", _nrt=False)


@njit(cache=True, error_model="numpy")
def env_reset(task: int, params: np.ndarray, start: np.ndarray, state: np.ndarray) -> None:
    """Starts an episode: copies the start state and resets the bookkeeping slots.

    Args:
        task: The task id.
        params: ``TASK_PARAMS``.
        start: A start state of ``STATE_SIZE`` slots (from ``sample_start``).
        state: The state array to initialise (``STATE_SIZE`` slots).
    """
    for i in range(STATE_SIZE):
        state[i] = start[i]
    state[PREV_FORCE_SLOT] = params[task, P_FORCE]
    state[STEP_SLOT] = 0.0


@njit(cache=True, error_model="numpy")
def env_observe(
    task: int,
    params: np.ndarray,
    state: np.ndarray,
    noise: float,
    obs: np.ndarray,
    eps: np.ndarray | None = None,
) -> None:
    """Writes the two observed inputs, each in [-1, 1].

    Args:
        task: The task id.
        params: ``TASK_PARAMS``.
        state: The current state array.
        noise: The episode's U[0, 1] noise value for this step (used by one-input tasks).
        obs: Output array of at least two slots.
        eps: The episode's two standard normal values for this step (the observation
            noise of a variant with ``noise``); None when the table has none.
    """
    p = params[task]
    task_observe(observe_kind(p), p, state, noise, obs)
    if eps is not None and p[P_OBS_SD] != 0.0:
        add_obs_noise(p, eps[0], eps[1], obs)


@step_kernel
def add_obs_noise(p: np.ndarray, eps0: float, eps1: float, obs: np.ndarray) -> None:
    """Adds a variant's Gaussian observation noise to the inputs that observe the state.

    Each such input becomes ``clip(obs + sd * eps)`` (``sd = p[P_OBS_SD]``, in the
    inputs' [-1, 1] units); the U[0, 1] noise input of a one-input task is left as it is.

    Args:
        p: The parameter row.
        eps0: Standard normal value of the first input.
        eps1: Standard normal value of the second input.
        obs: The observation, updated in place.
    """
    sd = p[P_OBS_SD]
    n = np.int64(p[P_OBS_NOISY])
    if n > 0:
        obs[0] = clip_obs(obs[0] + sd * eps0)
    if n > 1:
        obs[1] = clip_obs(obs[1] + sd * eps1)


#: The observation kind of a row whose ``P_OBS`` column is set (a variant's observation).
VARIANT_OBSERVATION = -2


@step_kernel
def observe_kind(p: np.ndarray) -> int:
    """The observation kind of a parameter row: its base task id, or ``VARIANT_OBSERVATION``."""
    if p[P_OBS] != 0.0:
        return VARIANT_OBSERVATION
    return np.int64(p[P_KIND])


@step_kernel
def variant_observe(p: np.ndarray, state: np.ndarray, noise: float, obs: np.ndarray) -> None:
    """A variant's observation: each input a state slot scaled to a range, or the noise.

    A state input takes its slot's value (wrapped, or its cosine or sine, by ``P_OBS_FN``)
    and maps ``P_OBS_LO..P_OBS_HI`` linearly onto ``P_OBS_OUT_LO..P_OBS_OUT_HI`` (-1..1
    unless the variant sets ``obs_low`` / ``obs_high``), clipped to that range (a NaN
    becomes its middle). When the two ranges are the same the value is taken as it is.
    The noise input is the U[0, 1] draw, or ``P_NOISE_LO + (P_NOISE_HI - P_NOISE_LO) *
    draw`` unclipped when the variant sets ``noise_low`` / ``noise_high`` (the authors'
    code feeds U[-pi, pi] noise as it is).

    Args:
        p: The variant's parameter row (columns ``P_OBS_*``, ``P_NOISE_*``).
        state: The current state array.
        noise: The episode's U[0, 1] noise value for this step.
        obs: Output array of at least two slots.
    """
    out_lo = p[P_OBS_OUT_LO]
    out_hi = p[P_OBS_OUT_HI]
    default_out = out_lo == -1.0 and out_hi == 1.0
    for i in range(2):
        slot = np.int64(p[P_OBS_SLOT + i])
        if slot < 0:
            n_lo = p[P_NOISE_LO]
            n_hi = p[P_NOISE_HI]
            if n_lo == 0.0 and n_hi == 1.0:
                obs[i] = clip_obs(noise)
            else:
                obs[i] = n_lo + (n_hi - n_lo) * noise
            continue
        x = state[slot]
        fn = np.int64(p[P_OBS_FN + i])
        if fn == OBS_WRAP:
            x = pendulum.angle_normalize(x)
        elif fn == OBS_COS:
            x = np.cos(x)
        elif fn == OBS_SIN:
            x = np.sin(x)
        lo = p[P_OBS_LO + i]
        hi = p[P_OBS_HI + i]
        if lo == out_lo and hi == out_hi:
            v = x
        elif default_out:
            v = 2.0 * (x - lo) / (hi - lo) - 1.0
        else:
            v = out_lo + (out_hi - out_lo) * (x - lo) / (hi - lo)
        if default_out:
            obs[i] = clip_obs(v)
        elif v != v:
            obs[i] = 0.5 * (out_lo + out_hi)
        else:
            obs[i] = min(max(v, out_lo), out_hi)


@step_kernel
def task_observe(
    kind: int, p: np.ndarray, state: np.ndarray, noise: float, obs: np.ndarray
) -> None:
    """The observation dispatch: writes the two inputs of a parameter row.

    Args:
        kind: The row's observation kind, :func:`observe_kind` (its base task id, or
            ``VARIANT_OBSERVATION``), taken once per episode.
        p: The parameter row.
        state: The current state array.
        noise: The episode's U[0, 1] noise value for this step.
        obs: Output array of at least two slots (NaN for an id without a branch).
    """
    task = kind
    if task == CARTPOLE:
        cartpole.observe(p, state, noise, obs)
    elif task == ACROBOT:
        acrobot.observe(p, state, noise, obs)
    elif task == CARTCENTERING:
        cartcentering.observe(p, state, noise, obs)
    elif task == PENDULUM:
        pendulum.observe(p, state, noise, obs)
    elif task == MOUNTAINCAR or task == MOUNTAINCARCONTINUOUS:
        mountaincar.observe(p, state, noise, obs)
    elif task == VARIANT_OBSERVATION:
        variant_observe(p, state, noise, obs)
    else:
        obs[0] = np.nan
        obs[1] = np.nan


@step_kernel
def task_step(
    kind: int, p: np.ndarray, state: np.ndarray, a_d: int, a_c: float
) -> tuple[float, bool, bool]:
    """The step dispatch: advances the task of a parameter row by one step in place.

    Compiled as a :data:`step_kernel` (no reference counting): the batch kernel calls it
    once per step.

    Args:
        kind: The row's base task id (``p[P_KIND]``): which kernels play it.
        p: The parameter row.
        state: The state array, updated in place.
        a_d: The discrete action (read by the discrete tasks).
        a_c: The continuous action (read by the continuous tasks).

    Returns:
        (reward, terminated, truncated); an id without a branch gives (NaN, True, False).
    """
    task = kind
    state[STEP_SLOT] += 1.0
    if task == CARTPOLE:
        reward, terminated = cartpole.step(p, state, a_d)
    elif task == ACROBOT:
        reward, terminated = acrobot.step(p, state, a_c)
    elif task == CARTCENTERING:
        reward, terminated = cartcentering.step(p, state, a_d)
    elif task == PENDULUM:
        reward, terminated = pendulum.step(p, state, a_c)
    elif task == MOUNTAINCAR:
        reward, terminated = mountaincar.step_discrete(p, state, a_d)
    elif task == MOUNTAINCARCONTINUOUS:
        reward, terminated = mountaincar.step_continuous(p, state, a_c)
    else:
        reward, terminated = np.nan, True
    truncated = (not terminated) and state[STEP_SLOT] >= p[P_MAX_STEPS]
    return reward, terminated, truncated


@njit(cache=True, error_model="numpy", inline="always")
def task_continuous(
    kind: int, p: np.ndarray, state: np.ndarray, W: np.ndarray, off: int, stride: int
) -> None:
    """Hands a task the continuous outputs past ``m[0]``: none for the registered tasks.

    The engine calls it before every :func:`task_step`, with the workspace ``W`` and the
    index ``off`` of ``m[0]`` of the deciding program's bank (``m[j]`` at
    ``off + j * stride``). The registered tasks read one continuous action, ``a_c = m[0]``,
    so this one does nothing and compiles away (it is inlined); the dispatch generated for
    compiled tasks of several continuous dimensions copies ``m[0..n)`` into the task's
    state array, where its ``step`` reads them (:mod:`mtpg.envs.dynamics.user_dispatch`).

    Args:
        kind: The row's base task id.
        p: The parameter row.
        state: The state array.
        W: The workspace holding the bank.
        off: The index of ``m[0]`` in ``W``.
        stride: The distance between ``m[j]`` and ``m[j + 1]`` in ``W``.
    """
    return None


@njit(cache=True, error_model="numpy")
def env_step(
    task: int, params: np.ndarray, state: np.ndarray, a_d: int, a_c: float
) -> tuple[float, bool, bool]:
    """Advances the task by one step in place.

    Args:
        task: The task id.
        params: ``TASK_PARAMS``.
        state: The state array, updated in place.
        a_d: The discrete action (read by CartPole, CartCentering, MountainCar).
        a_c: The continuous action (read by Acrobot, Pendulum, MountainCarContinuous).

    Returns:
        (reward, terminated, truncated); truncated is True when the step count reaches the
        task's time limit without termination.
    """
    p = params[task]
    return task_step(np.int64(p[P_KIND]), p, state, a_d, a_c)
