"""The six built-in tasks written as compiled tasks: the contract's first users.

Each of :data:`CARTPOLE`, :data:`ACROBOT`, :data:`CARTCENTERING`, :data:`PENDULUM`,
:data:`MOUNTAINCAR` and :data:`MOUNTAINCARCONTINUOUS` is a
:class:`~mtpg.envs.specs.compiled_task.CompiledTask` (``mtpg.CompiledTask``) made with the
public contract alone (docs/compiled-task.md), from the task's own module: its ``observe``
kernel as it is, its ``step`` kernel behind a two-line adapter to the contract's
``step(p, s, a_d, a_c)``, its ``sample_start`` with the bookkeeping slots appended, and its
registry entry's sizes and constants. There is one definition of each task's dynamics, and a
graph plays the same episodes and returns on ``mtpg.envs.dynamics.builtin_compiled:CARTPOLE``
as on ``CartPole`` (``tests/envs/test_builtins_as_compiled_tasks.py``)::

    mtpg train --preset demo --tasks mtpg.envs.dynamics.builtin_compiled:CARTPOLE

What each built-in needs, in the contract's terms:

- **Parameter row.** ``p`` is the registry's row: ``max_steps`` is column 0, the
  ``action_bound`` column 1 and ``params`` columns 2 onwards, so the task modules' column
  constants read the same values. A discrete task's column 1 is its force: its
  ``action_bound`` is unused by the engine (``n_continuous=0``) and read by its ``step``.
- **State.** The physical state in slots ``0..`` as the registered tasks keep it; CartPole
  and CartCentering keep the previous force in slot ``PREV_FORCE_SLOT`` (4), starting at
  ``+F`` as the registered tasks' reset sets it, and CartCentering counts its steps in slot
  ``STEP_SLOT`` (5), which its terminal penalty reads. The engine's own step count is kept
  elsewhere, so the task counts for itself.
- **Actions.** The paper's interface: every task has the same three atomic actions (the
  continuous tasks ignore ``a_d``) and the three continuous tasks read ``a_c``, which the
  engine has made finite and clipped to ``+-action_bound``, as the registered dispatch's
  ``continuous_action`` does (the kernels clip it again, which changes nothing).
- **Noise.** The one-input tasks observe the episode's U[0, 1] noise as their second input
  (``noise_input=True``).
- **Scores.** A compiled task's reference scores are given, not registered:
  :func:`references` gives the registry's, for ``evaluation.references``.

The registered tasks' dispatch (:mod:`mtpg.envs.dynamics.dispatch`) still calls the same
kernels directly: it is compiled once and cached, while a compiled task's dispatch is
generated per run and compiled in each process (:mod:`mtpg.envs.dynamics.user_dispatch`).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from mtpg.envs.dynamics import acrobot, cartcentering, cartpole, mountaincar, pendulum
from mtpg.envs.specs import registry
from mtpg.envs.specs.compiled_task import CompiledTask
from mtpg.envs.specs.contract import PREV_FORCE_SLOT, STEP_SLOT
from mtpg.envs.specs.task_spec import TaskSpec

#: The module's name, the part before the colon of its tasks' names.
MODULE = __name__

#: The adapters' compile options: the task modules' own.
_kernel = njit(cache=True, error_model="numpy")


def _with_bookkeeping(spec: TaskSpec, physical: np.ndarray, slots: int) -> np.ndarray:
    """A start state of ``slots`` values: the physical state, then the previous force ``+F``.

    Args:
        spec: The registered task.
        physical: Its physical start state.
        slots: The compiled task's ``state_dim`` (5: up to the previous force; 6: with the
            step count, 0 at the start).

    Returns:
        float64 [slots].
    """
    s = np.zeros(slots, dtype=np.float64)
    s[: physical.shape[0]] = physical
    s[PREV_FORCE_SLOT] = spec.params[1]
    return s


# CartPole: reads a_d; keeps the previous force.
@_kernel
def cartpole_step(p: np.ndarray, s: np.ndarray, a_d: int, a_c: float) -> tuple[float, bool]:
    """The contract's ``step``: :func:`mtpg.envs.dynamics.cartpole.step` on ``a_d``."""
    return cartpole.step(p, s, a_d)


def cartpole_start(rng: np.random.Generator) -> np.ndarray:
    """CartPole's start draw, then the first previous force (+10 N)."""
    return _with_bookkeeping(registry.CARTPOLE, cartpole.sample_start(rng), PREV_FORCE_SLOT + 1)


# Acrobot: reads a_c.
@_kernel
def acrobot_step(p: np.ndarray, s: np.ndarray, a_d: int, a_c: float) -> tuple[float, bool]:
    """The contract's ``step``: :func:`mtpg.envs.dynamics.acrobot.step` on ``a_c``."""
    return acrobot.step(p, s, a_c)


