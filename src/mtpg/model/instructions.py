"""The instruction set of the linear register programs (paper Table 2 and Algorithm 1).

An instruction is four integers ``(op, dst, src1, src2)``. Operands index one logical
register file per program execution, laid out as

==================  ==========================================  =============
range               registers                                   access
==================  ==========================================  =============
``[0, R)``          private bank ``r`` (zeroed every execution)  read / write
``[R, R+M)``        the program's shared memory bank ``m``      read / write
``[R+M, R+M+18)``   the constants -0.9 ... -0.1, 0.1 ... 0.9    read only
``[R+M+18, +2)``    the observation ``s(t)``                    read only
==================  ==========================================  =============

with ``R = n_registers`` (8) and ``M = n_memory`` (8). The operand rules of Algorithm 1
follow from the ranges: ``dst`` is in r or m, ``src1`` in r, m or the constants,
``src2`` anywhere. Binary operations compute ``dst <- src1 o src2``; unary operations read
the second operand, ``dst <- o(src2)`` (Table 2 writes them ``r_x[i] <- o(r_y[j])``, with
``r_y[j]`` the second operand of the binary form, which lets a unary operation read the
observation); conditionals negate ``dst`` when ``src1 < src2`` (or ``>``).

Protected semantics: every register stays finite. With ``BIG = 1e10``:

=========  =====================================================================
operation  result
=========  =====================================================================
``+ - *``  plain IEEE result, then clamped to ``[-BIG, BIG]``
``/``      ``a / b``, clamped; ``a`` unchanged when ``|b| < 1e-12`` (no division)
``pow``    ``|a| ** b``; 0 when ``a == 0``; ``BIG`` when ``b * ln|a| > ln BIG``;
           0 when ``b * ln|a| < -700``
``cos``    ``cos(b)``
``ln``     ``ln|b|``; 0 when ``b == 0``
``exp``    ``exp(b)``, clamped (``exp(b) = BIG`` when ``b > ln BIG``)
``sqrt``   ``sqrt(|b|)``
``sin``    ``sin(b)``
``tanh``   ``tanh(b)``
``x^2``    ``b * b``, clamped
``|x|``    ``|b|``
``x^3``    ``b * b * b``, clamped
``IF <``   ``dst <- -dst`` when ``a < b``
``IF >``   ``dst <- -dst`` when ``a > b``
=========  =====================================================================

Inputs to every operation are finite and within ``[-BIG, BIG]`` (observations are in
[-1, 1], memory starts at 0), so the table above covers every case: no NaN or infinity
can arise. The execution engine and the reference interpreter both implement exactly this
table with the same floating-point operations, so they agree bit for bit.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Bits of an :data:`OP_READS` entry: the operands an op code reads. ``READS_TARGET``: the
#: target's old value (the conditionals, which may negate it); ``READS_A``: the first
#: operand ``src1``; ``READS_B``: the second operand ``src2``.
READS_TARGET, READS_A, READS_B = 1, 2, 4
_BINARY = READS_A | READS_B
_UNARY = READS_B
_CONDITIONAL = READS_TARGET | READS_A | READS_B

#: The op semantics table, one row per op code in op-code order: the op's name and the
#: operands it reads. Every part of the package that asks which operands an instruction
#: reads (intron removal, constant folding, the lane engine's register zeroing, the
#: tracer's memory log, the exporters and :func:`disassemble`) reads this table; the
#: arithmetic of each op is written in :func:`mtpg.engine.ops.apply_op` (and its lane,
#: reference and exported copies, tested against it). The last row, ``copy``
#: (:data:`OP_COPY`: ``dst <- src2``), is the engine's own: constant folding writes it,
#: no program holds it. Adding an op is one row here, before ``copy``, plus its
#: arithmetic; tests/engine/test_op_reads.py proves every consumer agrees with the table.
OP_TABLE: tuple[tuple[str, int], ...] = (
    ("add", _BINARY),
    ("sub", _BINARY),
    ("mul", _BINARY),
    ("div", _BINARY),
    ("pow", _BINARY),
    ("cos", _UNARY),
    ("ln", _UNARY),
    ("exp", _UNARY),
    ("sqrt", _UNARY),
    ("sin", _UNARY),
    ("tanh", _UNARY),
    ("square", _UNARY),
    ("abs", _UNARY),
    ("cube", _UNARY),
    ("if_lt", _CONDITIONAL),
    ("if_gt", _CONDITIONAL),
    ("copy", _UNARY),
)
#: Engine-only op code (never in a program): ``dst <- src2``, the copy that constant
#: folding (:mod:`mtpg.engine.fold`) writes where a known value must reach a register.
OP_COPY = len(OP_TABLE) - 1
#: The operands each op code reads (``READS_*`` bits), indexed by op code, ``OP_COPY``
#: included: an int64 array, so compiled kernels index it as a constant.
OP_READS = np.array([reads for _, reads in OP_TABLE], dtype=np.int64)
OP_READS.flags.writeable = False
#: Operation codes of programs, in op-code order.
OP_NAMES: tuple[str, ...] = tuple(name for name, _ in OP_TABLE[:OP_COPY])
N_OPS = len(OP_NAMES)
OP_ADD, OP_SUB, OP_MUL, OP_DIV, OP_POW = range(5)
OP_COS, OP_LN, OP_EXP, OP_SQRT, OP_SIN, OP_TANH, OP_SQUARE, OP_ABS, OP_CUBE = range(5, 14)
OP_IF_LT, OP_IF_GT = 14, 15
#: Op codes whose result depends on the first operand (binary operations).
BINARY_OPS = frozenset(op for op in range(N_OPS) if OP_READS[op] == _BINARY)
#: Op codes reading only the second operand.
UNARY_OPS = frozenset(op for op in range(N_OPS) if OP_READS[op] == _UNARY)
#: Op codes that read the target and may negate it.
CONDITIONAL_OPS = frozenset(op for op in range(N_OPS) if OP_READS[op] & READS_TARGET)


def operands_read(op: int) -> tuple[str, ...]:
    """The operands op code ``op`` reads (:data:`OP_READS`), in argument order.

    ``"d"`` is its target's old value, ``"a"`` the first operand (``src1``), ``"b"`` the
    second (``src2``): ``("a", "b")`` for ``add``, ``("b",)`` for ``cos``, ``("d", "a",
    "b")`` for ``if_lt``. The exported operation functions take these parameters.
    """
    reads = int(OP_READS[op])
    return tuple(
        name for name, bit in (("d", READS_TARGET), ("a", READS_A), ("b", READS_B)) if reads & bit
    )


#: The read-only constants appended to the private bank (Table 2).
CONSTANTS = np.array(
    [
        -0.9,
        -0.8,
        -0.7,
        -0.6,
        -0.5,
        -0.4,
        -0.3,
        -0.2,
        -0.1,
        0.1,
        0.2,
        0.3,
        0.4,
        0.5,
        0.6,
        0.7,
        0.8,
        0.9,
    ]
)
N_CONSTANTS = len(CONSTANTS)
#: Magnitude bound of every register value.
BIG = 1e10
#: ``ln(BIG)``: exponent above which ``exp`` and ``pow`` saturate.
LOG_BIG = float(np.log(BIG))
#: Denominators smaller than this in magnitude leave the numerator unchanged.
DIV_EPS = 1e-12
#: ``pow`` results whose log is below this are 0.
LOG_TINY = -700.0


@dataclass(frozen=True, slots=True)
class RegisterLayout:
    """Sizes of what a program sees and emits: its register file, inputs and actions.

    The inputs and the atomic actions are the run's tasks' (the paper's six: 2 and 3; the
    largest over the tasks of a run, :attr:`mtpg.envs.taskset.task_table.TaskTable.shape`).
    """

    n_registers: int = 8
    """Private stateless registers ``r``; ``r[0]`` is the program's bid."""
    n_memory: int = 8
    """Registers of a shared stateful memory bank ``m``; ``m[0]`` is the continuous output
    (``m[j]`` the continuous action's dimension ``j``)."""
    n_obs: int = 2
    """Observed inputs ``s(t)``."""
    n_actions: int = 3
    """Atomic actions a program may hold (``0 .. n_actions - 1``)."""

    def __post_init__(self) -> None:
        for name in ("n_registers", "n_memory", "n_obs", "n_actions"):
            if getattr(self, name) < 1:
                raise ValueError(f"{name} must be >= 1, got {getattr(self, name)}")

    @property
    def mem_start(self) -> int:
        """First logical index of the memory bank."""
        return self.n_registers

    @property
    def const_start(self) -> int:
        """First logical index of the constants."""
        return self.n_registers + self.n_memory

    @property
    def obs_start(self) -> int:
        """First logical index of the observation."""
        return self.const_start + N_CONSTANTS

    @property
    def size(self) -> int:
        """Number of logical registers."""
        return self.obs_start + self.n_obs

    def name(self, index: int) -> str:
        """Human-readable name of a logical register, e.g. ``r[3]``, ``m[0]``, ``s[1]``."""
        if index < self.mem_start:
            return f"r[{index}]"
        if index < self.const_start:
            return f"m[{index - self.mem_start}]"
        if index < self.obs_start:
            return f"{CONSTANTS[index - self.const_start]:+.1f}"
        return f"s[{index - self.obs_start}]"


