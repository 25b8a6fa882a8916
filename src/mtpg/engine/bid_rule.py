"""The decision rule's bid comparison, written once for both compiled engines.

Each visited team runs all its programs in order; a program is *eligible* when its pointer
is atomic or leads to a team not yet visited in this decision, and it takes the lead from
the best bid so far only with a strictly higher bid (ties: the earlier program).
:func:`takes_lead` is that comparison; the scalar kernel
(:func:`mtpg.engine.episode_kernels.decide_bank`) and the lane engine
(:func:`mtpg.engine.lane_decide.run_team`) call it, inlined, with the best bid of a team
starting at :data:`NO_BID`. The plain-Python oracle (:mod:`mtpg.engine.oracle`) and each
exporter (:mod:`mtpg.export.python`, :mod:`mtpg.export.c`) state the same rule once each,
independently, and are tested against the engine.
"""

from __future__ import annotations

import numpy as np
from numba import njit

#: The best bid of a team before any program ran: below every bid, so the first eligible
#: program always takes the lead (every bid is finite: see :func:`takes_lead`).
NO_BID = -np.inf


@njit(cache=True, error_model="numpy", inline="always")
def takes_lead(act, marks, at, stamp, bid, best):
    """Whether a program takes the lead of its team's decision from the best bid so far.

    Eligible: its pointer ``act`` is atomic (``act < 0``), or the team it leads to is not
    marked visited in this decision (``marks[at] != stamp``; ``marks`` is read only for a
    pointer, so ``at`` may be anything for an atomic program). An eligible program takes
    the lead only with a bid strictly higher than ``best``: the earlier of equal bids
    keeps it. With ``best`` starting at :data:`NO_BID` (-inf), the first eligible program
    takes it.

    Bit-identical to the rule the engine had before this function (the scalar kernel took
    the first eligible program by a sentinel, ``best_p < 0 or bid > best``; the lane
    engine compared from -inf) because every bid is a finite number, so ``bid > -inf``
    holds exactly when the sentinel test did:

    * a bid is ``r[0]`` after the program ran: zeroed before the run, then written only by
      :func:`~mtpg.engine.ops.apply_op`, whose every op but the engine's copy ends in
      ``_clamp`` (``maxnum``/``minnum``: a NaN becomes ``-BIG``, an infinity ``+-BIG``),
      and whose copy reads a folded constant, itself an ``apply_op`` result or a zero;
    * the lane ops (:mod:`mtpg.engine.lane_ops`) compute the same values for the finite
      inputs the tasks give (observations in [-1, 1], constants, memory that starts at 0:
      :mod:`mtpg.model.instructions`).

    A NaN bid would differ between the two old spellings (the sentinel took a first NaN,
    -inf never does); none can arise, so the one rule changes no result.

    Args:
        act: The program's pointer: ``-1 - action`` when atomic, else a team.
        marks: int64 visit marks (the scalar kernel's ``team_stamp``, the lane engine's
            ``visited``).
        at: Index in ``marks`` of the pointed-to team's mark.
        stamp: This decision's mark.
        bid: The program's bid.
        best: The best bid of the team so far (:data:`NO_BID` before the first).

    Returns:
        True when the program becomes the team's winner so far.
    """
    return (act < 0 or marks[at] != stamp) and bid > best