# CartCentering: reads a_d; keeps the previous force and counts its steps (the penalty's t).
@_kernel
def cartcentering_step(p: np.ndarray, s: np.ndarray, a_d: int, a_c: float) -> tuple[float, bool]:
    """The contract's ``step``: counts the step, then :func:`~.cartcentering.step` on ``a_d``."""
    s[STEP_SLOT] += 1.0
    return cartcentering.step(p, s, a_d)


def cartcentering_start(rng: np.random.Generator) -> np.ndarray:
    """CartCentering's start draw, the first previous force (+1 N) and a step count of 0."""
    physical = cartcentering.sample_start(rng)
    return _with_bookkeeping(registry.CARTCENTERING, physical, STEP_SLOT + 1)


# Pendulum: reads a_c.
@_kernel
def pendulum_step(p: np.ndarray, s: np.ndarray, a_d: int, a_c: float) -> tuple[float, bool]:
    """The contract's ``step``: :func:`mtpg.envs.dynamics.pendulum.step` on ``a_c``."""
    return pendulum.step(p, s, a_c)


# MountainCar: reads a_d (no previous force: 1 means no push).
@_kernel
def mountaincar_step(p: np.ndarray, s: np.ndarray, a_d: int, a_c: float) -> tuple[float, bool]:
    """The contract's ``step``: :func:`mtpg.envs.dynamics.mountaincar.step_discrete`."""
    return mountaincar.step_discrete(p, s, a_d)


# MountainCarContinuous: reads a_c.
@_kernel
def mountaincarcontinuous_step(
    p: np.ndarray, s: np.ndarray, a_d: int, a_c: float
) -> tuple[float, bool]:
    """The contract's ``step``: :func:`mtpg.envs.dynamics.mountaincar.step_continuous`."""
    return mountaincar.step_continuous(p, s, a_c)


def as_compiled(spec: TaskSpec, step, sample_start, state_dim: int) -> CompiledTask:
    """A registered task as a :class:`CompiledTask`: its observation kernel and its row.

    Args:
        spec: The registered task (:mod:`mtpg.envs.specs.registry`).
        step: Its step in the contract's signature (an adapter above).
        sample_start: Its start draw, ``state_dim`` values.
        state_dim: Slots of its state (physical, then any bookkeeping).

    Returns:
        The compiled task, titled as the registered one.
    """
    return CompiledTask(
        spec.name,
        spec.kernel("observe"),
        step,
        sample_start,
        n_obs=2,
        n_actions=3,
        n_continuous=int(spec.continuous),
        state_dim=state_dim,
        max_steps=spec.max_steps,
        params=tuple(spec.params[2:]),
        action_bound=float(spec.params[1]),
        noise_input=len(spec.observed_slots) < 2,
    )


CARTPOLE = as_compiled(registry.CARTPOLE, cartpole_step, cartpole_start, PREV_FORCE_SLOT + 1)
ACROBOT = as_compiled(registry.ACROBOT, acrobot_step, acrobot.sample_start, acrobot.STATE_DIM)
CARTCENTERING = as_compiled(
    registry.CARTCENTERING, cartcentering_step, cartcentering_start, STEP_SLOT + 1
)
PENDULUM = as_compiled(registry.PENDULUM, pendulum_step, pendulum.sample_start, pendulum.STATE_DIM)
MOUNTAINCAR = as_compiled(
    registry.MOUNTAINCAR, mountaincar_step, mountaincar.sample_start, mountaincar.STATE_DIM
)
MOUNTAINCARCONTINUOUS = as_compiled(
    registry.MOUNTAINCARCONTINUOUS,
    mountaincarcontinuous_step,
    mountaincar.sample_start,
    mountaincar.STATE_DIM,
)

#: The registered task's name -> its compiled task's name (``module:ATTR``), in id order.
NAMES: dict[str, str] = {spec.name: f"{MODULE}:{spec.name.upper()}" for spec in registry.TASKS}


def references(names: tuple[str, ...] = registry.TASK_NAMES) -> list[str]:
    """``evaluation.references`` entries giving the compiled tasks the registry's scores.

    With them a run on the compiled tasks normalises its scores as a run on the registered
    ones (the random score given, so none is measured).

    Args:
        names: Registered task names.

    Returns:
        One entry per task: ``"module:ATTR: best=..., random=..., source=..."``.
    """
    entries = []
    for name in names:
        ref = registry.spec(name).reference
        source = f"the registry's {name}: {ref.source}"
        entries.append(f"{NAMES[name]}: best={ref.best!r}, random={ref.random!r}, source={source}")
    return entries
