"""C99 code generation: one header and one source file, depending only on ``<math.h>``.

The generated API::

    void mtpg_reset(void);                                    /* zero all banks */
    void mtpg_act(const double obs[2], int *a_d, double *a_c); /* one decision */

Each program becomes a ``static`` function of straight-line code (introns removed,
values known at export time substituted, see :mod:`mtpg.export.lowering`) that runs on a
``static`` array of memory banks, so memory persists between calls until ``mtpg_reset``.
Each team becomes a ``case`` of a loop in ``mtpg_act`` that runs all its programs in order
and keeps the first highest bid among eligible programs, as the engine does. Compiled
with ``-DMTPG_TRACE``, ``mtpg_act`` also records the teams it visits.

Bit-identity: every protected operation is written as the engine's table
(:func:`mtpg.engine.ops.apply_op`), calling the same C library functions (``log``,
``pow``, ``exp``, ``cos``, ``sin``, ``tanh``, ``sqrt``) in the same order and clamping in
the same way; literals are printed as shortest round-trip decimals. The functions that
are not correctly rounded are called through ``volatile`` pointers, so no compiler can
evaluate them at compile time with its own (correctly rounded) arithmetic: the last-bit
difference that caused is what the tests first caught. With IEEE double arithmetic (SSE2
or any FPU without extended precision) and no floating-point contraction
(``-ffp-contract=off``; no ``-ffast-math``), results equal the engine's bit for bit as
long as the C library's ``log``/``pow``/``exp``/``cos``/``sin``/``tanh`` are the ones the
engine ran with (the same libm; other libms may differ in the last bit).
"""

from __future__ import annotations

from mtpg.export.common import TABLE_CONSTANTS, ExportGraph, ExportProgram, action_text
from mtpg.export.lowering import Operand
from mtpg.model.instructions import OP_NAMES, operands_read

#: C library functions that are not correctly rounded, by the ops calling them. They are
#: called through volatile pointers so that no compiler can evaluate them at compile time
#: (compilers fold calls on constant arguments with their own correctly rounded arithmetic,
#: which may differ from the library's in the last bit) or rewrite them (``pow(x, 0.5)`` as
#: ``sqrt(x)``). ``sqrt`` and ``fabs`` are exact, so they are called directly.
_LIBM: dict[str, tuple[str, ...]] = {
    "pow": ("log", "pow"),
    "cos": ("cos",),
    "ln": ("log",),
    "exp": ("exp",),
    "sin": ("sin",),
    "tanh": ("tanh",),
}

#: Body of each protected operation; its parameters are the operands it reads
#: (:func:`~mtpg.model.instructions.operands_read`; ``d`` is the target's current value).
_OPS: dict[str, str] = {
    "add": "return mtpg_clamp(a + b);",
    "sub": "return mtpg_clamp(a - b);",
    "mul": "return mtpg_clamp(a * b);",
    "div": "return mtpg_clamp(fabs(b) < MTPG_DIV_EPS ? a : a / b);",
    "pow": (
        "double x = fabs(a), e;\n"
        "    if (x == 0.0)\n        return 0.0;\n"
        "    e = b * mtpg_log(x);\n"
        "    if (e > MTPG_LOG_BIG)\n        return MTPG_BIG;\n"
        "    if (e < MTPG_LOG_TINY)\n        return 0.0;\n"
        "    return mtpg_clamp(mtpg_pow(x, b));"
    ),
    "cos": "return mtpg_clamp(mtpg_cos(b));",
    "ln": "return mtpg_clamp(b == 0.0 ? 0.0 : mtpg_log(fabs(b)));",
    "exp": "return mtpg_clamp(b > MTPG_LOG_BIG ? MTPG_BIG : mtpg_exp(b));",
    "sqrt": "return mtpg_clamp(sqrt(fabs(b)));",
    "sin": "return mtpg_clamp(mtpg_sin(b));",
    "tanh": "return mtpg_clamp(mtpg_tanh(b));",
    "square": "return mtpg_clamp(b * b);",
    "abs": "return mtpg_clamp(fabs(b));",
    "cube": "return mtpg_clamp(b * b * b);",
    "if_lt": "return mtpg_clamp(a < b ? -d : d);",
    "if_gt": "return mtpg_clamp(a > b ? -d : d);",
}


