"""Frames of the tasks: Gymnasium's classic-control renderers, and one for CartCentering.

Which renderer draws a task is its spec's ``render`` field (:mod:`mtpg.envs.specs.registry`): a
Gymnasium ``classic_control`` class name, or ``""`` for the class ``<name>Renderer`` here.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from mtpg.envs.dynamics import cartcentering
from mtpg.envs.dynamics.numeric import clip
from mtpg.envs.specs.contract import CARTCENTERING, PENDULUM
from mtpg.envs.specs.param_table import TASK_PARAMS
from mtpg.envs.specs.registry import spec
from mtpg.envs.specs.task_spec import TaskSpec


class GymRenderer:
    """Draws a task with the matching Gymnasium environment's ``render`` by setting its state.

    Args:
        task: The task's spec (a Gymnasium task, or a variant of one).
    """

    def __init__(self, task: TaskSpec):
        from gymnasium.envs import classic_control

        self.env: Any = getattr(classic_control, task.render)(render_mode="rgb_array")
        self.kind = task.base or task.name  # a variant draws as its base
        self.dim = task.state_dim

    def frame(self, state: np.ndarray, last_action: float) -> np.ndarray:
        """Renders one frame.

        Args:
            state: The task state array.
            last_action: The last continuous action (Pendulum draws the torque).

        Returns:
            An ``H x W x 3`` uint8 frame.
        """
        self.env.state = np.array(state[: self.dim], dtype=np.float64)
        if self.kind == spec(PENDULUM).name:
            bound = spec(PENDULUM).bound
            self.env.last_u = clip(last_action, -bound, bound) if np.isfinite(last_action) else 0.0
        return np.asarray(self.env.render(), dtype=np.uint8)

    def close(self) -> None:
        """Closes the Gymnasium environment."""
        self.env.close()


class CartCenteringRenderer:
    """Draws the cart-centering track: bounds, the capture zone and the cart."""

    width = 600
    height = 200

    def __init__(self) -> None:
        import pygame

        self.pygame = pygame
        self.surf = pygame.Surface((self.width, self.height))
        self.x_bound = float(TASK_PARAMS[CARTCENTERING, cartcentering.X_BOUND])

    def frame(self, state: np.ndarray, last_action: float) -> np.ndarray:
        """Renders one frame.

        Args:
            state: The task state array (x, v, previous force, ...).
            last_action: Unused.

        Returns:
            An ``H x W x 3`` uint8 frame.
        """
        pg = self.pygame
        surf = self.surf
        surf.fill((255, 255, 255))
        scale = (self.width - 40) / (2 * self.x_bound)
        mid = self.width / 2
        ground = int(self.height * 0.65)

        def to_px(x: float) -> int:
            return int(round(mid + clip(x, -self.x_bound * 1.05, self.x_bound * 1.05) * scale))

        left, right = to_px(-self.x_bound), to_px(self.x_bound)
        pg.draw.line(surf, (0, 0, 0), (left, ground), (right, ground))
        for edge in (left, right):
            pg.draw.line(surf, (200, 0, 0), (edge, ground - 40), (edge, ground + 10), 2)
        centre = to_px(0.0)
        pg.draw.line(surf, (0, 150, 0), (centre, ground - 60), (centre, ground + 10), 2)
        x = float(state[0])
        v = float(state[1])
        cx = to_px(x)
        pg.draw.rect(surf, (40, 40, 40), pg.Rect(cx - 20, ground - 25, 40, 25))
        tip = to_px(x + 0.25 * v) if np.isfinite(v) else cx
        pg.draw.line(surf, (0, 0, 200), (cx, ground - 35), (tip, ground - 35), 3)
        force = float(state[4])
        arrow = 15 if force > 0 else -15
        pg.draw.polygon(
            surf,
            (204, 77, 77),
            [(cx + arrow, ground - 12), (cx, ground - 18), (cx, ground - 6)],
        )
        return np.transpose(np.array(pg.surfarray.pixels3d(surf)), axes=(1, 0, 2)).copy()

    def close(self) -> None:
        """Nothing to release (the surface is off-screen)."""


def make_renderer(task: TaskSpec) -> GymRenderer | CartCenteringRenderer:
    """Returns the renderer of a task.

    Args:
        task: The task's spec.

    Returns:
        An object with ``frame(state, last_action)`` and ``close()``.
    """
    if task.render:
        return GymRenderer(task)
    return globals()[f"{task.base or task.name}Renderer"]()
