"""Shared matplotlib helpers of every figure: file-only figures, captions and saving."""

from __future__ import annotations

import textwrap
from pathlib import Path

#: Resolution of every PNG figure.
DPI = 110


class _AggFigures:
    """The part of pyplot the figures use, on figures pyplot never sees.

    Each figure gets its own Agg canvas (files only, no window), so drawing a report
    neither needs a display nor switches the backend of the caller's session (a notebook's
    inline figures, say), as ``matplotlib.use("Agg")`` did.
    """

    def __init__(self) -> None:
        import matplotlib

        self.rcParams = matplotlib.rcParams
        self._colormaps = matplotlib.colormaps

    def subplots(self, nrows: int = 1, ncols: int = 1, *, figsize=None, **kwargs):
        """A new figure and its axes, as ``pyplot.subplots`` returns them."""
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure

        fig = Figure(figsize=figsize)
        FigureCanvasAgg(fig)
        return fig, fig.subplots(nrows, ncols, **kwargs)

    def get_cmap(self, name: str):
        """The named colormap."""
        return self._colormaps[name]

    def close(self, fig) -> None:
        """Nothing to release: pyplot holds no reference to these figures."""


def pyplot() -> _AggFigures:
    """What the figures need of pyplot, on their own Agg canvases (:class:`_AggFigures`)."""
    return _AggFigures()


def save(fig, path: Path) -> Path:
    """Saves a figure as PNG and closes it."""
    fig.savefig(path, dpi=DPI)
    pyplot().close(fig)
    return Path(path)


def title_and_legend_above(ax, title: str) -> None:
    """Titles the axes and puts their legend between title and axes, in two columns.

    For bar charts whose bars reach the top: a legend inside the axes hides bars and
    their values.
    """
    ax.set_title(title, pad=34)
    ax.legend(fontsize=7, loc="lower center", bbox_to_anchor=(0.5, 1.0), ncol=2, frameon=False)


def finish(fig, path: Path, caption: str, legend_rows: int = 0) -> Path:
    """Adds the caption (what is shown, how chosen) under the axes and saves the figure."""
    text = "\n".join(
        textwrap.wrap(caption, width=int(fig.get_figwidth() * 15), break_on_hyphens=False)
    )
    lines = text.count("\n") + 1
    caption_top = (0.16 * lines + 0.1) / fig.get_figheight()
    for legend in fig.legends:  # a figure legend sits between the plots and the caption
        legend.set_bbox_to_anchor((0.5, caption_top), transform=fig.transFigure)
    bottom = caption_top + 0.3 * legend_rows / fig.get_figheight()
    fig.text(0.01, 0.01, text, fontsize=7, va="bottom", ha="left", color="0.25")
    fig.tight_layout(rect=(0, bottom, 1, 1))
    return save(fig, path)