def _random_operand(
    rng: np.random.Generator, layout: RegisterLayout, kinds: int, n: int
) -> np.ndarray:
    """Draws operand indices: a bank uniformly among the first ``kinds``, then an index.

    Banks, in order: r (with the constants), m, s. Choosing the bank first (as the
    authors' code does) keeps observations at one third of second operands instead of
    the 2-in-36 a uniform index would give.
    """
    kind = rng.integers(0, kinds, size=n)
    r_pick = rng.integers(0, layout.n_registers + N_CONSTANTS, size=n)
    r_index = np.where(
        r_pick < layout.n_registers, r_pick, layout.const_start + r_pick - layout.n_registers
    )
    m_index = layout.mem_start + rng.integers(0, layout.n_memory, size=n)
    s_index = layout.obs_start + rng.integers(0, layout.n_obs, size=n)
    return np.choose(kind, [r_index, m_index, s_index]).astype(np.int32)


def random_instructions(rng: np.random.Generator, layout: RegisterLayout, n: int) -> np.ndarray:
    """Draws ``n`` random valid instructions.

    The target is in r or m (one half each, then a uniform index), the first operand in
    r-with-constants or m, the second in r-with-constants, m or s (one third each).

    Args:
        rng: The generator to draw from.
        layout: Register sizes.
        n: Number of instructions.

    Returns:
        int32 array of shape ``(n, 4)``: ``op, dst, src1, src2``.
    """
    out = np.empty((n, 4), dtype=np.int32)
    out[:, 0] = rng.integers(0, N_OPS, size=n)
    dst_mem = rng.integers(0, 2, size=n)
    out[:, 1] = np.where(
        dst_mem == 1,
        layout.mem_start + rng.integers(0, layout.n_memory, size=n),
        rng.integers(0, layout.n_registers, size=n),
    )
    out[:, 2] = _random_operand(rng, layout, 2, n)
    out[:, 3] = _random_operand(rng, layout, 3, n)
    return out


