"""A task graph as one HTML page: the figure, with every detail it leaves out in tables beside it.

The figure is Graphviz's SVG, inline: hovering a node or an arc shows its details (its
``tooltip``). Beside it, two tables hold what the readable figure leaves out: the nominal
chain's nodes with their constraints and edges with their full action calls and failure
modes (monitor, margin, window, recovery), and each recovery branch with where it leaves and
merges, what fires it, its calls and the other arm's way. The page needs no script and no
network: one file to open in a browser or attach to a report.
"""

from __future__ import annotations

import html
import re

from agentchord.graph.figure import (
    NOMINAL_COLOR,
    RECOVERY_TEXT,
    Arc,
    node_title,
    recovery_arcs,
)
from agentchord.graph.models import ActionCall, Edge, FailureMode, TaskGraph

_ARM_LETTER = {"left": "L", "right": "R"}

_STYLE = f"""
body {{ font-family: Helvetica, Arial, sans-serif; margin: 1.5em; color: #222; }}
.layout {{ display: flex; flex-wrap: wrap; gap: 2em; align-items: flex-start; }}
.figure svg {{ max-width: 100%; height: auto; }}
.tables {{ flex: 1 1 40em; min-width: 30em; }}
table {{ border-collapse: collapse; margin-bottom: 2em; font-size: 0.85em; width: 100%; }}
th, td {{ border: 1px solid #ccc; padding: 0.3em 0.5em; vertical-align: top; text-align: left; }}
th {{ background: #f3f3f3; }}
code {{ font-size: 0.95em; }}
h2.nominal {{ color: {NOMINAL_COLOR}; }}
h2.recovery {{ color: {RECOVERY_TEXT}; }}
ul {{ margin: 0; padding-left: 1.1em; }}
"""


def _e(text: object) -> str:
    return html.escape(str(text))


def call_text(arm: str, call: ActionCall) -> str:
    """One action call with its arguments, e.g. ``grasp(L, obj=block, height=0.85)``."""
    args = [_ARM_LETTER.get(arm, arm), *(f"{name}={value}" for name, value in call.args.items())]
    return f"{call.fn}({', '.join(args)})"


def _calls_html(edge: Edge) -> str:
    steps = []
    for step in edge.steps:
        calls = [call_text(arm, call) for arm, call in step.items() if call is not None]
        steps.append(" + ".join(f"<code>{_e(c)}</code>" for c in calls) or "idle")
    if len(steps) == 1:
        return steps[0]
    return "<ol>" + "".join(f"<li>{step}</li>" for step in steps) + "</ol>"


def _failure_html(edge: Edge | None, failure: FailureMode, recovery: bool = True) -> str:
    where = f" on <b>{_e(edge.id)}</b>" if edge is not None else ""
    text = (
        f"<b>{_e(failure.name)}</b>{where}: <code>{_e(failure.monitor)}</code> &gt; {failure.margin:g} "
        f"for {failure.window} ticks"
    )
    if recovery:
        text += f" \u2192 <code>{_e(failure.recovery)}</code>"
    return text + f" ({_e(failure.intent)})"


def _list(items: list[str]) -> str:
    return "<ul>" + "".join(f"<li>{item}</li>" for item in items) + "</ul>" if items else "-"


def _nominal_tables(graph: TaskGraph) -> str:
    rows = [
        f"<tr><td><b>{_e(node_title(node, graph))}</b></td><td>{_e(node.semantic)}</td>"
        f"<td>{_list([f'<code>{_e(c)}</code> &le; 0' for c in node.constraints])}</td></tr>"
        for node in graph.nodes
        if not node.is_recovery
    ]
    nodes = "<table><tr><th>node</th><th>sub-goal</th><th>constraints</th></tr>" + "".join(rows) + "</table>"
    rows = [
        f"<tr><td><b>{_e(edge.id)}</b></td><td>{_e(edge.source)} \u2192 {_e(edge.target)}</td>"
        f"<td>{_calls_html(edge)}</td><td>{_list([_failure_html(None, f) for f in edge.failures])}</td></tr>"
        for edge in graph.nominal_edges()
    ]
    edges = (
        "<table><tr><th>edge</th><th>from \u2192 to</th><th>actions</th><th>failure modes (monitor &gt; margin "
        "for window ticks \u2192 recovery entry)</th></tr>" + "".join(rows) + "</table>"
    )
    return nodes + edges


def _branch_row(arc: Arc, graph: TaskGraph) -> str:
    edge = arc.edge
    merge = edge.target
    if merge in {node.id for node in graph.recovery_nodes()}:
        merge += " (recovery node)"
    fired = [_failure_html(t.edge, t.failure, recovery=False) for t in arc.triggers]
    others = [f"<b>{_e(alt.id)}</b>: {_calls_html(alt)}" for alt in arc.alternatives]
    if edge.alternative_to is not None:
        others.insert(0, f"instead of <b>{_e(edge.alternative_to)}</b> when its arm cannot reach")
    return (
        f"<tr><td><b>{_e(edge.id)}</b></td><td>{_e(edge.source)} \u2192 {_e(merge)}</td>"
        f"<td>{_list(fired)}</td><td>{_calls_html(edge)}</td><td>{_list(others)}</td></tr>"
    )


def _recovery_table(graph: TaskGraph) -> str:
    rows = [_branch_row(arc, graph) for arc in recovery_arcs(graph)]
    nodes = [
        f"<tr><td><b>{_e(node.id)}</b> (recovery node)</td><td colspan=4>{_e(node.semantic)}: "
        f"{', '.join(f'<code>{_e(c)}</code> &le; 0' for c in node.constraints) or 'no constraints'}</td></tr>"
        for node in graph.recovery_nodes()
    ]
    return (
        "<table><tr><th>recovery edge</th><th>leaves \u2192 merges at</th><th>fired by</th><th>actions</th>"
        "<th>the other arm's way</th></tr>" + "".join(rows + nodes) + "</table>"
    )


def svg_body(svg: str) -> str:
    """Graphviz's SVG without its XML prolog and doctype (to sit inline in a page)."""
    start = svg.find("<svg")
    if start < 0:
        return svg
    return re.sub(r"<!--.*?-->", "", svg[start:], flags=re.DOTALL)


def to_html(graph: TaskGraph, svg: str) -> str:
    """The page: ``svg`` (the figure Graphviz drew) and the tables of the graph's details.

    Args:
        graph: The task graph.
        svg: Its figure as SVG (:func:`agentchord.graph.render.render` lays it out).
    """
    instruction = f"<p>{_e(graph.instruction)}</p>" if graph.instruction else ""
    return (
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
        f"<title>{_e(graph.task)}: task graph</title><style>{_STYLE}</style></head><body>\n"
        f"<h1>{_e(graph.task)}</h1>{instruction}"
        "<p>Hover a node or an arc for its details; the tables list them all.</p>\n"
        f"<div class=\"layout\"><div class=\"figure\">{svg_body(svg)}</div>\n<div class=\"tables\">"
        f"<h2 class=\"nominal\">Nominal chain</h2>{_nominal_tables(graph)}"
        f"<h2 class=\"recovery\">Recovery branches</h2>{_recovery_table(graph)}"
        "</div></div>\n</body></html>\n"
    )
