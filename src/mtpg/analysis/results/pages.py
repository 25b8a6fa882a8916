"""The committed pages written from the committed runs, and how each is regenerated.

``mtpg report --results results`` rewrites every page of :data:`PAGES` (``--page NAME``
some of them) from the runs of ``results/`` alone; with ``--out DIR`` it writes them into
``DIR`` (the results folder) and ``DIR/../docs`` instead, which is how
``tests/analysis/test_results_pages.py`` checks that each committed page regenerates byte
for byte. A page whose text is partly written by hand (the study pages) is read from the
committed one, and only its section between markers is rewritten.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

__all__ = ["PAGES", "Page", "regenerate"]


@dataclass(frozen=True)
class Page:
    """One committed page.

    Attributes:
        name: Its name (``--page NAME``).
        path: The page, relative to the repository (the results folder's parent).
        write: ``write(results, out)`` rewrites it from the results folder's runs
            (``out``: the results folder written to) and returns its path.
        what: What it shows, in words.
    """

    name: str
    path: str
    write: Callable[[Path, Path], Path]
    what: str


def _results(results: Path, out: Path) -> Path:
    from mtpg.analysis.results.readme import build

    with np.errstate(all="ignore"):  # as the page has always been written: no float noise
        return build(results, out=out)


def _candidates(results: Path, out: Path) -> Path:
    from mtpg.analysis.results.candidates import write

    return write(results, out)


def _variants(results: Path, out: Path) -> Path:
    from mtpg.analysis.results.variants import write

    return write(results, out)


def _memorisation(results: Path, out: Path) -> Path:
    from mtpg.analysis.results.memorisation_page import write

    return write(results, out)


def _audit(results: Path, out: Path) -> Path:
    from mtpg.analysis.results.audit_page import write

    return write(results, out)


#: Every page, by name, in the order ``mtpg report --results`` writes them.
PAGES = {
    p.name: p
    for p in (
        Page("results", "results/README.md", _results, "the paper's experiment and TPG-robust"),
        Page(
            "candidates",
            "results/candidates/README.md",
            _candidates,
            "the demo-scale candidates of the memorisation study",
        ),
        Page("variants", "docs/variants-study.md", _variants, "the interface study"),
        Page("memorisation", "docs/memorisation.md", _memorisation, "the memorisation probes"),
        Page("robust-audit", "docs/robust-audit.md", _audit, "why TPG-robust lags in two tasks"),
    )
}


def regenerate(
    results: Path, out: Path | None = None, names: Sequence[str] | None = None
) -> list[Path]:
    """Rewrites pages from the runs of a results folder.

    Args:
        results: The results folder (``results/``; the study pages are in ``docs/``
            beside it).
        out: The results folder written to (default: ``results``).
        names: The pages (default: all of :data:`PAGES`).

    Returns:
        The pages written.

    Raises:
        ValueError: An unknown page name, or a page that cannot be written from the runs.
    """
    names = list(names or PAGES)
    unknown = [n for n in names if n not in PAGES]
    if unknown:
        raise ValueError(f"no page {unknown[0]!r} (pages: {', '.join(PAGES)})")
    results = Path(results).resolve()
    out = results if out is None else Path(out).resolve()
    out.mkdir(parents=True, exist_ok=True)
    return [PAGES[n].write(results, out) for n in names]
