"""``mtpg.analysis.results.candidates``: the candidates' table from per-run normalised scores."""

from mtpg.analysis.results import candidates


def _tool():
    return candidates


def test_table_lists_every_run_and_compares_the_groups():
    tool = _tool()
    plain = {f"demo-seed{s}": {"CartPole": 0.1 * s, "Acrobot": 0.5} for s in (1, 2, 3)}
    resampled = {f"demo-resample10-seed{s}": {"CartPole": 0.9, "Acrobot": 0.6} for s in (1, 2, 3)}
    text = tool.table({"demo": plain, "demo-resample10": resampled})
    for run in [*plain, *resampled]:
        assert f"| {run} |" in text
    assert "| demo-seed3 | 0.30 | 0.50 | 0.30 |" in text
    # every resampled run beats every plain one in both tasks
    assert "P(demo-resample10 > demo) = 1.00 [1.00, 1.00]" in text


def test_a_run_is_finished_at_its_configured_generation(tmp_path):
    tool = _tool()
    (tmp_path / "config.toml").write_text("generations = 3\n")
    (tmp_path / "metrics.csv").write_text("generation,x\n1,0\n2,0\n")
    assert not tool.finished(tmp_path)
    with (tmp_path / "metrics.csv").open("a") as f:
        f.write("3,0\n")
    assert tool.finished(tmp_path)
