from inside_graphs import writer_every_k
from mtpg.cli.main import main
from mtpg.io.serialize import save_graph


def test_show_lists_teams_programs_introns_banks_and_writes_dot(tmp_path, capsys):
    pop, root = writer_every_k()
    pop.programs[pop.teams[root].programs[1]].instructions = pop.programs[
        pop.teams[root].programs[1]
    ].instructions.repeat(2, axis=0)  # the first copy of r[0] <- r[1] * m[1] is an intron
    path = tmp_path / "g.json"
    save_graph(path, pop, root, {"tasks": ["CartPole"]})
    dot = tmp_path / "g.dot"
    assert main(["show", str(path), "--dot", str(dot)]) == 0
    out = capsys.readouterr().out
    assert "team 1 (id 1, depth 0" in out and "team 2 (id 0, depth 1" in out
    assert "-> team 2" in out and "action 1" in out
    assert "m[1] <- abs(s[0])" in out
    lines = [ln for ln in out.splitlines() if "r[0] <- r[1] * m[1]" in ln]
    assert len(lines) == 2 and lines[0].endswith("intron") and not lines[1].endswith("intron")
    assert "bank 1: team 1 program 1, team 1 program 2, team 2 program 1" in out
    text = dot.read_text()
    assert text.startswith("digraph") and "t1 -> t2" in text


def test_show_run_directory_uses_the_all_task_champion(tmp_path, capsys):
    assert main(["show", str(tmp_path)]) == 2  # not a run directory: one clear line
    assert "show: error:" in capsys.readouterr().err