def op_function(name: str) -> str:
    """The generated function of operation ``name``: one parameter per operand it reads."""
    params = ", ".join(f"double {x}" for x in operands_read(OP_NAMES.index(name)))
    return f"static double mtpg_op_{name}({params})\n{{\n    {_OPS[name]}\n}}"


def _params(function: str) -> str:
    return "double, double" if function == "pow" else "double"


def _literal(value: float) -> str:
    """A C double literal that parses back to exactly ``value``."""
    text = repr(float(value))
    return f"({text})" if text.startswith("-") else text


def _comment(lines: list[tuple[str, str]], indent: str = " * ") -> str:
    width = max(len(label) for label, _ in lines)
    return "\n".join(
        f"{indent}{label + ':':<{width + 1}} {value.replace('*/', '* /')}" for label, value in lines
    )


def _operand(operand: Operand) -> str:
    kind, value = operand
    return _literal(float(value)) if kind == "c" else f"{kind}[{value}]"


def _program_function(graph: ExportGraph, k: int, prog: ExportProgram) -> str:
    """The ``static double mtpg_pK(const double *s)`` function of one program."""
    lines = []
    for st in prog.body:
        value = (
            _operand(st.args[0])
            if st.op is None
            else f"mtpg_op_{st.op}({', '.join(_operand(x) for x in st.args)})"
        )
        lines.append(f"    {_operand(st.target)} = {value};")
    kinds = {x[0] for st in prog.body for x in (st.target, *st.args)} | {prog.bid[0]}
    head = [
        f"/* program {prog.id}: bank {graph.bank_ids[prog.bank]}, {len(prog.code)} of "
        f"{prog.n_total} instructions effective, {prog.folded} evaluated at export time */",
        f"static double mtpg_p{k}(const double *s)",
        "{",
    ]
    if "r" in kinds:
        head.append(f"    double r[{graph.layout.n_registers}] = {{0.0}};")
    if "m" in kinds or graph.no_memory:
        head.append(f"    double *m = mtpg_mem[{prog.bank}];")
    if "s" not in kinds:
        head.append("    (void)s;")
    if graph.no_memory:
        head.append("    mtpg_zero_bank(m); /* memory off: the bank is zeroed before every run */")
    return "\n".join(head + lines + [f"    return {_operand(prog.bid)};", "}"])


def _takes_lead(prog: ExportProgram) -> str:
    """The engine's bid rule (:func:`mtpg.engine.bid_rule.takes_lead`) as a C condition.

    Eligible: atomic, or pointing to a team not visited in this decision; then the first
    eligible program (``!have``), or a strictly higher bid (ties: the earlier program).
    """
    lead = "!have || bid > best"
    return lead if prog.is_atomic else f"!visited[{prog.target}] && ({lead})"


def _team_case(graph: ExportGraph, t: int) -> str:
    lines = [f"        case {t}: /* team {graph.team_ids[t]} */"]
    for k in graph.teams[t]:
        prog = graph.programs[k]
        lines.append(f"            bid = mtpg_p{k}(obs);")
        if prog.is_atomic:
            take = f"next = {prog.target}; bank = {prog.bank};"
            what = f"program {prog.id}: action {-1 - prog.target}"
        else:
            take = f"next = {prog.target};"
            what = f"program {prog.id}: team {graph.team_ids[prog.target]}"
        lines.append(f"            if ({_takes_lead(prog)}) {{ /* {what} */")
        lines.append(f"                have = 1; best = bid; {take}")
        lines.append("            }")
    lines.append("            break;")
    return "\n".join(lines)


def _memory_phrase(graph: ExportGraph) -> str:
    if graph.no_memory:
        return "Memory off: each program zeroes its bank before it runs"
    return "Memory persists between calls"


