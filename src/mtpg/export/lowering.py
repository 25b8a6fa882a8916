"""Lowering a program to statements, evaluating at export time what does not vary.

Private registers start every run at 0 and constants are constants, so a part of many
programs computes the same values at every decision. :func:`lower` runs such instructions
once, at export time, with the engine's reference table
(:func:`mtpg.engine.oracle.reference_op`, bit-identical with the compiled engine),
and substitutes their results as literals. What is left reads the observation or memory.

Why here and not in the C compiler: a compiler folds calls such as ``exp(-0.3)`` with its
own correctly rounded arithmetic, which can differ in the last bit from the C library the
engine calls. The exporter evaluates them with the engine's own functions instead, and
the generated C calls the library through ``volatile`` pointers so the compiler cannot
fold what remains (see :mod:`mtpg.export.c`).

Memory registers are unknown (they persist across decisions), except in no-memory mode,
where the bank is zeroed before every run and so starts known. A write to memory is always
emitted, as a store of the literal when its value is known.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mtpg.engine.oracle import reference_op
from mtpg.model.instructions import CONSTANTS, OP_NAMES, RegisterLayout, operands_read

#: An operand: ``("r", i)``, ``("m", j)``, ``("s", k)`` or a literal ``("c", value)``.
Operand = tuple[str, int | float]


@dataclass(frozen=True)
class Statement:
    """One generated assignment: ``target = op(*args)``, or ``target = args[0]`` (no op).

    Attributes:
        target: ``("r", i)`` or ``("m", j)``.
        op: Operation name (:data:`mtpg.model.instructions.OP_NAMES`), or None for a
            store of a literal.
        args: The operands the operation reads, in argument order
            (:func:`~mtpg.model.instructions.operands_read`: the target's value, the
            first operand, the second operand, each where the op reads it).
    """

    target: Operand
    op: str | None
    args: tuple[Operand, ...]


def _logical(index: int, layout: RegisterLayout) -> Operand:
    if index < layout.mem_start:
        return "r", int(index)
    if index < layout.const_start:
        return "m", int(index - layout.mem_start)
    if index < layout.obs_start:
        return "c", float(CONSTANTS[index - layout.const_start])
    return "s", int(index - layout.obs_start)


def lower(
    code: np.ndarray, layout: RegisterLayout, no_memory: bool
) -> tuple[list[Statement], Operand, int]:
    """Turns effective instructions into statements with export-time constants folded.

    Args:
        code: int ``(n, 4)`` effective instructions (logical operand layout).
        layout: Register sizes.
        no_memory: The bank is zeroed before every run (memory starts known).

    Returns:
        ``(statements, bid, folded)``: the statements to emit, the bid (``("r", 0)`` or a
        literal) and the number of instructions evaluated at export time (memory writes
        among them are still emitted, as stores of literals).
    """
    known: dict[tuple[str, int], float] = {("r", i): 0.0 for i in range(layout.n_registers)}
    if no_memory:
        known.update({("m", j): 0.0 for j in range(layout.n_memory)})
    body: list[Statement] = []
    folded = 0

    def read(index: int) -> Operand:
        kind, value = _logical(int(index), layout)
        if kind in ("r", "m") and (kind, value) in known:
            return "c", known[(kind, value)]
        return kind, value

    for op, dst, a, b in np.asarray(code).tolist():
        target = _logical(dst, layout)
        names = operands_read(op)  # the operands the op reads, in argument order
        operand = {"d": dst, "a": a, "b": b}
        args = tuple(read(operand[name]) for name in names)
        if all(kind == "c" for kind, _ in args):
            values = {"d": 0.0, "a": 0.0, "b": 0.0}
            values.update((name, float(v)) for name, (_, v) in zip(names, args, strict=True))
            result = reference_op(op, values["d"], values["a"], values["b"])
            known[target] = result
            folded += 1
            if target[0] == "m":
                body.append(Statement(target, None, (("c", result),)))
        else:
            known.pop(target, None)
            body.append(Statement(target, OP_NAMES[op], args))
    bid = ("c", known[("r", 0)]) if ("r", 0) in known else ("r", 0)
    return body, bid, folded
