"""What each agent call writes, and how many tokens that is: the parts of a graph as replies.

A token-priced latency model charges a call by its output (time to first token + output tokens /
decode rate), so each call is priced by the reply it returns: the graph part it writes, serialised
as compact JSON the way the LLM prompts ask for it (defaults left out). Tokens are counted as
characters / 4, no tokenizer being shipped; against GPT-4o's ``o200k_base`` it counts 0.71 of these
replies' real tokens on the mean, 0.57 of the conductor's numbers (``benchmarks/bench_token_count.py``).

The pipelined plan splits the agents' work (:mod:`agentchord.execution.planning`): the composer's
nominal graph is written in execution order -- the start node, then each edge followed by the node it
reaches (:func:`stream_order`) -- so that an edge and both its nodes can be read from the stream
long before the reply ends; the arranger writes each edge's failure modes, then each mode's branch,
and last, in calls of their own, the branches' other-arm alternatives; the conductor grounds each
edge, each branch and each alternative (:func:`branch_owners` says which mode's branch
brings which recovery edge).
"""

from __future__ import annotations

import json
import math
from typing import Any

from agentchord.graph.models import Edge, TaskGraph
from agentchord.graph.progress import nominal_path, recovery_reach, with_alternatives

#: Characters per token: the usual rule of thumb (o200k_base measures 2.8 on these compact JSON replies).
CHARS_PER_TOKEN = 4.0
#: What a streamed nominal graph opens with, before its nodes and edges (:func:`stream_order`).
STREAM_HEADER = ("task", "instruction", "objects", "start", "goal")


def count_tokens(value: Any) -> int:
    """Output tokens of ``value`` written as compact JSON (a string is counted as it is)."""
    text = value if isinstance(value, str) else json.dumps(value, separators=(",", ":"), ensure_ascii=False)
    return math.ceil(len(text) / CHARS_PER_TOKEN)


def _dump(model) -> dict[str, Any]:
    return model.model_dump(mode="json", exclude_defaults=True)


def stream_order(graph: TaskGraph) -> list[str]:
    """The nominal graph's node and edge ids in the order the composer writes them: as they execute.

    Each edge of the nominal path followed by the node it reaches (the first edge by the start node
    too, which it leaves); nominal nodes and edges off the path (none in a well-formed graph) close
    the list. The first edge is written before any node -- the conductor grounds its actions from
    the edge alone -- and a reader of the stream has every edge with both its nodes one node later.
    """
    order: list[str] = []
    for edge_id in nominal_path(graph):
        edge = graph.edge(edge_id)
        order += [edge_id, *(node for node in (edge.source, edge.target) if node not in order)]
    seen = set(order)
    order += [n.id for n in graph.nodes if not n.is_recovery and n.id not in seen]
    order += [e.id for e in graph.edges if not e.is_recovery and e.id not in seen]
    return order


def nominal_reply(graph: TaskGraph) -> dict[str, Any]:
    """The composer's reply: the nominal graph (no failure modes, no recovery) as it streams.

    The header (:data:`STREAM_HEADER`), then ``graph``: its nodes and edges in :func:`stream_order`
    (an edge is the item with a ``source``).
    """
    data = _dump(graph)
    items = {n.id: _dump(n) for n in graph.nodes if not n.is_recovery}
    items |= {e.id: _dump(e.model_copy(update={"failures": []})) for e in graph.edges if not e.is_recovery}
    reply = {key: data[key] for key in STREAM_HEADER if key in data}
    reply["graph"] = [items[item] for item in stream_order(graph)]
    return reply


def streamed_tokens(graph: TaskGraph) -> dict[str, int]:
    """Per nominal node and edge, the composer's output tokens up to the end of it in its streamed reply."""
    reply = nominal_reply(graph)
    text = json.dumps(reply, separators=(",", ":"), ensure_ascii=False)
    ends: dict[str, int] = {}
    cursor = text.index('"graph":')
    for item in reply["graph"]:
        piece = json.dumps(item, separators=(",", ":"), ensure_ascii=False)
        cursor = text.index(piece, cursor) + len(piece)
        ends[item["id"]] = math.ceil(cursor / CHARS_PER_TOKEN)
    return ends


