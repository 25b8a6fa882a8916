"""Drawing a figure leaves the caller's matplotlib backend as it was."""

import matplotlib

from mtpg.analysis.plotting import pyplot, save


def test_figures_do_not_switch_the_callers_backend(tmp_path):
    before = matplotlib.get_backend()
    matplotlib.use("svg")
    try:
        fig, ax = pyplot().subplots(figsize=(2, 2))
        ax.plot([0, 1], [1, 0])
        path = save(fig, tmp_path / "f.png")
        assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
        assert matplotlib.get_backend() == "svg"
    finally:
        matplotlib.use(before)