def header_text(graph: ExportGraph, name: str) -> str:
    """The ``.h`` file: API, sizes, provenance and the bit-identity conditions."""
    guard = "".join(ch if ch.isalnum() else "_" for ch in name).upper() + "_H"
    actions = action_text(graph.layout.n_actions)
    return f"""/* {name}.h: an mtpg program graph as standalone C99 code (generated by mtpg export).
 *
{_comment(graph.provenance)}
 *
 * API: call mtpg_reset() at the start of every episode (it zeroes all memory banks),
 * then mtpg_act() once per step. The state is static: one agent per program (not
 * reentrant). {_memory_phrase(graph)}.
 *
 * Bit-identity: compiled as C99 with IEEE double arithmetic and WITHOUT floating-point
 * contraction (gcc/clang: -ffp-contract=off; never -ffast-math), every a_d and a_c equals
 * the mtpg engine's bit for bit, given the same C library math functions (log, pow, exp,
 * cos, sin, tanh) as the engine ran with; those are called through volatile pointers so
 * that the compiler cannot evaluate them at compile time with its own rounding. Compile
 * with -DMTPG_TRACE to record the teams each decision visits.
 */
#ifndef {guard}
#define {guard}

#define MTPG_N_TEAMS {len(graph.teams)}
#define MTPG_N_BANKS {len(graph.bank_ids)}
#define MTPG_N_MEMORY {graph.layout.n_memory}

#ifdef __cplusplus
extern "C" {{
#endif

/* Zeroes every memory bank: call at the start of every episode. */
void mtpg_reset(void);

/* One decision for observation obs: the discrete action ({actions}) in *a_d and the
 * continuous output (m[0] of the winning program's memory bank) in *a_c. */
void mtpg_act(const double obs[{graph.layout.n_obs}], int *a_d, double *a_c);

/* After mtpg_act: m[0..n) of the winning program's bank in out[0..n) (n at most
 * MTPG_N_MEMORY), a task's continuous dimensions j = 0..n-1; out[0] equals *a_c. */
void mtpg_continuous(int n, double *out);

#ifdef MTPG_TRACE
/* Teams visited by the last decision (ids of the graph file), in order. */
extern int mtpg_trace_n;
extern int mtpg_trace_teams[MTPG_N_TEAMS];
#endif

#ifdef __cplusplus
}}
#endif

#endif /* {guard} */
"""


