"""A task graph drawn for a person: the nominal chain top to bottom, each recovery branch a short named arc.

The readable figure (``graph render``'s default) keeps what a reader needs at a glance:

- the nominal chain, top to bottom (a long chain stays within a page's width), each node
  with its id and its sub-goal in words, each nominal edge with its id and its action calls;
- one pink arc per recovery entry edge, from where the branch leaves (the failing edge's
  source) to where it merges, named by what fires it and what it does
  (``block_dropped -> regrasp``), with its edge id underneath;
- an arm-switching alternative (the other arm's way) folded into the arc it stands in for
  (``or left arm``); one with other ends is drawn dotted, on its own.

Every action list, monitor expression and persistence window stays out of the picture: in
the SVG they are each arc's and node's hover text (Graphviz ``tooltip``), and
:mod:`agentchord.graph.page` lists them in tables beside the figure. The full-label view
of every detail on the arcs is :func:`agentchord.graph.render.to_dot`.
"""

from __future__ import annotations

import html
import textwrap
from dataclasses import dataclass, field

from agentchord.graph.models import Edge, FailureMode, Node, TaskGraph

NOMINAL_COLOR = "#1f77b4"
#: The paper's pink (Fig. 3) for the arcs; their text darker, legible on white.
RECOVERY_COLOR = "#e377c2"
RECOVERY_TEXT = "#b0317f"
RECOVERY_FILL = "#fbe3f1"
DETAIL_COLOR = "#666666"
TITLE = "nominal chain (blue), recovery branches (pink, dashed: fired by a failure)"
#: Characters per line of a node's sub-goal and of an arc's name.
NODE_WRAP = 30
ARC_WRAP = 30

_ARM_NAMES = {"left": "left arm", "right": "right arm"}


@dataclass(frozen=True)
class Trigger:
    """A failure mode that fires a recovery entry edge, with the edge it watches."""

    edge: Edge
    failure: FailureMode


@dataclass
class Arc:
    """One recovery arc of the figure: a recovery edge and what it stands for.

    Attributes:
        edge: The recovery edge drawn.
        triggers: Failure modes that fire it, on any edge (its own included: a re-entry).
        alternatives: Its arm-switching alternatives with the same ends, folded into the arc.
    """

    edge: Edge
    triggers: list[Trigger] = field(default_factory=list)
    alternatives: list[Edge] = field(default_factory=list)

    @property
    def named_by(self) -> list[Trigger]:
        """The triggers that name the arc: those of other edges (a re-entry on itself says nothing new)."""
        own = {self.edge.id, *(alt.id for alt in self.alternatives)}
        outer = [t for t in self.triggers if t.edge.id not in own]
        return outer or self.triggers

    def name_lines(self) -> list[str]:
        """``failure[, failure] -> intent`` lines, one per intent; the edge's calls if nothing fires it."""
        by_intent: dict[str, list[str]] = {}
        for trigger in self.named_by:
            names = by_intent.setdefault(trigger.failure.intent, [])
            if trigger.failure.name not in names:
                names.append(trigger.failure.name)
        if not by_intent:
            return [edge_calls(self.edge)]
        return [f"{', '.join(names)} \u2192 {intent}" for intent, names in by_intent.items()]

    def reentries(self) -> list[str]:
        """Failure names that only its own run watches (it starts again on them), not naming it already."""
        named = {t.failure.name for t in self.named_by}
        return list(dict.fromkeys(t.failure.name for t in self.triggers if t.failure.name not in named))


def edge_calls(edge: Edge) -> str:
    """The edge's action calls, e.g. ``grasp(R)``, ``grasp(L) + grasp(R)``, ``grasp(R); move_to_obj(R)``."""
    letters = {"left": "L", "right": "R"}
    steps = []
    for step in edge.steps:
        calls = [f"{call.fn}({letters.get(arm, arm)})" for arm, call in step.items() if call is not None]
        steps.append(" + ".join(calls) or "idle")
    return "; ".join(steps)


def edge_arms(edge: Edge) -> list[str]:
    """The arms the edge's actions use, in the order they first act."""
    arms: list[str] = []
    for arm, call in edge.calls:
        if call is not None and arm not in arms:
            arms.append(arm)
    return arms


def recovery_arcs(graph: TaskGraph) -> list[Arc]:
    """The figure's recovery arcs in file order, alternatives with the same ends folded into theirs.

    An alternative whose ends differ from those of the edge it stands in for, or that stands in
    for an edge that is not there, keeps an arc of its own.
    """
    triggers: dict[str, list[Trigger]] = {}
    for edge, failure in graph.failures():
        triggers.setdefault(failure.recovery, []).append(Trigger(edge, failure))
    by_id = {edge.id: edge for edge in graph.edges}
    folded: dict[str, list[Edge]] = {}
    for edge in graph.recovery_edges():
        main = by_id.get(edge.alternative_to or "")
        if main is not None and (main.source, main.target) == (edge.source, edge.target):
            folded.setdefault(main.id, []).append(edge)
    hidden = {alt.id for alts in folded.values() for alt in alts}
    arcs = []
    for edge in graph.recovery_edges():
        if edge.id not in hidden:
            arcs.append(Arc(edge, triggers.get(edge.id, []), folded.get(edge.id, [])))
    return arcs


