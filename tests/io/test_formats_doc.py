"""docs/formats.md states the instruction set and the format versions the code has."""

import re
from pathlib import Path

from mtpg.analysis.graph.replay import SCHEMA_VERSION
from mtpg.io.checkpoint import CHECKPOINT_FORMAT, CHECKPOINT_VERSION
from mtpg.io.runschema import READABLE_VERSIONS, RUN_FORMAT, RUN_SCHEMA_VERSION, UNVERSIONED
from mtpg.io.serialize import GRAPH_FORMAT, GRAPH_VERSION, POPULATION_FORMAT, POPULATION_VERSION
from mtpg.model.instructions import CONSTANTS, OP_NAMES, RegisterLayout, disassemble

DOC = (Path(__file__).resolve().parents[2] / "docs" / "formats.md").read_text()


def test_the_operation_table_is_the_op_code_order_and_the_disassembly():
    rows = re.findall(r"^\| (\d+) \| `(\w+)` \| `([^`]+)` \|", DOC, re.M)
    assert [int(code) for code, _, _ in rows] == list(range(len(OP_NAMES)))
    assert tuple(name for _, name, _ in rows) == OP_NAMES
    layout = RegisterLayout(8, 8, 2)
    for code, _, written in rows:  # d = r[0], a = r[1], b = r[2]
        [text] = disassemble([[int(code), 0, 1, 2]], layout)
        for letter, register in (("d", "r[0]"), ("a", "r[1]"), ("b", "r[2]")):
            written = re.sub(rf"\b{letter}\b", register, written)
        assert text == written


def test_register_ranges_and_versions():
    assert f"-{abs(CONSTANTS[0])}, -0.8" in DOC and len(CONSTANTS) == 18
    assert "| R+M .. R+M+17 (16-33) |" in DOC
    assert f"`{GRAPH_FORMAT}`, {GRAPH_VERSION}" in DOC
    assert f"`{CHECKPOINT_FORMAT}`, {CHECKPOINT_VERSION}" in DOC
    assert f"`{POPULATION_FORMAT}`, {POPULATION_VERSION}" in DOC
    assert f"`schema_version` {SCHEMA_VERSION}" in DOC
    assert (
        f"`{RUN_FORMAT}`, {RUN_SCHEMA_VERSION} (a run without `format.json` is {UNVERSIONED})"
        in DOC
    )
    assert f'{{"format": "{RUN_FORMAT}", "version": {RUN_SCHEMA_VERSION}}}' in DOC
    assert READABLE_VERSIONS == (1,)  # the page says only version 1 is read; update it too
