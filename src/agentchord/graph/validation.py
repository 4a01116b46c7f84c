"""Checks of a task graph beyond its schema: ids, references, actions, expressions, progress.

:func:`check_graph` returns every problem it finds, each with the field path it
is about (``edges[1].failures[0].monitor``), so that a file can be fixed in one pass.
Checks that need a sound graph (reachability, cost-to-go) run only when the ids
and references are sound, and the cost check only when every action's cost is known.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

import networkx as nx
from pydantic import ValidationError

from agentchord.graph.catalog import ACTIONS
from agentchord.expr import ExprError, Vocabulary, compile_expr
from agentchord.features.frame import ARMS
from agentchord.graph._hints import did_you_mean
from agentchord.graph.exceptions import GraphFileError, UnknownActionError
from agentchord.graph.loader import collector_paused, format_loc, load_graph
from agentchord.graph.models import ActionCall, Edge, TaskGraph
from agentchord.graph.progress import cost_to_go, recovery_branches, recovery_reach, with_alternatives


@dataclass(frozen=True)
class Problem:
    """One thing wrong with a graph.

    Attributes:
        path: Field path in the graph file, e.g. ``edges[1].failures[0].monitor``.
        message: What is wrong.
    """

    path: str
    message: str

    def __str__(self) -> str:
        return f"{self.path}: {self.message}"


def check_graph(graph: TaskGraph) -> list[Problem]:
    """Every problem of ``graph``; an empty list means the graph is valid.

    Args:
        graph: A graph that passed the schema (e.g. from ``load_graph``).

    Returns:
        The problems, grouped by check, each in file order.
    """
    with collector_paused():  # a 10,000-node graph: the collector would walk its models over and over
        problems = _check_ids(graph)
        problems += _check_references(graph)
        sound = not problems
        problems += _check_entries(graph)
        problems += _check_actions(graph)
        problems += _check_expressions(graph)
        if sound:
            problems += _check_structure(graph)
            # An unknown action (reported above) has no cost, so D is unknown: skip the progress check.
            with contextlib.suppress(UnknownActionError):
                problems += _check_progress(graph)
    return problems


def check_file(path: str | Path) -> list[str]:
    """Load and check a graph file.

    Args:
        path: A ``.yaml``, ``.yml`` or ``.json`` graph file.

    Returns:
        One line per problem, ``FILE: path.to.field: what is wrong``; empty when valid.
    """
    try:
        graph = load_graph(path)
    except GraphFileError as error:
        return error.problems
    return [f"{path}: {problem}" for problem in check_graph(graph)]


def _duplicates(items: Iterable[str], where: str, what: str, suffix: str = "") -> list[Problem]:
    first: dict[str, int] = {}
    problems = []
    for index, item in enumerate(items):
        if item in first:
            problems.append(
                Problem(f"{where}[{index}]{suffix}", f"duplicate {what} {item!r} (first at {where}[{first[item]}])")
            )
        else:
            first[item] = index
    return problems


def _check_ids(graph: TaskGraph) -> list[Problem]:
    problems = _duplicates(graph.objects, "objects", "object")
    problems += _duplicates((n.id for n in graph.nodes), "nodes", "node id", ".id")
    problems += _duplicates((e.id for e in graph.edges), "edges", "edge id", ".id")
    for i, edge in enumerate(graph.edges):
        # (edge, failure name) is the key of the recovery map (Eq. 13).
        problems += _duplicates((f.name for f in edge.failures), f"edges[{i}].failures", "failure mode", ".name")
    return problems


def _unknown(kind: str, name: str, known: Iterable[str]) -> str:
    return f"unknown {kind} {name!r}{did_you_mean(name, known)}"


def _check_references(graph: TaskGraph) -> list[Problem]:
    nodes = {n.id for n in graph.nodes}
    edges = {e.id for e in graph.edges}
    problems = [
        Problem(field, _unknown("node", node_id, nodes))
        for field, node_id in (("start", graph.start), ("goal", graph.goal))
        if node_id not in nodes
    ]
    if graph.start == graph.goal:  # an episode would end before its first tick
        problems.append(Problem("goal", f"the goal is the start node {graph.start!r}: the graph has nothing to do"))
    for i, edge in enumerate(graph.edges):
        for field in ("source", "target"):
            node_id = getattr(edge, field)
            if node_id not in nodes:
                problems.append(Problem(f"edges[{i}].{field}", _unknown("node", node_id, nodes)))
        problems += [
            Problem(f"edges[{i}].failures[{j}].recovery", _unknown("edge", failure.recovery, edges))
            for j, failure in enumerate(edge.failures)
            if failure.recovery not in edges
        ]
    return problems


def _check_entries(graph: TaskGraph) -> list[Problem]:
    edges = {e.id: e for e in graph.edges}
    problems = []
    for i, edge in enumerate(graph.edges):
        for j, failure in enumerate(edge.failures):
            path = f"edges[{i}].failures[{j}].recovery"
            entry = edges.get(failure.recovery)
            if entry is None:
                continue  # reported by _check_references
            if not entry.is_recovery:
                problems.append(
                    Problem(
                        path,
                        f"entry edge {entry.id!r} is a {entry.kind} edge; a recovery entry edge needs kind: recovery",
                    )
                )
            if entry.source != edge.source:
                # The recovery starts where the robot is: at the failure context v_i.
                problems.append(
                    Problem(
                        path,
                        f"entry edge {entry.id!r} leaves {entry.source!r}, but the failure context is "
                        f"{edge.source!r} (the source of edge {edge.id!r})",
                    )
                )
    return problems + _check_alternatives(graph)


def _check_alternatives(graph: TaskGraph) -> list[Problem]:
    """An alternative is another way along a recovery entry edge: same ends, a recovery edge itself."""
    edges = {e.id: e for e in graph.edges}
    entries = {failure.recovery for _, failure in graph.failures()}
    problems = []
    for i, edge in enumerate(graph.edges):
        if edge.alternative_to is None:
            continue
        path = f"edges[{i}].alternative_to"
        entry = edges.get(edge.alternative_to)
        if entry is None:
            problems.append(Problem(path, _unknown("edge", edge.alternative_to, edges)))
            continue
        if not edge.is_recovery:
            problems.append(Problem(f"edges[{i}].kind", "an alternative of a recovery entry edge needs kind: recovery"))
        if entry.id not in entries:
            problems.append(Problem(path, f"edge {entry.id!r} is no failure mode's recovery entry edge"))
        if entry.alternative_to is not None:
            problems.append(Problem(path, f"edge {entry.id!r} is itself an alternative (of {entry.alternative_to!r})"))
        if (edge.source, edge.target) != (entry.source, entry.target):
            problems.append(
                Problem(path, f"an alternative goes where its entry edge goes: {entry.id!r} is {entry.source} -> "
                              f"{entry.target}, this edge {edge.source} -> {edge.target}")
            )
    return problems


def _steps_path(i: int, edge: Edge, s: int) -> str:
    # A single step is written as a mapping (no index), as the file has it.
    return f"edges[{i}].actions" + (f"[{s}]" if len(edge.steps) > 1 else "")


def _check_actions(graph: TaskGraph) -> list[Problem]:
    problems = []
    for i, edge in enumerate(graph.edges):
        if not edge.steps:
            problems.append(Problem(f"edges[{i}].actions", "no step; an edge needs at least one action"))
        for s, step in enumerate(edge.steps):
            base = _steps_path(i, edge, s)
            if all(call is None for call in step.values()):
                problems.append(Problem(base, "no arm acts in this step"))
            for arm, call in step.items():
                if arm not in ARMS:
                    problems.append(
                        Problem(f"{base}.{arm}", f"{_unknown('arm', arm, ARMS)}; arms are {', '.join(ARMS)}")
                    )
                if call is not None:
                    problems += _check_call(f"{base}.{arm}", call, graph.objects)
                if call is not None and call.fn == "grasp" and call.args.get("skip_if_placed") and not _placed_later(edge, s, arm, call):
                    problems.append(Problem(f"{base}.{arm}.args.skip_if_placed",
                                            f"no later place of {call.args.get('obj')} by the {arm} arm with a target in this edge "
                                            "to tell where it would lie placed"))
    return problems


def _placed_later(edge: Edge, s: int, arm: str, grasp: ActionCall) -> bool:
    """Whether a step after ``s`` places the grasped object with the same arm at a target."""
    for step in edge.steps[s + 1:]:
        call = step.get(arm)
        if call is not None and call.fn == "place" and call.args.get("obj") == grasp.args.get("obj"):
            return call.args.get("target") is not None
    return False


def _check_call(path: str, call: ActionCall, objects: list[str]) -> list[Problem]:
    spec = ACTIONS.get(call.fn)
    if spec is None:
        known = ", ".join(sorted(ACTIONS))
        return [Problem(f"{path}.fn", f"{_unknown('action', call.fn, ACTIONS)}; actions are {known}")]
    problems = []
    try:
        spec.args.model_validate(call.args)
    except ValidationError as error:
        for detail in error.errors(include_url=False):
            extra = detail["type"] == "extra_forbidden"
            hint = did_you_mean(str(detail["loc"][-1]), spec.args.model_fields) if extra else ""
            where = ".".join(filter(None, (f"{path}.args", format_loc(detail["loc"]))))
            problems.append(Problem(where, f"{detail['msg']}{hint}"))
    listed = ", ".join(objects) if objects else "none (list them under objects)"
    for name in spec.object_fields:
        value = call.args.get(name)
        if isinstance(value, str) and value not in objects:
            message = f"{_unknown('object', value, objects)}; graph objects: {listed}"
            problems.append(Problem(f"{path}.args.{name}", message))
    return problems


def _check_expressions(graph: TaskGraph) -> list[Problem]:
    vocabulary = Vocabulary(frozenset(graph.objects))
    sources: list[tuple[str, str]] = []
    for i, node in enumerate(graph.nodes):
        sources += [(f"nodes[{i}].constraints[{k}]", c) for k, c in enumerate(node.constraints)]
    for i, edge in enumerate(graph.edges):
        sources += [(f"edges[{i}].path_constraints[{k}]", c) for k, c in enumerate(edge.path_constraints)]
        sources += [(f"edges[{i}].failures[{j}].monitor", f.monitor) for j, f in enumerate(edge.failures)]
    problems = []
    verdicts: dict[str, str | None] = {}  # the same monitor recurs on many edges: compile it once
    for path, source in sources:
        if source not in verdicts:
            try:
                compile_expr(source, vocabulary, finite_constants=True)
                verdicts[source] = None
            except ExprError as error:
                verdicts[source] = str(error)
        if verdicts[source] is not None:
            problems.append(Problem(path, verdicts[source]))
    return problems


def _check_structure(graph: TaskGraph) -> list[Problem]:
    problems = []
    nominal = nx.DiGraph((e.source, e.target) for e in graph.nominal_edges())
    nominal.add_node(graph.start)
    if graph.goal not in nx.descendants(nominal, graph.start) | {graph.start}:
        problems.append(
            Problem("goal", f"{graph.goal!r} is not reachable from start {graph.start!r} over nominal edges")
        )

    entries = {f.recovery for _, f in graph.failures()}
    reached_edges, reached_nodes = recovery_reach(graph, with_alternatives(graph, entries))
    augmented = nx.DiGraph((e.source, e.target) for e in graph.edges)
    augmented.add_node(graph.goal)
    to_goal = nx.ancestors(augmented, graph.goal) | {graph.goal}
    for i, node in enumerate(graph.nodes):
        if not node.is_recovery:
            continue
        if node.id not in reached_nodes:
            problems.append(
                Problem(f"nodes[{i}]", f"recovery node {node.id!r} is not reachable from any recovery entry edge")
            )
        if node.id not in to_goal:
            problems.append(Problem(f"nodes[{i}]", f"recovery node {node.id!r} has no path to the goal {graph.goal!r}"))
    for i, edge in enumerate(graph.edges):
        if edge.is_recovery and edge.id not in reached_edges:
            problems.append(
                Problem(
                    f"edges[{i}]",
                    f"recovery edge {edge.id!r} is on no recovery branch (no failure mode's recovery leads to it)",
                )
            )
    return problems


def _check_progress(graph: TaskGraph) -> list[Problem]:
    paths = {
        (e.id, f.name): f"edges[{i}].failures[{j}].recovery"
        for i, e in enumerate(graph.edges)
        for j, f in enumerate(e.failures)
    }
    return [
        Problem(
            paths[branch.edge, branch.failure],
            f"regressive recovery branch (forward-moving principle): {branch.reason}",
        )
        for branch in recovery_branches(graph, cost_to_go(graph))
        if not branch.admissible
    ]
