"""Team-graph pictures without system binaries: networkx lays out, matplotlib draws.

The layout is layered by depth (shortest distance from the root, which is on top), using
networkx's ``multipartite_layout``; networkx is a well-kept graph library, so the project
does not maintain its own graph algorithms. DOT
(:func:`mtpg.analysis.description.listing.graph_dot`) is written beside a picture, and
rendered to SVG only when GraphViz's ``dot`` is on PATH.
"""

from __future__ import annotations

import shutil
import subprocess
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from mtpg.analysis.description.numbering import index_graph
from mtpg.analysis.palette import IDLE_COLOUR, PATH_COLOUR
from mtpg.model.graph import Population


@dataclass(frozen=True)
class GraphLayout:
    """Positions of a graph's teams.

    Attributes:
        pos: float ``(T, 2)``: centre of team number ``k + 1`` at ``pos[k]``.
        edges: ``(from, to)`` team numbers, one per distinct pointer.
        depth: int ``(T,)`` depth of each team.
        radius: Node radius in layout units.
    """

    pos: np.ndarray
    edges: tuple[tuple[int, int], ...]
    depth: np.ndarray
    radius: float


def layout_graph(pop: Population, root: int) -> GraphLayout:
    """Lays the team graph out in layers by depth from the root (root on top)."""
    import networkx as nx

    index = index_graph(pop, root)
    depth_of = index.depths(pop)
    graph = nx.DiGraph()
    for tid in index.teams:
        graph.add_node(index.team_number(tid), layer=depth_of[tid])
    edges = []
    for src, dst, _ in index.edges(pop):
        e = (index.team_number(src), index.team_number(dst))
        if e not in edges:
            edges.append(e)
    graph.add_edges_from(edges)
    n = len(index.teams)
    depth = np.array([depth_of[t] for t in index.teams], dtype=np.int64)
    if n == 1:
        pos = np.zeros((1, 2))
    else:
        raw = nx.multipartite_layout(graph, subset_key="layer", align="horizontal")
        pos = np.array([raw[k] for k in range(1, n + 1)], dtype=np.float64)
        widest = int(np.bincount(depth).max())
        span = np.ptp(pos[:, 0]) or 1.0
        pos[:, 0] = (pos[:, 0] - pos[:, 0].mean()) / span * max(widest - 1, 1)
        pos[:, 1] = -depth.astype(np.float64)
    return GraphLayout(pos, tuple(edges), depth, 0.3)