def edge_reply(edge: Edge) -> dict[str, Any]:
    """One nominal edge as the composer writes it (actions and path constraints; no failure modes)."""
    return _dump(edge.model_copy(update={"failures": []}))


def grounding_patch(edges: list[Edge]) -> dict[str, Any]:
    """What the conductor writes for ``edges``: the values it grounds, not the structure it keeps.

    Per edge, every numeric action argument (offsets, heights, yaws, targets, angles: ``step.arm.arg``)
    and every failure mode's trigger (margin, window); tolerances inside expressions are left out
    (they are few, and a patch of them would name the expression). The structure -- ids, endpoints,
    actions, monitors, the recovery map -- is fixed by the composer and the arranger and not repeated.
    """
    patch: dict[str, Any] = {}
    for edge in edges:
        values: dict[str, Any] = {}
        for index, step in enumerate(edge.steps):
            for arm, call in step.items():
                if call is None:
                    continue
                for name, value in call.args.items():
                    if isinstance(value, (int, float, list)) and not isinstance(value, bool):
                        values[f"{index}.{arm}.{name}"] = value
        for failure in edge.failures:
            values[failure.name] = [failure.margin, failure.window]
        if values:
            patch[edge.id] = values
    return patch


def branch_owners(graph: TaskGraph) -> dict[str, tuple[str, str]]:
    """Recovery edge or node id -> the (nominal edge, failure mode) whose branch first leads to it.

    Nominal edges are taken in execution order and each one's failure modes in order; from a mode
    the walk follows its entry edge, the entry's alternatives, what leaves the recovery nodes they
    reach, and the failure modes of every recovery edge reached (a second failure while recovering),
    until nothing new is found. What no nominal edge's mode leads to is owned by the last mode.
    """
    owners: dict[str, tuple[str, str]] = {}
    last: tuple[str, str] | None = None
    for edge_id, failure in nominal_failures(graph):
        last = (edge_id, failure)
        for item in branch_reach(graph, edge_id, failure):
            owners.setdefault(item, last)
    for item in [*graph.recovery_edges(), *graph.recovery_nodes()]:
        if last is not None:
            owners.setdefault(item.id, last)
    return owners


def nominal_failures(graph: TaskGraph) -> list[tuple[str, str]]:
    """Every (nominal edge, failure mode name) pair, edges in execution order."""
    return [(edge_id, f.name) for edge_id in nominal_path(graph) for f in graph.edge(edge_id).failures]


def branch_reach(graph: TaskGraph, edge_id: str, failure: str) -> list[str]:
    """Recovery edge and node ids the branch of one failure mode can pass through, in a stable order."""
    known = {e.id: e for e in graph.edges}
    frontier = [f.recovery for f in known[edge_id].failures if f.name == failure]
    seen: list[str] = []
    while frontier:
        entries = [e for e in with_alternatives(graph, frontier) if e not in seen]
        frontier = []
        edges, nodes = recovery_reach(graph, entries)
        for reached in sorted(edges - set(seen)):
            seen.append(reached)
            frontier += [f.recovery for f in known[reached].failures]
        seen += [n for n in sorted(nodes) if n not in seen and graph.node(n).is_recovery]
    return seen


def modes_reply(edge: Edge) -> list[dict[str, Any]]:
    """What the arranger first writes for one nominal edge: its failure modes (monitors, triggers, intents)."""
    return [_dump(f.model_copy(update={"recovery": ""})) for f in edge.failures]


def branch_alternatives(graph: TaskGraph, edge_id: str, failure: str, owners: dict[str, tuple[str, str]]) -> list[Edge]:
    """The other arm's ways (``alternative_to`` edges) one failure mode's branch brings: the arranger
    writes them in a call of their own, after every edge's branches (:func:`alternatives_reply`)."""
    return [e for e in graph.recovery_edges() if e.alternative_to is not None and owners.get(e.id) == (edge_id, failure)]


def alternatives_reply(graph: TaskGraph, edge_id: str, failure: str, owners: dict[str, tuple[str, str]]) -> dict[str, Any]:
    """What the arranger writes for one failure mode's other-arm alternatives (none: an empty list)."""
    return {"failure": failure, "alternatives": [_dump(e) for e in branch_alternatives(graph, edge_id, failure, owners)]}


