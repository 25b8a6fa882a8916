"""Task decomposition by team (paper Fig. 10): where in state space each team runs.

For one task's replay, each team gets the points ``(observed variable, hidden velocity)``
of the steps at which it was visited; a point is *final* when the team chose the action
at that step (it is then coloured by that action), otherwise the team passed execution
on (grey). The observed variable is the task's first input ``s[0]``; the velocity is the
state slot of :data:`mtpg.analysis.graph.measures.HIDDEN_VELOCITY`.
"""

from __future__ import annotations

import numpy as np

from mtpg.analysis.graph.replay import Replay
from mtpg.envs.taskset.variants import task_spec


def decomposition(replay: Replay, n_teams: int) -> dict[str, object]:
    """Points of each team in (observed variable, hidden velocity) space.

    Args:
        replay: One task's replay.
        n_teams: Teams of the graph.

    Returns:
        ``teams``: a list over team numbers 1..n_teams of dicts with ``x``, ``y``, ``final``
        (bool) and ``action`` (the action of the step: for a continuous task ``a_c``
        clipped to the task's bound, as the task applies it, else ``a_d``) arrays;
        ``continuous`` (bool), ``x_label``, ``y_label``.
    """
    task = replay.task
    spec = task_spec(task)
    continuous = spec.continuous
    counts = replay.counts("visit")
    step_of_visit = np.repeat(np.arange(replay.n_steps), counts)
    last_visit = np.zeros(len(step_of_visit), dtype=bool)
    last_visit[replay["visit_offsets"][1:] - 1] = True
    x = replay["observation"][:, 0]
    y = replay["hidden_state"][:, spec.velocity_slot]
    bound = spec.bound
    action = np.clip(replay["a_c"], -bound, bound) if continuous else replay["a_d"] * 1.0
    teams = []
    for number in range(1, n_teams + 1):
        sel = replay["visit_team"] == number
        steps = step_of_visit[sel]
        teams.append(
            {
                "x": x[steps],
                "y": y[steps],
                "final": last_visit[sel],
                "action": action[steps],
            }
        )
    return {
        "task": task,
        "teams": teams,
        "continuous": continuous,
        "x_label": f"observed s[0] = {spec.observed.split(',')[0]}",
        "y_label": f"hidden {spec.velocity_name}",
    }
