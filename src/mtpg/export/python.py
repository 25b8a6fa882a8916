"""Python code generation: one module needing nothing but the standard library's ``math``.

The generated module has ``reset()`` (zero all memory banks: episode start) and
``act(obs) -> (a_d, a_c)`` (one decision; memory persists between calls), plus
``TEAM_IDS`` and ``last_teams`` (the team ids the last decision visited).

Bit-identity: Python floats are IEEE doubles and the protected operations are written as
the engine's table (:func:`mtpg.engine.ops.apply_op`) with the functions the engine's
reference interpreter uses (``math.log``, ``math.pow``, ``math.exp``, ``math.cos``,
``math.sin``, ``math.tanh``, ``math.sqrt``, ``abs``). Every input to them is finite and
within the clamp bound, where CPython's ``math`` functions return the C library's result
(they add only error checks for non-finite or overflowing results, which the protection
rules out), so the module agrees with the engine bit for bit on the same C library.
``math.pow`` is used rather than ``**`` because that is what the engine computes.
"""

from __future__ import annotations

from pathlib import Path

from mtpg.export.common import TABLE_CONSTANTS, ExportGraph, ExportProgram, action_text
from mtpg.export.lowering import Operand
from mtpg.model.instructions import OP_NAMES, operands_read

#: Body of each protected operation; its parameters are the operands it reads
#: (:func:`~mtpg.model.instructions.operands_read`: ``d`` target, ``a``/``b`` operands).
_OPS: dict[str, str] = {
    "add": "return _clamp(a + b)",
    "sub": "return _clamp(a - b)",
    "mul": "return _clamp(a * b)",
    "div": "return _clamp(a if abs(b) < DIV_EPS else a / b)",
    "pow": (
        "x = abs(a)\n    if x == 0.0:\n        return 0.0\n    e = b * math.log(x)\n"
        "    if e > LOG_BIG:\n        return BIG\n    if e < LOG_TINY:\n        return 0.0\n"
        "    return _clamp(math.pow(x, b))"
    ),
    "cos": "return _clamp(math.cos(b))",
    "ln": "return _clamp(0.0 if b == 0.0 else math.log(abs(b)))",
    "exp": "return _clamp(BIG if b > LOG_BIG else math.exp(b))",
    "sqrt": "return _clamp(math.sqrt(abs(b)))",
    "sin": "return _clamp(math.sin(b))",
    "tanh": "return _clamp(math.tanh(b))",
    "square": "return _clamp(b * b)",
    "abs": "return _clamp(abs(b))",
    "cube": "return _clamp(b * b * b)",
    "if_lt": "return _clamp(-d if a < b else d)",
    "if_gt": "return _clamp(-d if a > b else d)",
}


def op_function(name: str) -> str:
    """The generated function of operation ``name``: one parameter per operand it reads."""
    params = ", ".join(operands_read(OP_NAMES.index(name)))
    return f"def _{name}({params}):\n    {_OPS[name]}"


def _operand(operand: Operand) -> str:
    kind, value = operand
    if kind == "c":
        return repr(float(value))
    return f"r{value}" if kind == "r" else f"{kind}[{value}]"


def _program_function(graph: ExportGraph, k: int, prog: ExportProgram) -> str:
    body = []
    for st in prog.body:
        args = ", ".join(_operand(x) for x in st.args)
        value = args if st.op is None else f"_{st.op}({args})"
        body.append(f"    {_operand(st.target)} = {value}")
    kinds = {x[0] for st in prog.body for x in (st.target, *st.args)}
    head = [
        f"def _p{k}(s):",
        f'    """Program {prog.id}: bank {graph.bank_ids[prog.bank]}, {len(prog.code)} of '
        f'{prog.n_total} instructions effective, {prog.folded} evaluated at export."""',
    ]
    if graph.no_memory or "m" in kinds:
        head.append(f"    m = _MEM[{prog.bank}]")
    if graph.no_memory:
        head.append("    m[:] = _ZEROS  # memory off: the bank is zeroed before every run")
    # a register is read only after a generated statement wrote it (values known at
    # export time are substituted), so none needs initialising
    return "\n".join(head + body + [f"    return {_operand(prog.bid)}"])


def _takes_lead(prog: ExportProgram) -> str:
    """The engine's bid rule (:func:`mtpg.engine.bid_rule.takes_lead`) as a condition.

    Eligible: atomic, or pointing to a team not visited in this decision; then the first
    eligible program (``not have``), or a strictly higher bid (ties: the earlier program).
    """
    lead = "not have or bid > best"
    return lead if prog.is_atomic else f"not visited[{prog.target}] and ({lead})"


