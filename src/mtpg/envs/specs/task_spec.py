"""What a task is, as data: the :class:`TaskSpec` record and its :class:`Reference` scores.

A spec names the task's compiled kernels by module and function (``kernel_module``,
``step``, ``observe``, ``sample_start``) rather than holding them, so that the registry
(:mod:`mtpg.envs.specs.registry`) loads without Numba: importing :mod:`mtpg.envs` registers the
Gymnasium ids from the registry alone. :meth:`TaskSpec.kernel` imports the function on
demand.
"""

from __future__ import annotations

import importlib
import math
from dataclasses import dataclass
from typing import Any, NamedTuple

#: The two kinds of action a task reads.
ACTION_KINDS: tuple[str, ...] = ("discrete", "continuous")


class Reference(NamedTuple):
    """Reference figures of one task.

    Attributes:
        random: Mean score of the random agent (see :mod:`mtpg.envs.taskset.reference_scores`).
        random_std: Standard deviation of that score.
        best: Reference best score (Fig. 6 normalisation).
        solved: Registered solved threshold, or NaN when there is none.
        source: Where ``best`` comes from.
    """

    random: float
    random_std: float
    best: float
    solved: float
    source: str


@dataclass(frozen=True)
class TaskSpec:
    """One task: its kernels, constants, interface and the facts the analyses need.

    Attributes:
        name: Task name (also the Gymnasium id ``mtpg/<name>-v0``).
        short: Short name of the progress lines (two or three capitals).
        kernel_module: Module holding the compiled kernels, e.g. ``"mtpg.envs.dynamics.cartpole"``.
        step: Name of the step kernel ``step(p, state, action) -> (reward, terminated)``.
        observe: Name of the observation kernel ``observe(p, state, noise, obs)``.
        sample_start: Name of the start sampler ``sample_start(rng) -> physical state``.
        params: The parameter row; column 0 is the time limit, column 1 the force
            magnitude (discrete) or action bound (continuous); the rest are named by the
            column constants of ``kernel_module``.
        param_names: Name of each parameter column (the lower-case column constants of
            ``kernel_module``); a variant overrides a parameter by this name.
        state_names: Names of the physical state variables, in Gymnasium's order.
        state_low: Per state variable, the low end of the range a variant's observation
            scales to -1 (see :mod:`mtpg.envs.taskset.variants`).
        state_high: Per state variable, the high end of that range (scaled to +1).
        angle_slots: State slots holding angles, wrapped into [-pi, pi) before scaling.
        observed_slots: State slots the task's own observation reads (the rest of the two
            inputs is noise).
        observed: The observation, as text (``mtpg envs``).
        action: ``"discrete"`` (reads ``a_d``) or ``"continuous"`` (reads ``a_c``).
        action_text: The action and its meaning, as text.
        reference: Reference scores with their source.
        velocity_slot: State slot of the hidden velocity the section-6 analyses track.
        colour: The task's colour in every section-6 figure.
        render: Gymnasium ``classic_control`` class drawing the task, or ``""`` for a
            renderer of :mod:`mtpg.envs.gym_api.render` named ``<name>Renderer``.
        base: For a variant (:mod:`mtpg.envs.taskset.variants`), the name of its registered base
            task; ``""`` for a registered task.
    """

    name: str
    short: str
    kernel_module: str
    step: str
    observe: str
    sample_start: str
    params: tuple[float, ...]
    param_names: tuple[str, ...]
    state_names: tuple[str, ...]
    state_low: tuple[float, ...]
    state_high: tuple[float, ...]
    angle_slots: tuple[int, ...]
    observed_slots: tuple[int, ...]
    observed: str
    action: str
    action_text: str
    reference: Reference
    velocity_slot: int
    colour: str
    render: str
    base: str = ""

    def __post_init__(self) -> None:
        """Checks the spec's internal consistency (naming the field at fault)."""
        n = len(self.state_names)
        checks = (
            (self.action in ACTION_KINDS, "action", f"must be one of {', '.join(ACTION_KINDS)}"),
            (len(self.params) >= 2, "params", "needs the time limit and the force/bound"),
            (float(self.params[0]) >= 1, "params", "time limit (column 0) must be >= 1"),
            (
                len(self.param_names) == len(self.params) and self.param_names[0] == "max_steps",
                "param_names",
                "needs one name per column, max_steps first",
            ),
            (1 <= n <= 4, "state_names", "needs 1 to 4 state variables"),
            (len(self.state_low) == n, "state_low", "needs one value per state variable"),
            (len(self.state_high) == n, "state_high", "needs one value per state variable"),
            (
                all(lo < hi for lo, hi in zip(self.state_low, self.state_high, strict=True)),
                "state_high",
                "must exceed state_low",
            ),
            (all(0 <= s < n for s in self.angle_slots), "angle_slots", "must be state slots"),
            (
                all(0 <= s < n for s in self.observed_slots) and len(self.observed_slots) <= 2,
                "observed_slots",
                "must be at most two state slots",
            ),
            (0 <= self.velocity_slot < n, "velocity_slot", "must be a state slot"),
        )
        for ok, field, message in checks:
            if not ok:
                raise ValueError(f"task {self.name}: {field} {message}")

    @property
    def max_steps(self) -> int:
        """The time limit in steps."""
        return int(self.params[0])

    @property
    def continuous(self) -> bool:
        """Whether the task reads the continuous action ``a_c``."""
        return self.action == "continuous"

    @property
    def bound(self) -> float:
        """The symmetric bound of the continuous action (0 for discrete tasks)."""
        return float(self.params[1]) if self.continuous else 0.0

    @property
    def state_dim(self) -> int:
        """Number of physical state variables."""
        return len(self.state_names)

    @property
    def velocity_name(self) -> str:
        """Name of the velocity the section-6 analyses track."""
        return self.state_names[self.velocity_slot]

    @property
    def gym_id(self) -> str:
        """The Gymnasium id of the paper's two-action interface."""
        return variant_gym_id(self.name) if self.base else f"mtpg/{self.name}-v0"

    def kernel(self, role: str) -> Any:
        """The function named by ``step``, ``observe`` or ``sample_start``, imported.

        Args:
            role: ``"step"``, ``"observe"`` or ``"sample_start"``.

        Returns:
            The function (a Numba dispatcher for the two kernels).
        """
        if role not in ("step", "observe", "sample_start"):
            raise ValueError(f"unknown kernel role {role!r}")
        return getattr(importlib.import_module(self.kernel_module), getattr(self, role))


#: "No threshold" in :class:`Reference`.
NONE = math.nan


def variant_gym_id(name: str) -> str:
    """The Gymnasium id of a canonically spelled variant, ``Base[k=v;k=v]``.

    ``"CartPole[max_steps=500]"`` gives ``"mtpg/CartPole-max_steps_500-v0"``: the settings
    in their canonical (sorted) order, ``+`` written ``.``, ``cos(x)`` written ``cos_x``.
    """
    base, _, body = name.rstrip("]").partition("[")
    parts = [
        item.replace("=", "_", 1).replace("+", ".").replace("(", "_").replace(")", "")
        for item in body.split(";")
    ]
    return f"mtpg/{base}-{'-'.join(parts)}-v0"
