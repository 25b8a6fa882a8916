"""A task written as Numba functions in the user's own module: ``--tasks mymodule:MY_TASK``.

The contract (docs/own-task.md, "A compiled task"): a module-level :class:`CompiledTask`
in an importable module, naming three functions and the task's sizes::

    @njit
    def observe(p, s, noise, obs): ...          # writes obs[0..n_obs)
    @njit
    def step(p, s, a_d, a_c): ...               # returns (reward, terminated)
    def sample_start(rng): ...                  # plain Python: the start state

    MY_TASK = CompiledTask("MyTask", observe, step, sample_start,
                           n_obs=4, n_actions=2, n_continuous=0, state_dim=4,
                           max_steps=500, params=(10.0, 0.02))

- ``s`` is the task's own state, ``state_dim`` float64 slots, from ``sample_start(rng)``
  (``rng`` is the episode's ``numpy.random.Generator``, seeded by the episode's seed; the
  draws it makes are the task's business).
- ``p`` is the task's parameter row: ``p[0]`` the time limit, ``p[1]`` the bound of the
  continuous action (``action_bound``; a task without a continuous action may read it as
  a constant of its own), ``p[2:]`` the ``params`` given (at most :data:`MAX_PARAMS`).
- ``obs`` has at least ``n_obs`` slots; write values in about ``[-1, 1]`` (the programs'
  range; nothing is rescaled). ``noise`` is a U[0, 1] value drawn for this step from the
  episode's seed, for tasks that observe noise.
- ``a_d`` is in ``0..n_actions-1`` (0 when the task has no discrete action); ``a_c`` is
  ``m[0]`` of the final program's memory bank, a non-finite value made 0 and then clipped
  to ``[-p[1], p[1]]`` (0 when the task has no continuous action). A task of
  ``n_continuous = n > 1`` dimensions gets ``a_c`` as a float64 array of ``n`` values,
  ``a_c[j]`` being ``m[j]``, each made finite and clipped the same way (at most
  ``program.n_memory`` dimensions, 8 by default).
- The engine counts the steps: an episode ends when ``step`` returns ``terminated`` or after
  ``max_steps`` steps (truncated).
- Episode seeds as for the registered tasks (test episode ``k``: seed ``1_000_000 + k``):
  the episode of seed ``S`` is ``rng = numpy.random.default_rng(S)``, ``s =
  sample_start(rng)``, then ``noise = rng.random(max_steps + 1)`` (``noise[t]`` observed
  after ``t`` steps), so a plain loop calling the task's functions replays any episode.

The six registered tasks are this contract's first users: ``mtpg.envs.dynamics.builtin_compiled``
writes each as a :class:`CompiledTask` from its own module's kernels, and a run on them
equals the run on the registered tasks bit for bit. A run naming the registered tasks
still uses their dispatch, compiled once and cached, while a compiled task's is generated
for the run's task set and compiled in each process (:mod:`mtpg.envs.dynamics.user_dispatch`),
which takes some seconds: Numba caches by source file, and generated code has none.
"""

from __future__ import annotations

import importlib
import math
from collections.abc import Callable
from dataclasses import dataclass
from functools import cache
from typing import Any

import numpy as np

from mtpg.envs.specs.param_table import N_TASK_COLUMNS

#: Most ``params`` a compiled task may give (the parameter row's task columns, less two).
MAX_PARAMS = N_TASK_COLUMNS - 2
#: Most state slots of a compiled task.
MAX_STATE = 64
#: Most continuous dimensions of a compiled task (a run also needs as many memory
#: registers per bank, ``program.n_memory``: :func:`mtpg.limits.check_continuous_fits`).
MAX_CONTINUOUS = 64


class CompiledTaskError(ValueError):
    """A compiled task cannot be used as asked; the message is one line."""


def is_compiled_name(name: str) -> bool:
    """Whether a task name names a compiled task of a user's module (``module:ATTR``)."""
    return ":" in name and not name.startswith("gym:") and "[" not in name


