"""Hand-made program graphs for the section-6 analysis tests (logical operand indices)."""

import numpy as np

from mtpg.model.graph import Population, atomic
from mtpg.model.instructions import OP_ABS, OP_ADD, OP_MUL, OP_SIN, RegisterLayout

L = RegisterLayout()
R1 = 1  # private register r[1] (always 0 when read first)
M1 = L.mem_start + 1  # memory register m[1]
S0 = L.obs_start  # observation s[0]
C09 = L.const_start + 17  # constant +0.9
CM09 = L.const_start  # constant -0.9


def code(*rows):
    return np.array(rows, dtype=np.int32)


def writer_every_k():
    """Root reads m[1] every step and visits a child that writes m[1] when s[0] > 0.

    Root (team 1): P1 bids sin(s[0]) and points to the child; P2 bids r[1] * m[1] = 0
    (reading m[1]) for action 1. Child (team 2): W writes m[1] <- |s[0]| (action 0), A
    bids -0.9 (action 2). Both share one bank.
    """
    pop = Population(layout=L)
    bank = pop.new_bank()
    child_w = pop.add_program(code([OP_ABS, M1, 0, S0]), atomic(0), bank)
    child_a = pop.add_program(code([OP_ADD, 0, CM09, R1]), atomic(2), bank)
    child = pop.add_team([child_w.id, child_a.id])
    p1 = pop.add_program(code([OP_SIN, 0, 0, S0]), child.id, bank)
    p2 = pop.add_program(code([OP_MUL, 0, R1, M1]), atomic(1), bank)
    root = pop.add_team([p1.id, p2.id])
    return pop, root.id


def cycle():
    """Root -> child -> root: the child's pointer back to the root bids highest.

    Root (team 1): P bids +0.9 to the child, Q bids -0.9 (action 0). Child (team 2): B
    points back to the root bidding +0.9, A bids -0.9 for action 1 (must be taken).
    """
    pop = Population(layout=L)
    bank = pop.new_bank()
    q = pop.add_program(code([OP_ADD, 0, CM09, R1]), atomic(0), bank)
    a = pop.add_program(code([OP_ADD, 0, CM09, R1]), atomic(1), bank)
    # placeholders pointing at atomic actions, re-pointed once both teams exist
    p = pop.add_program(code([OP_ADD, 0, C09, R1]), atomic(0), bank)
    b = pop.add_program(code([OP_ADD, 0, C09, R1]), atomic(0), bank)
    root = pop.add_team([p.id, q.id])
    child = pop.add_team([b.id, a.id])
    p.action = child.id
    b.action = root.id
    return pop, root.id


def single_team(action=0):
    """One team whose first program always wins with a fixed action (CartPole falls fast)."""
    pop = Population(layout=L)
    bank = pop.new_bank()
    w = pop.add_program(code([OP_ADD, 0, C09, R1], [OP_ADD, M1, C09, S0]), atomic(action), bank)
    o = pop.add_program(code([OP_ADD, 0, CM09, R1], [OP_SIN, 3, 0, S0]), atomic(1), bank)
    team = pop.add_team([w.id, o.id])
    return pop, team.id
