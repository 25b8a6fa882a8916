"""The representation: linear register programs, teams, memory banks and program graphs.

Plain Python and NumPy only: compiled code (Numba) lives in :mod:`mtpg.engine`, including
the effective-instruction analysis (:func:`mtpg.engine.compile.effective_mask`).
"""

from mtpg.model.graph import InvariantError, Population, Program, Team, check_invariants
from mtpg.model.instructions import (
    CONSTANTS,
    N_CONSTANTS,
    N_OPS,
    OP_NAMES,
    RegisterLayout,
    disassemble,
    random_instructions,
)

__all__ = [
    "CONSTANTS",
    "InvariantError",
    "N_CONSTANTS",
    "N_OPS",
    "OP_NAMES",
    "Population",
    "Program",
    "RegisterLayout",
    "Team",
    "check_invariants",
    "disassemble",
    "random_instructions",
]