@dataclass(frozen=True, eq=False)
class CompiledTask:
    """A task as Numba functions: the contract of the module docstring.

    Attributes:
        title: A readable name (progress lines, ``mtpg envs``); the run stores the task as
            ``module:ATTR``, the name it was loaded by (:attr:`name`).
        observe: ``observe(p, s, noise, obs) -> None``, a Numba function.
        step: ``step(p, s, a_d, a_c) -> (reward, terminated)``, a Numba function.
        sample_start: ``sample_start(rng) -> array of state_dim floats``, plain Python.
        n_obs: Observed inputs (1 or more).
        n_actions: Discrete actions (0: the task reads no discrete action).
        n_continuous: Continuous action dimensions: 0, 1 (``a_c`` is the float ``m[0]``)
            or more (``a_c`` is an array, ``a_c[j] = m[j]``).
        state_dim: Slots of the task's state.
        max_steps: The time limit in steps.
        params: The task's constants, ``p[2:]`` (at most :data:`MAX_PARAMS`).
        action_bound: The bound of the continuous action, ``p[1]`` (a constant the task
            may read when it has no continuous action).
        noise_input: Whether ``observe`` reads ``noise`` (the memorisation probe then
            redraws it, as for the registered tasks' noise input).
        name: Set by :func:`load`: ``module:ATTR``.
    """

    title: str
    observe: Callable[..., Any]
    step: Callable[..., Any]
    sample_start: Callable[[np.random.Generator], Any]
    n_obs: int
    n_actions: int
    n_continuous: int = 0
    state_dim: int = 4
    max_steps: int = 500
    params: tuple[float, ...] = ()
    action_bound: float = 1.0
    noise_input: bool = False
    name: str = ""

    def __post_init__(self) -> None:
        """Checks the sizes and the functions, naming the field at fault."""
        checks = (
            (self.n_obs >= 1, "n_obs", "must be >= 1"),
            (self.n_actions >= 0, "n_actions", "must be >= 0"),
            (
                0 <= self.n_continuous <= MAX_CONTINUOUS,
                "n_continuous",
                f"must be 0..{MAX_CONTINUOUS}",
            ),
            (self.n_actions + self.n_continuous > 0, "n_actions", "or n_continuous must be > 0"),
            (1 <= self.state_dim <= MAX_STATE, "state_dim", f"must be 1..{MAX_STATE}"),
            (self.max_steps >= 1, "max_steps", "must be >= 1"),
            (len(self.params) <= MAX_PARAMS, "params", f"takes at most {MAX_PARAMS} values"),
            (all(math.isfinite(float(v)) for v in self.params), "params", "must be finite"),
            (
                math.isfinite(self.action_bound) and self.action_bound > 0,
                "action_bound",
                "must be finite and > 0",
            ),
        )
        for ok, field, message in checks:
            if not ok:
                raise CompiledTaskError(f"compiled task {self.title}: {field} {message}")
        for role in ("observe", "step"):
            if not hasattr(getattr(self, role), "py_func"):
                raise CompiledTaskError(
                    f"compiled task {self.title}: {role} must be a Numba function (@njit)"
                )

    # The attributes the episode tables and reports read of any task spec.
    @property
    def continuous(self) -> bool:
        """Whether the task reads the continuous action."""
        return self.n_continuous > 0

    @property
    def slots(self) -> int:
        """Slots the task takes in the engine's state array.

        Its state, then its continuous action when it has several dimensions
        (:mod:`mtpg.envs.dynamics.user_dispatch`).
        """
        return self.state_dim + (self.n_continuous if self.n_continuous > 1 else 0)

    @property
    def bound(self) -> float:
        """The bound of the continuous action (0 for a task without one)."""
        return float(self.action_bound) if self.continuous else 0.0

    @property
    def short(self) -> str:
        """A short name for progress lines: the title's capitals, or its first three letters."""
        caps = "".join(c for c in self.title if c.isupper())
        return caps if 2 <= len(caps) <= 4 else self.title[:3]

    @property
    def observed(self) -> str:
        """The observation, as text (``mtpg envs``)."""
        noise = ", with the noise input" if self.noise_input else ""
        return f"{self.n_obs} inputs written by {self.observe.__name__}{noise}"

    @property
    def action_text(self) -> str:
        """The action, as text."""
        parts = [f"a_d in 0..{self.n_actions - 1}"] if self.n_actions else []
        if self.continuous:
            parts.append(f"a_c = m[0] clipped to +-{self.action_bound:g}")
        return ", ".join(parts)

    def row(self) -> tuple[float, ...]:
        """The task columns of its parameter row: time limit, bound, then ``params``."""
        return (float(self.max_steps), float(self.action_bound), *map(float, self.params))

    def parameters(self) -> np.ndarray:
        """The parameter row ``p`` its functions are given (:meth:`row`, read-only)."""
        p = np.array(self.row(), dtype=np.float64)
        p.setflags(write=False)
        return p

    def kernel(self, role: str) -> Any:
        """The function of a role (``"step"``, ``"observe"``, ``"sample_start"``)."""
        if role not in ("step", "observe", "sample_start"):
            raise ValueError(f"unknown kernel role {role!r}")
        return getattr(self, role)

    def start(self, rng: np.random.Generator) -> np.ndarray:
        """A start state from ``sample_start``, checked.

        Raises:
            CompiledTaskError: For a start of the wrong size or not finite.
        """
        s = np.asarray(self.sample_start(rng), dtype=np.float64).ravel()
        if s.shape != (self.state_dim,):
            raise CompiledTaskError(
                f"compiled task {self.name}: sample_start gave {s.size} values, "
                f"state_dim is {self.state_dim}"
            )
        if not np.isfinite(s).all():
            raise CompiledTaskError(
                f"compiled task {self.name}: sample_start gave a non-finite state"
            )
        return s


@cache
def load(name: str) -> CompiledTask:
    """The compiled task ``module:ATTR``: imports the module and reads the attribute.

    One object per name in a process (so the kernels compiled for it are compiled once).

    Raises:
        CompiledTaskError: One line: a module that does not import, a missing attribute,
            or an attribute that is not a :class:`CompiledTask`.
    """
    module, _, attr = name.partition(":")
    if not module or not attr or not attr.isidentifier():
        raise CompiledTaskError(f"task {name!r}: write a compiled task as module:ATTR")
    try:
        mod = importlib.import_module(module)
    except Exception as exc:  # the user's module: any error it raises is theirs
        raise CompiledTaskError(
            f"task {name!r}: module {module!r} does not import "
            f"({type(exc).__name__}: {str(exc).splitlines()[0] if str(exc) else ''})"
        ) from None
    task = getattr(mod, attr, None)
    if task is None:
        raise CompiledTaskError(f"task {name!r}: module {module!r} has no attribute {attr!r}")
    if not isinstance(task, CompiledTask):
        raise CompiledTaskError(
            f"task {name!r}: {module}.{attr} is a {type(task).__name__}, not a mtpg.CompiledTask"
        )
    return task if task.name == name else _named(task, name)


def _named(task: CompiledTask, name: str) -> CompiledTask:
    """The task under the name it was loaded by."""
    fields = {f: getattr(task, f) for f in task.__dataclass_fields__}
    return CompiledTask(**{**fields, "name": name})
