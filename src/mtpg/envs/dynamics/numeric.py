"""Small numba helpers shared by the task kernels."""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, error_model="numpy")
def clip(x: float, lo: float, hi: float) -> float:
    """Clips ``x`` to ``[lo, hi]`` (NaN passes through unchanged).

    Args:
        x: The value.
        lo: The lower bound.
        hi: The upper bound.

    Returns:
        ``x`` clipped to the bounds.
    """
    if x < lo:
        return lo
    if x > hi:
        return hi
    return x


@njit(cache=True, error_model="numpy")
def clip_obs(x: float) -> float:
    """Clips an observation to ``[-1, 1]``; a NaN becomes 0.

    Args:
        x: The scaled observation.

    Returns:
        A value in ``[-1, 1]``.
    """
    if x != x:
        return 0.0
    return clip(x, -1.0, 1.0)


@njit(cache=True, error_model="numpy")
def continuous_action(a_c: float, bound: float) -> float:
    """Sanitises a continuous action: non-finite values become 0, then clip to the bound.

    Args:
        a_c: The raw continuous action.
        bound: The task's symmetric bound.

    Returns:
        The action in ``[-bound, bound]``.
    """
    if not np.isfinite(a_c):
        return 0.0
    return clip(a_c, -bound, bound)


@njit(cache=True, error_model="numpy")
def bang_bang_force(a_d: int, previous: float, magnitude: float) -> float:
    """The force of a bang-bang task: ``0 -> +F``, ``2 -> -F``, anything else repeats.

    Args:
        a_d: The discrete action; values outside {0, 2} act as 1 ("repeat previous").
        previous: The force of the previous step (``+F`` before the first step).
        magnitude: The force magnitude ``F``.

    Returns:
        The force to apply this step.
    """
    if a_d == 0:
        return magnitude
    if a_d == 2:
        return -magnitude
    return previous