# ---------------------------------------------------------------------------------------------- DOT
#: Characters of one quoted DOT string (a label, a tooltip) a figure keeps: Graphviz refuses a quoted
#: string over 16,384 characters, and a label that long is unreadable anyway.
MAX_QUOTED_CHARS = 4000


def dot_quote(text: str) -> str:
    """``text`` as a quoted DOT string, cut to :data:`MAX_QUOTED_CHARS` (the cut says how long it was)."""
    if len(text) > MAX_QUOTED_CHARS:
        text = text[:MAX_QUOTED_CHARS - 40] + f"... [{len(text):,} characters in all]"
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


def _tooltip(lines: list[str]) -> str:
    # Graphviz turns "&#10;" into a line break in SVG titles; the rest is escaped text.
    return dot_quote("&#10;".join(html.escape(line, quote=False) for line in lines))


def _html(lines: list[tuple[str, str]]) -> str:
    """A Graphviz HTML-like label from (text, style) lines; style ``b`` bold, ``small`` grey."""
    parts = []
    for text, style in lines:
        text = html.escape(text, quote=False)
        if style == "b":
            parts.append(f"<b>{text}</b>")
        elif style == "small":
            parts.append(f'<font point-size="10" color="{DETAIL_COLOR}">{text}</font>')
        else:
            parts.append(text)
    return "<" + "<br/>".join(parts) + ">"


def node_title(node: Node, graph: TaskGraph) -> str:
    """The node's id, with ``(start)`` / ``(goal)``."""
    title = node.id
    if node.id == graph.start:
        title += " (start)"
    if node.id == graph.goal:
        title += " (goal)"
    return title


def failure_line(edge: Edge, failure: FailureMode, recovery: bool = True) -> str:
    """One failure mode in full: ``name on edge: monitor > margin for window ticks -> recovery (intent)``.

    ``recovery`` False leaves out ``-> recovery`` (said already: the arc it fires).
    """
    fired = f" \u2192 {failure.recovery}" if recovery else ""
    watch = f"{failure.monitor} > {failure.margin:g} for {failure.window} ticks"
    return f"{failure.name} on {edge.id}: {watch}{fired} ({failure.intent})"


def _node_statement(node: Node, graph: TaskGraph) -> str:
    lines = [(node_title(node, graph), "b"), *((line, "") for line in textwrap.wrap(node.semantic, NODE_WRAP))]
    tip = _tooltip([node_title(node, graph), node.semantic, *node.constraints])
    attrs = [f"label={_html(lines)}", f"tooltip={tip}"]
    if node.is_recovery:
        attrs += [f'color="{RECOVERY_COLOR}"', f'fillcolor="{RECOVERY_FILL}"', 'style="rounded,filled"']
    if node.id == graph.start:
        attrs += ['style="rounded,bold"', "penwidth=2"]
    if node.id == graph.goal:
        attrs.append("peripheries=2")
    return f"  {dot_quote(node.id)} [{', '.join(attrs)}];"


def _nominal_statement(edge: Edge) -> str:
    lines = [(edge.id, "b"), *((line, "") for line in textwrap.wrap(edge_calls(edge), ARC_WRAP))]
    # A little space between the chain's line and its label (Graphviz sets the label against it).
    lines = [("\u2003" + text, style) for text, style in lines]
    tip = [f"{edge.id}: {edge_calls(edge)}", *(failure_line(edge, f) for f in edge.failures)]
    attrs = [f"label={_html(lines)}", f'color="{NOMINAL_COLOR}"', f'fontcolor="{NOMINAL_COLOR}"', "penwidth=2.5",
             "weight=10", f"tooltip={_tooltip(tip)}", f"labeltooltip={_tooltip(tip)}"]
    return f"  {dot_quote(edge.source)} -> {dot_quote(edge.target)} [{', '.join(attrs)}];"


def arc_tooltip(arc: Arc) -> list[str]:
    """The arc's hover text: its edges' calls and every failure mode that fires it, in full."""
    lines = [f"{arc.edge.id}: {edge_calls(arc.edge)}"]
    lines += [f"  or {alt.id}: {edge_calls(alt)}" for alt in arc.alternatives]
    lines += [f"fired by {failure_line(t.edge, t.failure, recovery=False)}" for t in arc.triggers]
    return lines