def valid_instructions(instructions: np.ndarray, layout: RegisterLayout) -> str | None:
    """Checks operand ranges.

    Args:
        instructions: int array ``(n, 4)``.
        layout: Register sizes.

    Returns:
        None when valid, else a description of the first problem.
    """
    if instructions.ndim != 2 or instructions.shape[1] != 4 or len(instructions) == 0:
        return f"instructions must be a non-empty (n, 4) array, got shape {instructions.shape}"
    op, dst, a, b = (instructions[:, k] for k in range(4))
    for name, values, hi in (
        ("op", op, N_OPS),
        ("dst", dst, layout.const_start),
        ("src1", a, layout.obs_start),
        ("src2", b, layout.size),
    ):
        if values.min() < 0 or values.max() >= hi:
            return f"{name} out of range [0, {hi})"
    return None


def disassemble(instructions: np.ndarray, layout: RegisterLayout) -> list[str]:
    """Renders instructions as text lines, e.g. ``m[0] <- m[7] / s[1]``."""
    symbols = {"add": "+", "sub": "-", "mul": "*", "div": "/", "pow": "^"}
    lines = []
    for op, dst, a, b in instructions:
        name = OP_NAMES[op]
        d, x, y = layout.name(dst), layout.name(a), layout.name(b)
        if op in BINARY_OPS:
            lines.append(f"{d} <- {x} {symbols[name]} {y}")
        elif op in UNARY_OPS:
            lines.append(f"{d} <- {name}({y})")
        else:
            cmp = "<" if op == OP_IF_LT else ">"
            lines.append(f"if {x} {cmp} {y}: {d} <- -{d}")
    return lines
