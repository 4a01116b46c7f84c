"""Tests of agentchord.graph.render."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from agentchord.graph import RenderError, TaskGraph, load_graph, render, to_dot, to_mermaid

POUR = Path(__file__).parent / "data" / "graphs" / "pour_water.yaml"
BLUE, PINK = "#1f77b4", "#e377c2"


@pytest.fixture(scope="module")
def pour() -> TaskGraph:
    return load_graph(POUR)


def _dot_line(dot: str, start: str) -> str:
    return next(line for line in dot.splitlines() if line.strip().startswith(start))


def test_dot_colours_edges_and_nodes(pour: TaskGraph) -> None:
    dot = to_dot(pour)
    assert dot.startswith('digraph "single_arm_pour_water" {')
    nominal = _dot_line(dot, '"v1" -> "v2"')
    assert f'color="{BLUE}"' in nominal and "move_to_obj(R)" in nominal
    assert "! bottle_dropped -> e2_r_bottle_dropped" in nominal
    entry = _dot_line(dot, '"v1" -> "r_bottle_regrasped"')
    assert f'color="{PINK}"' in entry and 'style="dashed"' in entry
    assert "when bottle_dropped on e2" in entry
    exit_edge = _dot_line(dot, '"r_bottle_regrasped" -> "v2"')
    assert f'color="{PINK}"' in exit_edge and "dashed" not in exit_edge
    assert f'color="{PINK}"' in _dot_line(dot, '"r_bottle_regrasped" [')
    assert "(start)" in _dot_line(dot, '"v0" [') and "bold" in _dot_line(dot, '"v0" [')
    assert "peripheries=2" in _dot_line(dot, '"v5" [')


def test_dot_labels_multi_step_and_synchronous_edges(pour: TaskGraph) -> None:
    dot = to_dot(pour)
    assert "grasp(R); move_to_obj(R)" in _dot_line(dot, '"v2" -> "v2"')
    sync = pour.model_copy(deep=True)
    sync.edges[0].steps[0]["left"] = sync.edges[0].steps[0]["right"]
    assert "grasp(L) + grasp(R)" in _dot_line(to_dot(sync), '"v0" -> "v1"')


def test_dot_escapes_quotes() -> None:
    graph = TaskGraph.model_validate(
        {"task": 'say "hi"', "start": "a", "goal": "a", "nodes": [{"id": "a", "semantic": 'the "a" node'}], "edges": []}
    )
    dot = to_dot(graph)
    assert 'digraph "say \\"hi\\""' in dot and 'the \\"a\\" node' in dot


def test_mermaid_uses_link_styles(pour: TaskGraph) -> None:
    mmd = to_mermaid(pour)
    assert mmd.startswith("flowchart LR\n")
    assert f"linkStyle 0 stroke:{BLUE}" in mmd
    assert f"linkStyle 6 stroke:{PINK}" in mmd  # e2_r_bottle_dropped
    assert "n1_v1 -.->|" in mmd and "-#gt; e2_r_bottle_dropped" in mmd  # ">" inside labels is escaped
    assert f"classDef recovery stroke:{PINK}" in mmd
    assert "class n6_r_bottle_regrasped recovery" in mmd
    assert "class n0_v0 start" in mmd and "class n5_v5 goal" in mmd


def test_mermaid_ids_are_safe_words() -> None:
    graph = TaskGraph.model_validate(
        {
            "task": "t",
            "start": "end",
            "goal": "a-b",
            "nodes": [{"id": "end", "semantic": "s"}, {"id": "a-b", "semantic": '<x> & "y"'}],
            "edges": [{"id": "e", "source": "end", "target": "a-b", "actions": {"right": {"fn": "back"}}}],
        }
    )
    mmd = to_mermaid(graph)
    assert "n0_end -->" in mmd and "n1_a_b(" in mmd
    assert "#lt;x#gt; #amp; #quot;y#quot;" in mmd


@pytest.mark.parametrize(("suffix", "head"), [(".dot", "digraph"), (".mmd", "flowchart LR")])
def test_render_text_formats(pour: TaskGraph, tmp_path: Path, suffix: str, head: str) -> None:
    out = render(pour, tmp_path / f"g{suffix}")
    assert out.read_text().startswith(head)


@pytest.mark.skipif(shutil.which("dot") is None, reason="Graphviz `dot` not installed (apt-get install graphviz)")
def test_render_svg_and_png(pour: TaskGraph, tmp_path: Path) -> None:
    svg = render(pour, tmp_path / "g.svg").read_text()
    assert "<svg" in svg and PINK in svg and BLUE in svg
    assert render(pour, tmp_path / "g.png").read_bytes().startswith(b"\x89PNG")


def test_render_without_dot_says_how_to_install(
    pour: TaskGraph, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(shutil, "which", lambda name: None)
    with pytest.raises(RenderError, match="apt-get install graphviz"):
        render(pour, tmp_path / "g.svg")
    assert not (tmp_path / "g.svg").exists()


def test_render_unknown_suffix(pour: TaskGraph, tmp_path: Path) -> None:
    with pytest.raises(RenderError, match=r"unknown format '.jpg'; use .dot, .gv, .mmd, .svg, .png, .pdf"):
        render(pour, tmp_path / "g.jpg")


def test_render_refuses_a_graph_too_large_to_lay_out(pour: TaskGraph, tmp_path: Path, monkeypatch) -> None:
    import sys

    monkeypatch.setattr(sys.modules["agentchord.graph.render"], "MAX_LAYOUT_SIZE", 5)
    with pytest.raises(RenderError, match="render to .dot or .mmd instead"):
        render(pour, tmp_path / "g.svg")
    assert not (tmp_path / "g.svg").exists()
    render(pour, tmp_path / "g.dot")  # text formats have no limit


def test_an_arm_switching_alternative_is_drawn_dotted_and_says_what_it_replaces():
    from agentchord.graph.render import to_dot
    from agentchord.tasks import load_task_graph

    dot = to_dot(load_task_graph("single_arm_pour_water"))
    line = next(line for line in dot.splitlines() if "e2_r_bottle_dropped_via_left\\n" in line)
    assert 'style="dotted"' in line and "instead of e2_r_bottle_dropped when its arm cannot reach" in line
