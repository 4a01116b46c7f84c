"""Renderers of a task graph: Graphviz DOT, Mermaid, SVG/PNG/PDF through Graphviz, an HTML page.

Two styles. ``readable`` (the default of :func:`render`) is the figure for people of
:mod:`agentchord.graph.figure`: the nominal chain top to bottom, each recovery branch a short
arc named ``failure -> intent``, the details on hover and, in ``.html``, in tables beside it
(:mod:`agentchord.graph.page`). ``full`` (:func:`to_dot`) writes every detail on the arcs, left
to right: colours follow the paper's Fig. 3, nominal edges blue, recovery edges pink.
Recovery nodes are outlined pink, the start node is bold and the goal doubly
outlined. A recovery entry edge is dashed and labelled with the failure modes
that fire it (``when mode on edge``); a nominal edge lists its failure
modes with their entry edges (``! mode -> entry``). An arm-switching alternative of an
entry edge is dotted and says which entry it stands in for. Mermaid (``.mmd``) is the full view.
"""

from __future__ import annotations

import re
import shutil
import subprocess
import textwrap
from pathlib import Path

from agentchord.graph.exceptions import RenderError
from agentchord.graph.figure import NOMINAL_COLOR, RECOVERY_COLOR, dot_quote, to_figure_dot
from agentchord.graph.figure import edge_calls as edge_summary
from agentchord.graph.models import Edge, FailureMode, Node, TaskGraph
from agentchord.graph.page import to_html
from agentchord.guard.outputs import atomic_write_bytes, atomic_write_text

FORMATS = (".dot", ".gv", ".mmd", ".svg", ".png", ".pdf", ".html")
#: ``readable``: the figure for people (the default); ``full``: every action list and monitor on the arcs.
STYLES = ("readable", "full")
#: Largest graph (nodes + edges) laid out by Graphviz: its time grows faster than the size
#: (3,000 nodes take ~10 s, 10,000 never end); text formats have no limit.
MAX_LAYOUT_SIZE = 2500
#: Seconds Graphviz may take to lay a graph out before the render gives up with a RenderError.
LAYOUT_TIMEOUT_S = 60.0

__all__ = ["FORMATS", "STYLES", "edge_summary", "render", "to_dot", "to_mermaid"]


def _entry_failures(graph: TaskGraph) -> dict[str, list[tuple[Edge, FailureMode]]]:
    # Recovery entry edge id -> the failure modes (and their edges) that fire it.
    entries: dict[str, list[tuple[Edge, FailureMode]]] = {}
    for edge, failure in graph.failures():
        entries.setdefault(failure.recovery, []).append((edge, failure))
    return entries


def _trigger(failure: FailureMode, edge: Edge) -> str:
    # The monitor's expression stays in the file: a figure that prints it is unreadable.
    return f"when {failure.name} on {edge.id}"


def _edge_lines(edge: Edge, triggers: list[tuple[Edge, FailureMode]]) -> list[str]:
    lines = [edge.id, edge_summary(edge)]
    lines += [f"! {f.name} -> {f.recovery}" for f in edge.failures]
    lines += [_trigger(f, e) for e, f in triggers]
    if edge.alternative_to is not None:
        lines.append(f"instead of {edge.alternative_to} when its arm cannot reach")
    return lines


def _node_lines(node: Node, graph: TaskGraph) -> list[str]:
    title = node.id
    if node.id == graph.start:
        title += " (start)"
    if node.id == graph.goal:
        title += " (goal)"
    return [title, *textwrap.wrap(node.semantic, 32)]


def _dot_label(lines: list[str]) -> str:
    # "\l" would left-align; centred lines read better in small boxes.
    return dot_quote("\n".join(lines)).replace("\n", "\\n")


def to_dot(graph: TaskGraph) -> str:
    """The graph as Graphviz DOT source."""
    out = [
        f"digraph {dot_quote(graph.task)} {{",
        "  rankdir=LR;",
        '  node [shape=box, style="rounded", fontname="Helvetica", fontsize=10];',
        '  edge [fontname="Helvetica", fontsize=9];',
    ]
    for node in graph.nodes:
        attrs = [f"label={_dot_label(_node_lines(node, graph))}"]
        if node.is_recovery:
            attrs.append(f'color="{RECOVERY_COLOR}"')
        if node.id == graph.start:
            attrs.append('style="rounded,bold", penwidth=2')
        if node.id == graph.goal:
            attrs.append("peripheries=2")
        out.append(f"  {dot_quote(node.id)} [{', '.join(attrs)}];")
    triggers = _entry_failures(graph)
    for edge in graph.edges:
        color = RECOVERY_COLOR if edge.is_recovery else NOMINAL_COLOR
        attrs = [
            f"label={_dot_label(_edge_lines(edge, triggers.get(edge.id, [])))}",
            f'color="{color}"',
            f'fontcolor="{color}"',
        ]
        if edge.id in triggers:
            attrs.append('style="dashed"')
        elif edge.alternative_to is not None:
            attrs.append('style="dotted"')
        out.append(f"  {dot_quote(edge.source)} -> {dot_quote(edge.target)} [{', '.join(attrs)}];")
    out.append("}")
    return "\n".join(out) + "\n"


def _mermaid_text(lines: list[str]) -> str:
    # Mermaid labels are quoted strings: escape quotes and markup as entities.
    escaped = (
        line.replace("&", "#amp;").replace('"', "#quot;").replace("<", "#lt;").replace(">", "#gt;") for line in lines
    )
    return '"' + "<br/>".join(escaped) + '"'