def _team_function(graph: ExportGraph, t: int) -> str:
    lines = [
        f"def _t{t}(s, visited):",
        f'    """Team {graph.team_ids[t]}: returns (next team or -1 - action, winner bank)."""',
        "    have, best, nxt, bank = False, 0.0, -1, 0",
    ]
    for k in graph.teams[t]:
        prog = graph.programs[k]
        lines.append(f"    bid = _p{k}(s)")
        if prog.is_atomic:
            what = f"action {-1 - prog.target}"
            take = f"have, best, nxt, bank = True, bid, {prog.target}, {prog.bank}"
        else:
            what = f"team {graph.team_ids[prog.target]}"
            take = f"have, best, nxt = True, bid, {prog.target}"
        lines.append(f"    if {_takes_lead(prog)}:  # program {prog.id}: {what}")
        lines.append(f"        {take}")
    lines.append("    return nxt, bank")
    return "\n".join(lines)


def _numbers(n: int) -> str:
    return "two numbers" if n == 2 else f"{n} numbers"


def module_text(graph: ExportGraph) -> str:
    """The whole generated module."""
    width = max(len(label) for label, _ in graph.provenance)
    prov = "\n".join(f"    {label + ':':<{width + 1}} {value}" for label, value in graph.provenance)
    used = sorted({st.op for p in graph.programs for st in p.body if st.op is not None})
    n_mem, n_obs = graph.layout.n_memory, graph.layout.n_obs
    inputs = "two observations" if n_obs == 2 else f"{n_obs} observations"
    actions = action_text(graph.layout.n_actions)
    memory = (
        "Memory off: each program zeroes its bank before it runs"
        if graph.no_memory
        else "Memory persists between calls"
    )
    parts = [
        f'''"""An mtpg program graph as a standalone Python module (generated by mtpg export).

{prov}

Usage: call reset() at the start of every episode (it zeroes all memory banks), then
act(obs) once per step with the {inputs}; it returns (a_d, a_c): the discrete
action ({actions}) and the continuous output (m[0] of the winning program's memory bank);
continuous(n) then gives that bank's m[0..n), a task's n continuous dimensions.
{memory}.
Needs only the standard library; the results equal the mtpg engine's bit for bit (IEEE
doubles, same C library math functions).
"""

import math''',
        "\n".join(f"{key} = {value!r}" for key, value in TABLE_CONSTANTS.items()),
        f"#: Source id of each team; index 0 is the root.\nTEAM_IDS = "
        f"{tuple(graph.team_ids)!r}\n#: Memory banks (source ids {list(graph.bank_ids)}).\n"
        f"_MEM = [[0.0] * {n_mem} for _ in range({len(graph.bank_ids)})]\n"
        f"_ZEROS = [0.0] * {n_mem}\n#: Team ids visited by the last decision, in order.\n"
        "last_teams = []\n#: The bank of the last decision.\n_LAST = [0]",
        'def reset():\n    """Zeroes every memory bank: call at the start of every episode."""\n'
        "    for bank in _MEM:\n        bank[:] = _ZEROS",
        "def _clamp(v):\n    if v > BIG:\n        return BIG\n"
        "    if v < -BIG:\n        return -BIG\n    return v",
    ]
    parts.extend(op_function(op) for op in used)
    parts.extend(_program_function(graph, k, p) for k, p in enumerate(graph.programs))
    parts.extend(_team_function(graph, t) for t in range(len(graph.teams)))
    parts.append(f"_TEAMS = ({', '.join(f'_t{t}' for t in range(len(graph.teams)))},)")
    parts.append(
        "def act(obs):\n"
        f'    """One decision for observation obs ({_numbers(n_obs)}): returns (a_d, a_c)."""\n'
        f"    s = ({', '.join(f'float(obs[{i}])' for i in range(n_obs))}{',' * (n_obs == 1)})\n"
        f"    visited = [False] * {len(graph.teams)}\n"
        "    del last_teams[:]\n"
        "    team = 0\n"
        "    while True:\n"
        "        visited[team] = True\n"
        "        last_teams.append(TEAM_IDS[team])\n"
        "        nxt, bank = _TEAMS[team](s, visited)\n"
        "        if nxt < 0:\n"
        "            _LAST[0] = bank\n"
        "            return -1 - nxt, _MEM[bank][0]\n"
        "        team = nxt"
    )
    parts.append(
        "def continuous(n):\n"
        '    """m[0..n) of the bank of the last decision: n continuous outputs."""\n'
        f"    return tuple(_MEM[_LAST[0]][:min(n, {n_mem})])"
    )
    return "\n\n\n".join(parts) + "\n"


def write_python(graph: ExportGraph, path) -> Path:
    """Writes the module to ``path`` (its directory is created if missing).

    Args:
        graph: The prepared graph.
        path: Destination ``.py`` file.

    Returns:
        The path written.
    """
    out = Path(path)
    if out.suffix != ".py":
        raise ValueError(f"--out must name a .py file for --lang python, got {out}")
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(module_text(graph), encoding="utf-8")
    return out