def source_text(graph: ExportGraph, name: str) -> str:
    """The ``.c`` file: protected operations, programs, ``mtpg_reset`` and ``mtpg_act``."""
    used = sorted({st.op for p in graph.programs for st in p.body if st.op is not None})
    consts = "\n".join(
        f"#define MTPG_{key} {_literal(value)}" for key, value in TABLE_CONSTANTS.items()
    )
    parts = [
        f"/* {name}.c: generated by mtpg export; see {name}.h for the API and provenance.\n"
        f" * {graph.summary()}. */",
        f'#include <math.h>\n\n#include "{name}.h"',
        "/* The protected operation table of the mtpg engine (mtpg.model.instructions). */\n"
        + consts,
        f"static double mtpg_mem[MTPG_N_BANKS][MTPG_N_MEMORY]; /* bank ids: "
        f"{', '.join(str(b) for b in graph.bank_ids)} */",
        "#ifdef MTPG_TRACE\nint mtpg_trace_n;\nint mtpg_trace_teams[MTPG_N_TEAMS];\n"
        "static const int mtpg_team_ids[MTPG_N_TEAMS] = {"
        + ", ".join(str(t) for t in graph.team_ids)
        + "};\n#endif",
        "/* The bank of the last decision: its m[0..n) are a task's n continuous outputs. */\n"
        "static int mtpg_last_bank = 0;",
        "static void mtpg_zero_bank(double *m)\n{\n    int j;\n"
        "    for (j = 0; j < MTPG_N_MEMORY; j++)\n        m[j] = 0.0;\n}",
    ]
    libm = sorted({f for op in used for f in _LIBM.get(op, ())})
    if libm:
        parts.append(
            "/* The C library's log, pow, exp, cos, sin and tanh are called through volatile\n"
            " * pointers: a compiler can then neither evaluate them at compile time (with its\n"
            " * own, correctly rounded arithmetic, which may differ from the library's in the\n"
            " * last bit) nor rewrite them (pow(x, 0.5) as sqrt(x)). */\n"
            + "\n".join(
                f"static double (*const volatile mtpg_{f})({_params(f)}) = {f};" for f in libm
            )
        )
    if used:
        parts.append(
            "static double mtpg_clamp(double v)\n{\n    if (v > MTPG_BIG)\n        return MTPG_BIG;"
            "\n    if (v < -MTPG_BIG)\n        return -MTPG_BIG;\n    return v;\n}"
        )
    parts.extend(op_function(op) for op in used)
    for k, prog in enumerate(graph.programs):
        parts.append(_program_function(graph, k, prog))
    parts.append(
        "void mtpg_reset(void)\n{\n    int b;\n    for (b = 0; b < MTPG_N_BANKS; b++)\n"
        "        mtpg_zero_bank(mtpg_mem[b]);\n}"
    )
    parts.append(_act_function(graph))
    parts.append(
        "void mtpg_continuous(int n, double *out)\n{\n    int j;\n"
        "    for (j = 0; j < n && j < MTPG_N_MEMORY; j++)\n"
        "        out[j] = mtpg_mem[mtpg_last_bank][j];\n}"
    )
    return "\n\n".join(parts) + "\n"


def _act_function(graph: ExportGraph) -> str:
    pointers = any(not p.is_atomic for p in graph.programs)
    decl = ["    int team = 0;"]
    if pointers:
        decl = [
            "    unsigned char visited[MTPG_N_TEAMS];",
            "    int team = 0, i;",
            "    for (i = 0; i < MTPG_N_TEAMS; i++)",
            "        visited[i] = 0;",
        ]
    cases = "\n".join(_team_case(graph, t) for t in range(len(graph.teams)))
    return "\n".join(
        [
            f"void mtpg_act(const double obs[{graph.layout.n_obs}], int *a_d, double *a_c)",
            "{",
            *decl,
            "#ifdef MTPG_TRACE",
            "    mtpg_trace_n = 0;",
            "#endif",
            "    for (;;) {",
            "        int have = 0, next = -1, bank = 0;",
            "        double best = 0.0, bid;",
            *(["        visited[team] = 1;"] if pointers else []),
            "#ifdef MTPG_TRACE",
            "        mtpg_trace_teams[mtpg_trace_n++] = mtpg_team_ids[team];",
            "#endif",
            "        switch (team) {",
            cases,
            "        default:",
            "            break;",
            "        }",
            "        if (next < 0) {",
            "            *a_d = -1 - next;",
            "            *a_c = mtpg_mem[bank][0];",
            "            mtpg_last_bank = bank;",
            "            return;",
            "        }",
            "        team = next;",
            "    }",
            "}",
        ]
    )


def write_c(graph: ExportGraph, directory, name: str = "mtpg_graph") -> tuple:
    """Writes ``name.h`` and ``name.c`` into ``directory`` (created if missing).

    Args:
        graph: The prepared graph.
        directory: Output directory (``str`` or path).
        name: Base name of the two files (letters, digits and ``_``).

    Returns:
        ``(header path, source path)``.
    """
    from pathlib import Path

    if not name or not all(ch.isalnum() or ch == "_" for ch in name):
        raise ValueError(f"--name must be letters, digits and '_', got {name!r}")
    out = Path(directory)
    out.mkdir(parents=True, exist_ok=True)
    header, source = out / f"{name}.h", out / f"{name}.c"
    header.write_text(header_text(graph, name), encoding="utf-8")
    source.write_text(source_text(graph, name), encoding="utf-8")
    return header, source
