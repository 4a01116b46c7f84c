"""Tests of agentchord.graph.render."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from agentchord.library import library_path, library_tasks
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
    from agentchord.library import load_task_graph

    dot = to_dot(load_task_graph("single_arm_pour_water"))
    line = next(line for line in dot.splitlines() if "e2_r_bottle_dropped_via_left\\n" in line)
    assert 'style="dotted"' in line and "instead of e2_r_bottle_dropped when its arm cannot reach" in line


# ------------------------------------------------------------------ the readable figure (issue 49)
LIBRARY = [library_path(task) for task in library_tasks()]
needs_dot = pytest.mark.skipif(shutil.which("dot") is None, reason="Graphviz `dot` not installed (apt-get install graphviz)")


def _svg_text(svg: str) -> str:
    import html
    import re

    return "\n".join(html.unescape(t) for t in re.findall(r"<text[^>]*>([^<]*)</text>", svg))


@needs_dot
@pytest.mark.parametrize("path", LIBRARY, ids=[p.stem for p in LIBRARY])
def test_each_library_graph_renders_within_a_page_with_its_names(path: Path, tmp_path: Path) -> None:
    from PIL import Image

    graph = load_graph(path)
    png = render(graph, tmp_path / "g.png")
    width, height = Image.open(png).size
    assert width <= 1600 and height <= 2000, (width, height)  # legible at 1:1 on a 1600 px wide page
    text = _svg_text(render(graph, tmp_path / "g.svg").read_text())
    for node in graph.nodes:
        assert node.id in text
    for edge, failure in graph.failures():
        assert failure.name in text, f"{failure.name} on {edge.id}"
    # Monitors stay out of the picture (they are the hover text and the page's tables).
    assert not any(failure.monitor in text for _, failure in graph.failures())


def test_readable_dot_names_each_branch_and_folds_the_other_arm() -> None:
    from agentchord.graph.figure import to_figure_dot
    from agentchord.library import load_task_graph

    dot = to_figure_dot(load_task_graph("handover_block"))
    assert "rankdir=TB" in dot
    entry = _dot_line(dot, '"v0" -> "v1" [label=<block_dropped')
    assert "block_dropped \u2192 regrasp" in entry and "e1_r_block_dropped (or right arm)" in entry
    assert "e1_r_block_dropped_via_right" not in entry.split("tooltip")[0]  # folded: in the hover text only
    assert "open_gripper(L); grasp(R)" in entry  # ... where the other arm's calls are
    # Retries (leave and merge at the same node) share one box beside it, out and back.
    assert '"retry v1" [label=<<b>\u21bb retry at v1</b>' in dot
    assert '"v1" -> "retry v1"' in dot and '"retry v1" -> "v1"' in dot
    assert "grip_low \u2192 regrip high" in _dot_line(dot, '"retry v1" [')


def test_readable_figure_keeps_a_retry_box_clear_of_a_node_of_its_name() -> None:
    from agentchord.graph.figure import to_figure_dot

    graph = TaskGraph.model_validate({
        "task": "t", "start": "a", "goal": "retry a",
        "nodes": [{"id": "a", "semantic": "s"}, {"id": "retry a", "semantic": "g"}],
        "edges": [
            {"id": "e", "source": "a", "target": "retry a", "actions": {"right": {"fn": "back"}},
             "failures": [{"name": "f", "monitor": "1", "intent": "again", "recovery": "r"}]},
            {"id": "r", "kind": "recovery", "source": "a", "target": "a", "actions": {"right": {"fn": "back"}}},
        ],
    })
    dot = to_figure_dot(graph)
    assert "\"retry a'\" [label=" in dot and '"a" -> "retry a\'"' in dot


def test_html_page_has_the_figure_and_every_detail(pour: TaskGraph, tmp_path: Path) -> None:
    if shutil.which("dot") is None:
        pytest.skip("Graphviz `dot` not installed")
    page = render(pour, tmp_path / "g.html").read_text()
    assert page.startswith("<!DOCTYPE html>") and "<svg" in page and "<?xml" not in page
    assert "Nominal chain" in page and "Recovery branches" in page
    for _, failure in pour.failures():
        assert html_escape(failure.monitor) in page
    assert "grasp(R, obj=bottle" in page  # full calls, with their arguments


def html_escape(text: str) -> str:
    import html

    return html.escape(text)


def test_full_style_keeps_the_old_view(pour: TaskGraph, tmp_path: Path) -> None:
    assert render(pour, tmp_path / "g.dot", style="full").read_text() == to_dot(pour)
    assert "rankdir=TB" in render(pour, tmp_path / "r.dot").read_text()  # readable is the default
    with pytest.raises(RenderError, match="unknown style 'tiny'; use readable, full"):
        render(pour, tmp_path / "g.dot", style="tiny")


@needs_dot
def test_a_node_semantic_over_16_kb_renders_with_its_label_cut(tmp_path):
    """Issue 58: Graphviz refuses a quoted string over 16,384 characters and closed its input: BrokenPipeError, exit 3."""
    from agentchord.library import load_task_graph

    graph = load_task_graph("single_arm_pour_water")
    long = graph.nodes[1].model_copy(update={"semantic": "bottle held " * 2000})
    graph = graph.model_copy(update={"nodes": [graph.nodes[0], long, *graph.nodes[2:]]})
    for suffix in (".svg", ".html"):
        out = render(graph, tmp_path / f"g{suffix}", style="full")
        assert "characters in all" in out.read_text()


@needs_dot
def test_a_layout_that_takes_too_long_is_a_render_error(tmp_path, monkeypatch):
    """Issue 58: a dense graph (1,749 nodes and edges, under the size cap) was still laying out after 240 s."""
    import importlib

    from agentchord.library import load_task_graph

    render_module = importlib.import_module("agentchord.graph.render")  # the package's ``render`` is the function
    monkeypatch.setattr(render_module, "LAYOUT_TIMEOUT_S", 0.001)
    with pytest.raises(RenderError, match="did not lay the graph out within 0.001 s"):
        render(load_task_graph("dual_arm_pour_water"), tmp_path / "g.svg")
    assert not (tmp_path / "g.svg").exists()
