import numpy as np

from inside_graphs import cycle, writer_every_k
from mtpg.analysis.description.layout import GraphDrawing, layout_graph, render_svg
from mtpg.analysis.description.listing import graph_dot
from mtpg.analysis.description.numbering import index_graph
from mtpg.analysis.runs.hierarchical_complexity import hierarchy_statistics, mean_by_size


def test_layout_is_layered_by_depth_with_the_root_on_top():
    pop, root = writer_every_k()
    lay = layout_graph(pop, root)
    assert lay.depth.tolist() == [0, 1]
    assert lay.pos[0, 1] > lay.pos[1, 1]
    assert lay.edges == ((1, 2),)


def test_cycles_are_drawn_and_highlighted(tmp_path, monkeypatch):
    from mtpg.analysis.plotting import pyplot

    pop, root = cycle()
    index = index_graph(pop, root)
    assert index.teams[0] == root
    lay = layout_graph(pop, root)
    assert set(lay.edges) == {(1, 2), (2, 1)}
    fig, ax = pyplot().subplots()
    drawing = GraphDrawing(ax, lay)
    drawing.highlight([1, 2])
    assert drawing.arrows[(1, 2)].get_linewidth() > drawing.arrows[(2, 1)].get_linewidth()
    pyplot().close(fig)
    dot = tmp_path / "g.dot"
    dot.write_text(graph_dot(pop, root, highlight=[root]))
    assert "t1 -> t2" in dot.read_text() and "t2 -> t1" in dot.read_text()
    monkeypatch.setenv("PATH", str(tmp_path))  # no GraphViz: no SVG, no error
    assert render_svg(dot) is None


def test_hierarchy_statistics_from_run_files(tmp_path):
    (tmp_path / "tests.csv").write_text(
        "generation,subset,root,graph_teams,teams_per_decision,test_A\n"
        "5,A,1,1,1.0,0\n5,A+B,2,3,2.0,0\n10,A,1,2,1.5,0\n10,A+B,2,4,3.0,0\n10,B,3,1,1.0,0\n"
    )
    (tmp_path / "metrics.csv").write_text(
        "generation,teams_per_decision,champion_teams\n1,1.0,1\n2,1.2,2\n"
    )
    stats = hierarchy_statistics(tmp_path)
    assert stats["subset_size"].tolist() == [1, 2, 1, 2, 1]
    assert int(stats["final_generation"]) == 10
    assert stats["population_teams_per_decision"].tolist() == [1.0, 1.2]
    means = mean_by_size(stats)
    assert means["sizes"].tolist() == [1, 2]
    assert np.allclose(means["mean"], [[1.0, 1.25], [2.0, 3.0]])
