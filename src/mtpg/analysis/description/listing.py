"""A program graph as a researcher reads it: the text listing of ``mtpg show`` and GraphViz DOT.

Teams and banks carry the numbers of :mod:`mtpg.analysis.description.numbering`.
"""

from __future__ import annotations

from mtpg.analysis.description.numbering import GraphIndex, bank_users, index_graph
from mtpg.engine.compile import effective_mask
from mtpg.model.graph import Population
from mtpg.model.instructions import disassemble


def _action_text(pop: Population, index: GraphIndex, pid: int) -> str:
    prog = pop.programs[pid]
    if prog.is_atomic:
        return f"action {prog.atomic_action}"
    return f"-> team {index.team_number(prog.action)}"


def describe_graph(pop: Population, root: int, meta: dict | None = None) -> str:
    """The text listing of ``mtpg show``.

    Lists every team with its programs in execution order; each program with its action
    pointer, its memory bank and its instructions disassembled, introns (instructions
    that affect neither the bid ``r[0]`` nor memory; the compiler drops them) marked
    ``intron``; then the memory banks shared by more than one program.

    Args:
        pop: The population holding the graph.
        root: Root team id.
        meta: The graph file's metadata (printed when given).

    Returns:
        The listing, lines joined by newlines.
    """
    index = index_graph(pop, root)
    layout = pop.layout
    n_instr = sum(len(pop.programs[p].instructions) for p in index.programs)
    n_eff = sum(
        int(effective_mask(pop.programs[p].instructions, layout).sum()) for p in index.programs
    )
    lines = [
        f"graph: {len(index.teams)} team(s), {len(index.programs)} programs, "
        f"{len(index.banks)} memory banks of {layout.n_memory} registers, "
        f"{n_instr} instructions ({n_eff} effective, {n_instr - n_eff} introns)",
        "numbers: team N is the N-th team in depth-first order from the root (team 1); "
        "bank N likewise by first use",
        f"interface: {layout.n_obs} observed input{'s' * (layout.n_obs != 1)} "
        f"s[0..{layout.n_obs - 1}], {layout.n_actions} atomic "
        f"action{'s' * (layout.n_actions != 1)} 0..{layout.n_actions - 1}",
    ]
    tasks = (meta or {}).get("tasks")
    if isinstance(tasks, list) and tasks:
        lines.append("meta tasks: " + ", ".join(map(str, tasks)))
    for key, value in sorted((meta or {}).items()):
        if isinstance(value, str | int | float | bool):
            lines.append(f"meta {key}: {value}")
    depth = index.depths(pop)
    for tid in index.teams:
        team = pop.teams[tid]
        lines.append("")
        lines.append(
            f"team {index.team_number(tid)} (id {tid}, depth {depth[tid]}, born generation "
            f"{team.birth}): {len(team.programs)} programs"
        )
        for k, pid in enumerate(team.programs):
            prog = pop.programs[pid]
            mask = effective_mask(prog.instructions, layout)
            lines.append(
                f"  program {k + 1} (id {pid}) {_action_text(pop, index, pid)}, "
                f"bank {index.bank_number(prog.bank)}, {len(mask)} instructions "
                f"({int(mask.sum())} effective)"
            )
            for j, (text, live) in enumerate(
                zip(disassemble(prog.instructions, layout), mask, strict=True)
            ):
                lines.append(f"    {j:3d}  {text:<34}{'' if live else '  intron'}".rstrip())
    users = bank_users(pop, index)
    shared = {b: u for b, u in users.items() if len(u) > 1}
    lines.append("")
    lines.append(f"memory banks shared by more than one program: {len(shared)} of {len(users)}")
    for bank, progs in shared.items():
        where = ", ".join(f"team {t} program {k}" for t, k in progs)
        lines.append(f"  bank {bank}: {where}")
    return "\n".join(lines)


def graph_dot(
    pop: Population, root: int, highlight: list[int] | None = None, title: str | None = None
) -> str:
    """GraphViz DOT of the team graph: one node per team, one edge per team pointer.

    Each node lists its atomic actions; edges are labelled with the pointing program's
    position in its team. ``highlight`` (model team ids, a decision path) is drawn green.
    """
    index = index_graph(pop, root)
    on_path = set(highlight or [])
    path_edges = set(zip(highlight or [], (highlight or [])[1:], strict=False))
    lines = ["digraph tpg {", "  rankdir=TB;", '  node [shape=ellipse, fontname="Helvetica"];']
    if title:
        lines.append(f'  label="{title}"; labelloc=t;')
    for tid in index.teams:
        num = index.team_number(tid)
        progs = [pop.programs[p] for p in pop.teams[tid].programs]
        acts = sorted({p.atomic_action for p in progs if p.is_atomic})
        label = f"{num}\\nactions {','.join(map(str, acts))}"
        style = ', style=filled, fillcolor="#a1d99b"' if tid in on_path else ""
        shape = ", shape=doublecircle" if tid == root else ""
        lines.append(f'  t{num} [label="{label}"{shape}{style}];')
    for src, dst, pid in index.edges(pop):
        pos = pop.teams[src].programs.index(pid) + 1
        colour = ', color="#2ca02c", penwidth=2.5' if (src, dst) in path_edges else ""
        lines.append(
            f'  t{index.team_number(src)} -> t{index.team_number(dst)} [label="p{pos}"{colour}];'
        )
    lines.append("}")
    return "\n".join(lines) + "\n"
