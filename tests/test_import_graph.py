"""The module import graph of shellform (scripts/import_graph.py, read from the sources with ast):
no circle, no arrow into a higher layer of docs/design.md, and every module listed there."""

import importlib.util
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
spec = importlib.util.spec_from_file_location("import_graph", ROOT / "scripts" / "import_graph.py")
graph = importlib.util.module_from_spec(spec)
spec.loader.exec_module(graph)

def test_no_circles():
    assert graph.circles(graph.graph(ROOT)) == []


def test_layers_import_only_downward():
    mods = graph.modules(ROOT)
    level = graph.layer_of(mods, graph.layers(ROOT / "docs" / "design.md"))
    assert sorted(set(mods) - set(level)) == [], "every module lies in a layer of docs/design.md"
    assert graph.upward(graph.graph(ROOT), level) == []


def test_design_lists_every_module():
    text = (ROOT / "docs" / "design.md").read_text()
    missing = [p.relative_to(ROOT).as_posix() for p in graph.modules(ROOT).values()
               if f"| `{p.relative_to(ROOT).as_posix()}` |" not in text]
    assert missing == []


def test_the_graph_sees_upward_arrows_and_circles(tmp_path):
    """The checks themselves: a package whose low module imports a high one, in a circle."""
    pkg = tmp_path / "shellform"
    (pkg / "low").mkdir(parents=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "low" / "__init__.py").write_text("")
    (pkg / "low" / "a.py").write_text("def f():\n    from shellform.high import b\n")
    (pkg / "high.py").write_text("from shellform.low import a\nimport shellform.low.a\n")
    (tmp_path / "forms").mkdir()
    (tmp_path / "docs").mkdir()
    (tmp_path / "docs" / "design.md").write_text("```\nlayers (top to bottom)\nhigh\nlow\n```\n")
    arrows = graph.graph(tmp_path)
    assert arrows["shellform.low.a"] == [("shellform.high", True)]
    assert graph.circles(arrows) == [["shellform.high", "shellform.low.a"]]
    level = graph.layer_of(graph.modules(tmp_path), graph.layers(tmp_path / "docs" / "design.md"))
    assert graph.upward(arrows, level) == [("shellform.low.a", "shellform.high")]