def _arc_lines(arc: Arc) -> list[tuple[str, str]]:
    """The arc's name (wrapped) and, small, its edge id and the other arm's way."""
    edge = arc.edge
    lines = [(line, "") for name in arc.name_lines() for line in textwrap.wrap(name, ARC_WRAP)]
    detail = edge.id
    if arc.alternatives:
        # Name the arm an alternative brings in; one that uses the same arms differently is "the other arm's way".
        arms = [arm for alt in arc.alternatives for arm in edge_arms(alt) if arm not in edge_arms(edge)]
        detail += f" (or {' / '.join(_ARM_NAMES.get(a, a) for a in dict.fromkeys(arms)) or 'the other arm'})"
    if edge.alternative_to is not None:
        detail += f" instead of {edge.alternative_to}"
    lines.append((detail, "small"))
    if again := arc.reentries():
        lines += [(line, "small") for line in textwrap.wrap(f"again on {', '.join(again)}", ARC_WRAP + 10)]
    return lines


def _arc_statement(arc: Arc, recovery_nodes: set[str]) -> str:
    edge = arc.edge
    tip = _tooltip(arc_tooltip(arc))
    style = "dotted" if edge.alternative_to is not None else ("dashed" if arc.triggers else "solid")
    attrs = [f"label={_html(_arc_lines(arc))}", f'color="{RECOVERY_COLOR}"', f'fontcolor="{RECOVERY_TEXT}"',
             f'style="{style}"', "weight=1", f"tooltip={tip}", f"labeltooltip={tip}"]
    if edge.source in recovery_nodes and edge.target not in recovery_nodes:
        # A rank between the recovery node and its merge: its way back runs down to the node, labelled,
        # instead of sideways along the rank, all of its exits on one line.
        attrs.append("minlen=2")
    return f"  {dot_quote(edge.source)} -> {dot_quote(edge.target)} [{', '.join(attrs)}];"


def _retry_statements(node: str, arcs: list[Arc], box: str) -> list[str]:
    """The retries at ``node`` (recovery edges that leave and merge there): a box beside it, out and back.

    Graphviz draws self-loops small, stacked on the node's side, their labels over each other's lines.
    """
    lines = [(f"\u21bb retry at {node}", "b"), *(line for arc in arcs for line in _arc_lines(arc))]
    tip = _tooltip([line for arc in arcs for line in arc_tooltip(arc)])
    edge_attrs = f'color="{RECOVERY_COLOR}", style="dashed", tooltip={tip}'
    box_attrs = f'color="{RECOVERY_COLOR}", fontcolor="{RECOVERY_TEXT}", style="rounded,dashed", fontsize=12'
    return [
        f"  {dot_quote(box)} [label={_html(lines)}, {box_attrs}, tooltip={tip}];",
        f"  {{ rank=same; {dot_quote(node)}; {dot_quote(box)}; }}",
        f"  {dot_quote(node)} -> {dot_quote(box)} [{edge_attrs}];",
        f"  {dot_quote(box)} -> {dot_quote(node)} [{edge_attrs}];",
    ]


def _split_retries(graph: TaskGraph) -> tuple[list[Arc], dict[str, list[Arc]]]:
    """The recovery arcs between two nodes, and the retries (source = target) by node."""
    arcs: list[Arc] = []
    retries: dict[str, list[Arc]] = {}
    for arc in recovery_arcs(graph):
        if arc.edge.source == arc.edge.target:
            retries.setdefault(arc.edge.source, []).append(arc)
        else:
            arcs.append(arc)
    return arcs, retries


def to_figure_dot(graph: TaskGraph) -> str:
    """The readable figure as Graphviz DOT (see the module's docstring)."""
    out = [
        f"digraph {dot_quote(graph.task)} {{",
        "  rankdir=TB; nodesep=0.25; ranksep=0.35;",
        f"  label={dot_quote(f'{graph.task}: {TITLE}')};",
        '  labelloc=t; fontname="Helvetica"; fontsize=16;',
        '  node [shape=box, style="rounded", fontname="Helvetica", fontsize=13, margin="0.15,0.06"];',
        '  edge [fontname="Helvetica", fontsize=12, arrowsize=0.8];',
    ]
    out += [_node_statement(node, graph) for node in graph.nodes]
    out += [_nominal_statement(edge) for edge in graph.nominal_edges()]
    arcs, retries = _split_retries(graph)
    recovery_nodes = {node.id for node in graph.recovery_nodes()}
    out += [_arc_statement(arc, recovery_nodes) for arc in arcs]
    taken = {node.id for node in graph.nodes}
    for node, node_retries in retries.items():
        box = f"retry {node}"
        while box in taken:  # a node of that name: the box takes another
            box += "'"
        taken.add(box)
        out += _retry_statements(node, node_retries, box)
    out.append("}")
    return "\n".join(out) + "\n"