def branch_entry(graph: TaskGraph, edge_id: str, failure: str, owners: dict[str, tuple[str, str]]) -> list[str]:
    """The part of one failure mode's branch the robot needs the moment the mode fires: its recovery
    entry, with the recovery node it reaches. The entry's alternatives (the other arm's way) come
    later (:func:`alternatives_reply`): a recovery needs one only when its own arm cannot reach."""
    key = (edge_id, failure)
    entry = next(f.recovery for f in graph.edge(edge_id).failures if f.name == failure)
    edges = [entry] if owners.get(entry) == key else []
    nodes = [graph.edge(e).target for e in edges]
    return edges + [n for n in dict.fromkeys(nodes) if owners.get(n) == key]


def branch_reply(graph: TaskGraph, edge_id: str, failure: str, owners: dict[str, tuple[str, str]]) -> dict[str, Any]:
    """What the arranger writes for one failure mode's branch: its entry, the recovery nodes and edges it brings.

    Written entry first (:func:`branch_entry`: the entry edge, then the node it reaches), then the
    rest, so that the conductor can ground the entry while the rest streams. The other arm's
    alternatives are not in it (:func:`alternatives_reply`).
    """
    key = (edge_id, failure)
    first = branch_entry(graph, edge_id, failure, owners)
    rank = {item: k for k, item in enumerate(first)}
    edges = sorted(branch_edges(graph, edge_id, failure, owners), key=lambda e: rank.get(e.id, len(rank)))
    nodes = sorted((n for n in graph.recovery_nodes() if owners.get(n.id) == key), key=lambda n: rank.get(n.id, len(rank)))
    entry_edges = [e for e in edges if e.id in rank]
    entry_nodes = [n for n in nodes if n.id in rank]
    return {
        "failure": failure,
        "recovery": next(f.recovery for f in graph.edge(edge_id).failures if f.name == failure),
        "entry": [_dump(e) for e in entry_edges] + [_dump(n) for n in entry_nodes],
        "nodes": [_dump(n) for n in nodes if n.id not in rank],
        "edges": [_dump(e) for e in edges if e.id not in rank],
    }


def branch_entry_tokens(graph: TaskGraph, edge_id: str, failure: str, owners: dict[str, tuple[str, str]]) -> int:
    """The arranger's output tokens up to the end of a branch's entry part (:func:`branch_reply`)."""
    reply = branch_reply(graph, edge_id, failure, owners)
    head = {key: reply[key] for key in ("failure", "recovery", "entry")}
    return count_tokens(head)


def branch_edges(graph: TaskGraph, edge_id: str, failure: str, owners: dict[str, tuple[str, str]]) -> list[Edge]:
    """The recovery edges one failure mode's branch brings, its other-arm alternatives aside (the conductor grounds them)."""
    return [e for e in graph.recovery_edges() if e.alternative_to is None and owners.get(e.id) == (edge_id, failure)]


def branch_nominal_nodes(graph: TaskGraph, edge_id: str, failure: str, owners: dict[str, tuple[str, str]]) -> set[str]:
    """The nominal nodes one failure mode's branch names (where it leaves and merges): the arranger reads them first."""
    nominal = {n.id for n in graph.nodes if not n.is_recovery}
    edges = [*branch_edges(graph, edge_id, failure, owners), *branch_alternatives(graph, edge_id, failure, owners)]
    return {end for e in edges for end in (e.source, e.target) if end in nominal}


def augmentation_reply(graph: TaskGraph) -> dict[str, Any]:
    """What the arranger adds to the nominal graph, all edges at once (the paper's sequential order)."""
    return {
        "failures": {e.id: [_dump(f) for f in e.failures] for e in graph.nominal_edges() if e.failures},
        "nodes": [_dump(n) for n in graph.recovery_nodes()],
        "edges": [_dump(e) for e in graph.recovery_edges()],
    }


def grounded_reply(graph: TaskGraph) -> dict[str, Any]:
    """What the conductor grounds, all at once: every edge's values (:func:`grounding_patch`)."""
    return grounding_patch(graph.edges)