class GraphDrawing:
    """A team graph drawn on one matplotlib axes, whose highlight can change per frame.

    Args:
        ax: The axes (its aspect is set equal and its frame hidden).
        layout: The layout.
        pies: Optional ``(T, K)`` fractions: each node drawn as a pie of K slices.
        pie_colours: The K slice colours.
        font_size: Size of the team numbers.
    """

    def __init__(
        self,
        ax,
        layout: GraphLayout,
        pies: np.ndarray | None = None,
        pie_colours: list[str] | None = None,
        font_size: float = 9,
    ):
        self.ax = ax
        self.layout = layout
        self.arrows = self._draw_arrows()
        self.nodes = self._draw_nodes(pies, pie_colours, font_size)
        r = layout.radius
        pad = r * 2.2
        ax.set_xlim(layout.pos[:, 0].min() - pad, layout.pos[:, 0].max() + pad)
        ax.set_ylim(layout.pos[:, 1].min() - pad, layout.pos[:, 1].max() + pad)
        ax.set_aspect("equal")
        ax.set_xticks([])
        ax.set_yticks([])
        for spine in ax.spines.values():
            spine.set_visible(False)

    def _draw_arrows(self) -> dict:
        """One arrow per edge (curved when it points up or sideways), by ``(from, to)``."""
        from matplotlib.patches import FancyArrowPatch

        ax, layout, r = self.ax, self.layout, self.layout.radius
        arrows: dict[tuple[int, int], FancyArrowPatch] = {}
        for a, b in layout.edges:
            p, q = layout.pos[a - 1], layout.pos[b - 1]
            upward = layout.depth[b - 1] <= layout.depth[a - 1]
            rad = 0.35 if upward else 0.0
            start, end = _ends(p, q, r, rad)
            arrow = FancyArrowPatch(
                start,
                end,
                arrowstyle="-|>",
                mutation_scale=12,
                shrinkA=0,
                shrinkB=0,
                connectionstyle=f"arc3,rad={rad}",
                color="0.45",
                lw=1.0,
                zorder=1,
            )
            ax.add_patch(arrow)
            arrows[(a, b)] = arrow
        return arrows

    def _draw_nodes(self, pies, pie_colours, font_size: float) -> list:
        """One circle per team (a pie when ``pies`` is given) with its number."""
        from matplotlib.patches import Circle

        ax, layout, r = self.ax, self.layout, self.layout.radius
        nodes = []
        for k, (x, y) in enumerate(layout.pos):
            fill = "white" if pies is not None else IDLE_COLOUR
            idle = pies is not None and pies[k].sum() == 0
            circle = Circle(
                (x, y),
                r,
                facecolor=fill,
                edgecolor="0.3",
                lw=1.0,
                ls="--" if idle else "-",
                zorder=2,
            )
            ax.add_patch(circle)
            nodes.append(circle)
            if pies is not None and pies[k].sum() > 0:
                _pie(ax, (x, y), r, pies[k], pie_colours or [])
            ax.text(
                x,
                y - r * 1.15 if pies is not None else y,
                str(k + 1),
                ha="center",
                va="top" if pies is not None else "center",
                fontsize=font_size,
                fontweight="bold",
                zorder=4,
            )
        return nodes

    def highlight(self, path: list[int]) -> list:
        """Colours a decision path (team numbers in visiting order); returns changed artists."""
        on = set(path)
        steps = set(zip(path, path[1:], strict=False))
        for k, node in enumerate(self.nodes):
            node.set_facecolor(PATH_COLOUR if k + 1 in on else IDLE_COLOUR)
            node.set_linewidth(2.5 if path and k + 1 == path[-1] else 1.0)
        for edge, arrow in self.arrows.items():
            live = edge in steps
            arrow.set_color(PATH_COLOUR if live else "0.75")
            arrow.set_linewidth(2.2 if live else 0.8)
        return self.nodes + list(self.arrows.values())


def _pie(ax, centre: tuple[float, float], r: float, fractions, colours: list[str]) -> None:
    """Slices of a node, counter-clockwise from the top, one per non-zero fraction."""
    from matplotlib.patches import Wedge

    start = 90.0
    for frac, colour in zip(fractions, colours, strict=False):
        if frac <= 0:
            continue
        ax.add_patch(
            Wedge(
                centre,
                r,
                start,
                start + 360 * frac,
                facecolor=colour,
                edgecolor="white",
                lw=0.5,
                zorder=3,
            )
        )
        start += 360 * frac


def _ends(p: np.ndarray, q: np.ndarray, r: float, rad: float) -> tuple[tuple, tuple]:
    """Where an edge from node ``p`` to node ``q`` (radius ``r``) leaves and enters them.

    ``rad`` is the arc's curvature (matplotlib's ``arc3``): the arc leaves ``p`` turned by
    about ``atan(2 * rad)`` from the straight line, and enters ``q`` turned the other way.
    """
    d = q - p
    angle = np.arctan2(d[1], d[0])
    turn = np.arctan(2 * rad)
    start = p + r * np.array([np.cos(angle - turn), np.sin(angle - turn)])
    end = q - r * np.array([np.cos(angle + turn), np.sin(angle + turn)])
    return tuple(start), tuple(end)


def render_svg(dot_path: str | Path) -> Path | None:
    """Renders a DOT file to SVG beside it when GraphViz's ``dot`` is on PATH, else None."""
    exe = shutil.which("dot")
    if exe is None:
        return None
    dot_path = Path(dot_path)
    svg = dot_path.with_suffix(".svg")
    subprocess.run([exe, "-Tsvg", str(dot_path), "-o", str(svg)], check=True, timeout=60)
    return svg