def _mermaid_ids(graph: TaskGraph) -> dict[str, str]:
    # Mermaid ids are bare words; some words ("end", "graph") are keywords.
    ids: dict[str, str] = {}
    names = [n.id for n in graph.nodes] + [x for e in graph.edges for x in (e.source, e.target)]
    for name in names:
        if name not in ids:
            ids[name] = f"n{len(ids)}_{re.sub(r'[^0-9A-Za-z_]', '_', name)}"
    return ids


def to_mermaid(graph: TaskGraph) -> str:
    """The graph as a Mermaid flowchart, edge colours set with ``linkStyle``."""
    ids = _mermaid_ids(graph)
    out = ["flowchart LR"]
    for node in graph.nodes:
        out.append(f"  {ids[node.id]}({_mermaid_text(_node_lines(node, graph))})")
    triggers = _entry_failures(graph)
    styles = []
    for index, edge in enumerate(graph.edges):
        arrow = "-.->" if edge.id in triggers else "-->"
        label = _mermaid_text(_edge_lines(edge, triggers.get(edge.id, [])))
        out.append(f"  {ids[edge.source]} {arrow}|{label}| {ids[edge.target]}")
        color = RECOVERY_COLOR if edge.is_recovery else NOMINAL_COLOR
        styles.append(f"  linkStyle {index} stroke:{color},color:{color}")
    out += styles
    out.append(f"  classDef recovery stroke:{RECOVERY_COLOR},stroke-width:2px")
    out.append("  classDef start stroke-width:3px")
    out.append("  classDef goal stroke-width:3px,stroke-dasharray:0")
    for cls, members in (
        ("recovery", [n.id for n in graph.recovery_nodes()]),
        ("start", [graph.start] if graph.start in ids else []),
        ("goal", [graph.goal] if graph.goal in ids else []),
    ):
        if members:
            out.append(f"  class {','.join(ids[m] for m in members)} {cls}")
    return "\n".join(out) + "\n"


def render(graph: TaskGraph, out_path: str | Path, style: str = "readable") -> Path:
    """Write the graph to ``out_path`` in the format its suffix names.

    ``.dot``/``.gv`` and ``.mmd`` are text; ``.svg``, ``.png`` and ``.pdf`` are laid out
    by Graphviz (the ``graphviz`` Python package and the ``dot`` binary), up to
    :data:`MAX_LAYOUT_SIZE` nodes and edges; ``.html`` is a page with the SVG figure and
    tables of every node's, edge's and branch's details. The file is written atomically.

    Args:
        graph: The task graph.
        out_path: The file to write.
        style: One of :data:`STYLES` (``.mmd`` is always the full view).

    Returns:
        The path written.

    Raises:
        RenderError: Unknown suffix or style, a graph too large to lay out, or Graphviz missing or failing.
    """
    out_path = Path(out_path)
    suffix = out_path.suffix.lower()
    if style not in STYLES:
        raise RenderError(f"cannot render to {out_path}: unknown style {style!r}; use {', '.join(STYLES)}")
    dot = to_figure_dot if style == "readable" else to_dot
    if suffix in (".dot", ".gv"):
        atomic_write_text(out_path, dot(graph))
    elif suffix == ".mmd":
        atomic_write_text(out_path, to_mermaid(graph))
    elif suffix in (".svg", ".png", ".pdf", ".html"):
        if (size := len(graph.nodes) + len(graph.edges)) > MAX_LAYOUT_SIZE:
            raise RenderError(
                f"cannot render to {out_path}: the graph has {size} nodes and edges, more than Graphviz lays out "
                f"in reasonable time ({MAX_LAYOUT_SIZE}); render to .dot or .mmd instead"
            )
        if suffix == ".html":
            svg = _graphviz_pipe(dot(graph), "svg").decode("utf-8")
            atomic_write_text(out_path, to_html(graph, svg))
        else:
            atomic_write_bytes(out_path, _graphviz_pipe(dot(graph), suffix[1:]))
    else:
        raise RenderError(
            f"cannot render to {out_path}: unknown format {suffix or '(none)'!r}; use {', '.join(FORMATS)}"
        )
    return out_path


def _graphviz_pipe(source: str, fmt: str) -> bytes:
    if shutil.which("dot") is None:
        raise RenderError(
            f"rendering {fmt} needs the Graphviz `dot` binary, which is not on PATH: "
            "install it with `apt-get install graphviz` (macOS: `brew install graphviz`), "
            "or render to .dot or .mmd instead"
        )
    try:
        # The binary run as the package would run it, with a time limit the package does not offer.
        done = subprocess.run(["dot", f"-T{fmt}"], input=source.encode("utf-8"), capture_output=True,
                              timeout=LAYOUT_TIMEOUT_S, check=False)
    except subprocess.TimeoutExpired:
        raise RenderError(f"Graphviz did not lay the graph out within {LAYOUT_TIMEOUT_S:g} s (a graph this dense takes "
                          "longer than a figure is worth): render to .dot or .mmd instead") from None
    except OSError as error:
        raise RenderError(f"Graphviz failed to render {fmt}: {error}") from None
    if done.returncode != 0:
        message = done.stderr.decode("utf-8", "replace").strip()[:500]
        raise RenderError(f"Graphviz failed to render {fmt}: {message or f'exit status {done.returncode}'}")
    return done.stdout
