"""Suite-wide settings: the Hypothesis profile.

By default (and in CI) the ``ci`` profile runs: ``derandomize=True`` makes every
property test draw the same examples on every run and every machine (the seed is derived
from the test itself), so a failure seen in CI reproduces locally with the same command;
``print_blob=True`` prints the reproduction blob of a failing example. The ``explore``
profile draws fresh random examples (with the seed printed by Hypothesis on failure) for
hunting new bugs: ``HYPOTHESIS_PROFILE=explore pytest``.
"""

from __future__ import annotations

import os

from hypothesis import settings

settings.register_profile("ci", derandomize=True, print_blob=True, database=None)
settings.register_profile("explore", derandomize=False, print_blob=True)
PROFILE = os.environ.get("HYPOTHESIS_PROFILE", "ci")
settings.load_profile(PROFILE)


def pytest_sessionstart(session) -> None:
    """Clears Numba's kernel cache if the sources changed, before any test runs a kernel.

    ``import mtpg`` no longer does it (importing changes no file); the tests run kernels
    in this process, so the suite does it as the command line does.
    """
    from mtpg._kernel_cache import refresh

    refresh()


def pytest_report_header(config) -> str:
    current = settings.get_current_profile_name()
    mode = "fixed examples (derandomize)" if settings().derandomize else "random examples"
    return f"hypothesis profile: {current}, {mode}; set HYPOTHESIS_PROFILE to change"
