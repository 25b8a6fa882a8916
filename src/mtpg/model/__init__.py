"""The representation: linear register programs, teams, memory banks and program graphs."""

from mtpg.model.graph import Population, Program, Team, check_invariants
from mtpg.model.instructions import (
    CONSTANTS,
    N_CONSTANTS,
    N_OPS,
    OP_NAMES,
    RegisterLayout,
    disassemble,
    effective_mask,
    random_instructions,
)

__all__ = [
    "CONSTANTS",
    "N_CONSTANTS",
    "N_OPS",
    "OP_NAMES",
    "Population",
    "Program",
    "RegisterLayout",
    "Team",
    "check_invariants",
    "disassemble",
    "effective_mask",
    "random_instructions",
]
