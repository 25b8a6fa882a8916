"""Shared HTML of the two pages (``mtpg report`` and ``mtpg analyze``): head, style, images.

Pages are self-contained: every figure is embedded as a base64 PNG.
"""

from __future__ import annotations

import base64
import html
from pathlib import Path

#: The style every page shares; a page may add rules of its own.
STYLE = (
    "body{font-family:sans-serif;max-width:1100px;margin:2em auto}img{max-width:100%}\n"
    "table{border-collapse:collapse}td,th{border:1px solid #ccc;padding:3px 8px;"
    "text-align:right}\n"
)


def escape(text: object) -> str:
    """``text`` as HTML text."""
    return html.escape(str(text))


def figure(path: Path, title: str) -> str:
    """A section of a heading and the PNG at ``path``, embedded."""
    data = base64.b64encode(Path(path).read_bytes()).decode("ascii")
    return f'<h2>{escape(title)}</h2><img alt="{escape(title)}" src="data:image/png;base64,{data}">'


def page(title: str, body: str, extra_style: str = "") -> str:
    """A whole HTML document of ``body`` under ``title``."""
    return (
        '<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8">'
        f"<title>{escape(title)}</title>\n<style>{STYLE}{extra_style}</style></head><body>\n"
        f"{body}\n</body></html>\n"
    )
