"""Which optional extra of mtpg installs a module, for a one-line "missing dependency".

The extras are read from the installed distribution's metadata (``Requires-Dist`` lines
with ``extra == "NAME"``, written from ``pyproject.toml`` at install time), so the hint
always names an extra of the mtpg that is installed. The ``test`` extra, which gathers
the others for the test suite, is named only for what no other extra installs.
"""

from __future__ import annotations

import json
import re
from importlib import metadata

#: Modules whose distribution has another name (module -> distribution).
MODULE_DISTRIBUTIONS = {
    "pygame": "pygame-ce",
    "tomli_w": "tomli-w",
    "stable_baselines3": "sb3-contrib",  # the rl extra installs it with sb3-contrib
    "torch": "sb3-contrib",
}
#: Extras named only when no other extra installs the module.
_GATHERING = ("test",)
_EXTRA = re.compile(r"""extra\s*==\s*["']([^"']+)["']""")


def _normal(name: str) -> str:
    """A distribution name normalised as PEP 503 does (case, ``-``, ``_`` and ``.``)."""
    return re.sub(r"[-_.]+", "-", name).lower()


def requirements() -> list[tuple[str, str | None]]:
    """The requirements of mtpg: ``(normalised distribution, extra or None for the base)``."""
    try:
        lines = metadata.requires("mtpg") or []
    except metadata.PackageNotFoundError:
        return []
    out = []
    for line in lines:
        name = re.match(r"[A-Za-z0-9][A-Za-z0-9._-]*", line)
        if name is None:
            continue
        extra = _EXTRA.search(line.partition(";")[2])
        out.append((_normal(name.group(0)), extra.group(1) if extra else None))
    return out


def extras_of(module: str) -> tuple[list[str], bool]:
    """The extras that install ``module`` (most specific first) and whether the base does.

    Args:
        module: A module name, dotted or not (``distributed.comm`` is ``distributed``).

    Returns:
        ``(extras, base)``: extras in order of their number of requirements, the
        gathering ``test`` extra last; ``base`` is True for a dependency of every install.
    """
    top = module.partition(".")[0]
    dist = _normal(MODULE_DISTRIBUTIONS.get(top, top))
    reqs = requirements()
    size: dict[str, int] = {}
    for _, extra in reqs:
        if extra is not None:
            size[extra] = size.get(extra, 0) + 1
    base = any(name == dist and extra is None for name, extra in reqs)
    found = {extra for name, extra in reqs if name == dist and extra is not None}
    ordered = sorted(found, key=lambda e: (e in _GATHERING, size[e], e))
    return ordered, base


def _editable_source() -> str | None:
    """The project folder of an editable install of mtpg (``pip install -e``), else None."""
    try:
        text = metadata.distribution("mtpg").read_text("direct_url.json")
        doc = json.loads(text or "{}")
    except (metadata.PackageNotFoundError, ValueError, OSError):
        return None
    url = doc.get("url", "") if isinstance(doc, dict) else ""
    editable = isinstance(doc, dict) and (doc.get("dir_info") or {}).get("editable")
    if editable and url.startswith("file://"):
        return url.removeprefix("file://")
    return None


def install_command(extra: str | None = None) -> str:
    """The ``pip install`` command that installs mtpg with ``extra`` (the base when None).

    For an editable install (a checkout) it names the checkout, as installing it did.
    """
    suffix = f"[{extra}]" if extra else ""
    source = _editable_source()
    if source is not None:
        return f"pip install -e '{source}{suffix}'"
    return f"pip install 'mtpg{suffix}'"


def missing_dependency(module: str) -> str:
    """One line saying that ``module`` is missing and, where mtpg knows, what installs it.

    Example: ``module 'tensorboardX' is not installed; it comes with the extra
    'tensorboard': pip install 'mtpg[tensorboard]'``.
    """
    extras, base = extras_of(module)
    text = f"module {module.partition('.')[0]!r} is not installed"
    if extras and not base:
        return f"{text}; it comes with the extra {extras[0]!r}: {install_command(extras[0])}"
    if base:
        return f"{text}, though mtpg needs it; reinstall mtpg: {install_command()}"
    return text
