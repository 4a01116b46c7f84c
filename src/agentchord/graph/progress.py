"""Cost-to-go and the forward-moving principle (paper Eq. 8).

Edge weight = expected execution cost in control ticks. ``D(u, goal)`` is the
shortest-path cost from ``u`` to the goal in the augmented graph (nominal and
recovery edges). A recovery branch whose failure context is ``v_i`` (the source
of the failing edge) and whose entry edge reaches ``r`` is admissible only if
``D(r, goal) <= D(v_i, goal)``: recovering must never move the task backwards.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterable
from dataclasses import dataclass, field

import networkx as nx

from agentchord.graph.catalog import ACTIONS
from agentchord.graph.exceptions import NoPathError, UnknownActionError
from agentchord.graph.models import Edge, TaskGraph

#: Slack of the admissibility test, so that equal costs summed in another order still pass.
TOLERANCE = 1e-9


def edge_cost(edge: Edge) -> float:
    """Expected execution cost of ``edge`` in control ticks.

    ``edge.cost`` when set; otherwise the catalogue's ``expected_ticks`` summed
    over the steps, a synchronous step lasting as long as its slowest arm.

    Raises:
        UnknownActionError: ``edge.cost`` is unset and a step calls an unknown action.
    """
    if edge.cost is not None:
        return edge.cost
    total = 0.0
    for step in edge.steps:
        ticks = [0.0]
        for call in step.values():
            if call is None:
                continue
            spec = ACTIONS.get(call.fn)
            if spec is None:
                raise UnknownActionError(edge.id, call.fn)
            ticks.append(float(spec.expected_ticks))
        total += max(ticks)
    return total


def augmented_digraph(graph: TaskGraph, *, nominal_only: bool = False) -> nx.DiGraph:
    """The graph as a weighted ``networkx.DiGraph``.

    Each arc carries ``weight`` (:func:`edge_cost`) and ``edge`` (the edge id);
    of parallel edges between the same pair of nodes the cheapest is kept.

    Args:
        graph: The task graph.
        nominal_only: Keep only nominal edges (the plan without recovery).
    """
    digraph = nx.DiGraph()
    digraph.add_nodes_from(node.id for node in graph.nodes)
    for edge in graph.nominal_edges() if nominal_only else graph.edges:
        weight = edge_cost(edge)
        current = digraph.get_edge_data(edge.source, edge.target)
        if current is None or weight < current["weight"]:
            digraph.add_edge(edge.source, edge.target, weight=weight, edge=edge.id)
    return digraph


def cost_to_go(graph: TaskGraph) -> dict[str, float]:
    """``D(u, goal)`` for every node ``u`` over the augmented graph; ``inf`` when the goal is unreachable.

    Raises:
        UnknownNodeError: The goal is not a node of the graph.
        UnknownActionError: An edge without ``cost`` calls an unknown action.
    """
    graph.node(graph.goal)
    digraph = augmented_digraph(graph)
    # One Dijkstra from the goal over reversed arcs gives every node's distance to it.
    lengths = nx.single_source_dijkstra_path_length(digraph.reverse(copy=False), graph.goal, weight="weight")
    return {node: float(lengths.get(node, math.inf)) for node in digraph.nodes}


def nominal_path(graph: TaskGraph) -> list[str]:
    """Edge ids of the cheapest start-to-goal path over nominal edges.

    Raises:
        NoPathError: The goal is not reachable from the start over nominal edges.
        UnknownNodeError: Start or goal is not a node of the graph.
    """
    graph.node(graph.start)
    graph.node(graph.goal)
    digraph = augmented_digraph(graph, nominal_only=True)
    try:
        nodes = nx.dijkstra_path(digraph, graph.start, graph.goal, weight="weight")
    except nx.NetworkXNoPath:
        raise NoPathError(
            f"goal {graph.goal!r} is not reachable from start {graph.start!r} over nominal edges"
        ) from None
    return [digraph.edges[u, v]["edge"] for u, v in itertools.pairwise(nodes)]


@dataclass(frozen=True)
class RecoveryBranch:
    """One failure mode's recovery branch, judged by the forward-moving principle.

    Attributes:
        failure: Name of the failure mode.
        edge: Id of the edge the failure mode belongs to.
        recovery_edge: Id of the recovery entry edge.
        recovery_node: ``r``, the entry edge's target (a recovery node or a reused nominal one).
        context: ``v_i``, the failure context: the source of the failing edge.
        recovery_cost: ``D(r, goal)``.
        context_cost: ``D(v_i, goal)``.
    """

    failure: str
    edge: str
    recovery_edge: str
    recovery_node: str
    context: str
    recovery_cost: float
    context_cost: float

    @property
    def admissible(self) -> bool:
        """Whether ``D(r, goal) <= D(v_i, goal)`` (within :data:`TOLERANCE`)."""
        return self.recovery_cost <= self.context_cost + TOLERANCE

    @property
    def reason(self) -> str:
        """The comparison, e.g. ``D(r_x, goal)=350  >  D(v1, goal)=300``."""
        relation = "<=" if self.admissible else ">"
        return (
            f"D({self.recovery_node}, goal)={self.recovery_cost:g}  {relation}  "
            f"D({self.context}, goal)={self.context_cost:g}"
        )


#: The name the forward-moving filter's report uses for a branch it removed.
RemovedBranch = RecoveryBranch


@dataclass
class FilterResult:
    """What :func:`forward_filter` kept and removed.

    Attributes:
        graph: The filtered graph (a copy; the input is not modified).
        removed: Regressive branches whose failure modes were dropped.
        kept: Admissible branches.
        removed_edges: Recovery edge ids removed because no remaining entry reaches them.
        removed_nodes: Recovery node ids removed because no remaining entry reaches them.
    """

    graph: TaskGraph
    removed: list[RecoveryBranch]
    kept: list[RecoveryBranch] = field(default_factory=list)
    removed_edges: list[str] = field(default_factory=list)
    removed_nodes: list[str] = field(default_factory=list)


def recovery_branches(graph: TaskGraph, distances: dict[str, float] | None = None) -> list[RecoveryBranch]:
    """Every failure mode's recovery branch with its two costs, in file order.

    Args:
        graph: The task graph.
        distances: ``D(u, goal)``; computed with :func:`cost_to_go` when omitted.

    Raises:
        UnknownEdgeError: A failure mode names an unknown recovery entry edge.
    """
    if distances is None:
        distances = cost_to_go(graph)
    branches = []
    by_id = {e.id: e for e in graph.edges}  # one index, not a scan per branch (large graphs)
    for edge, failure in graph.failures():
        entry = by_id.get(failure.recovery) or graph.edge(failure.recovery)
        branches.append(
            RecoveryBranch(
                failure=failure.name,
                edge=edge.id,
                recovery_edge=entry.id,
                recovery_node=entry.target,
                context=edge.source,
                recovery_cost=distances.get(entry.target, math.inf),
                context_cost=distances.get(edge.source, math.inf),
            )
        )
    return branches


def recovery_reach(graph: TaskGraph, entries: Iterable[str]) -> tuple[set[str], set[str]]:
    """Edges and nodes a recovery can pass through, starting on the given entry edges.

    From each entry edge's target, the walk follows the edges that leave
    recovery nodes; it stops at nominal nodes, where the recovery has merged.

    Args:
        graph: The task graph.
        entries: Ids of recovery entry edges (unknown ids are ignored).

    Returns:
        ``(edge ids, node ids)`` reached; node ids include the nominal merge nodes.
    """
    known = {edge.id: edge for edge in graph.edges}
    recovery_nodes = {node.id for node in graph.recovery_nodes()}
    edges = {edge_id for edge_id in entries if edge_id in known}
    nodes: set[str] = set()
    frontier = [known[edge_id].target for edge_id in edges]
    leaving: dict[str, list] = {}  # one index, not a scan per node (large graphs)
    for edge in graph.edges:
        leaving.setdefault(edge.source, []).append(edge)
    while frontier:
        node = frontier.pop()
        if node in nodes:
            continue
        nodes.add(node)
        if node not in recovery_nodes:
            continue
        for edge in leaving.get(node, []):
            edges.add(edge.id)
            frontier.append(edge.target)
    return edges, nodes


def with_alternatives(graph: TaskGraph, entries: Iterable[str]) -> list[str]:
    """Recovery entry edge ids followed by the ids of their alternatives (``Edge.alternative_to``)."""
    entries = list(entries)
    wanted = set(entries)
    return entries + [edge.id for edge in graph.edges if edge.alternative_to in wanted]


def forward_filter(graph: TaskGraph) -> FilterResult:
    """Remove regressive recovery branches (paper Eq. 8).

    ``D`` is computed once, on the unfiltered augmented graph. A branch with
    ``D(r, goal) > D(v_i, goal)`` loses its failure mode; recovery edges and
    nodes that no remaining recovery entry reaches any more are removed too.

    Args:
        graph: A graph whose references are valid (see ``check_graph``).

    Returns:
        The filtered copy of the graph and what was removed and why.

    Raises:
        UnknownEdgeError: A failure mode names an unknown recovery entry edge.
        UnknownActionError: An edge without ``cost`` calls an unknown action.
    """
    branches = recovery_branches(graph, cost_to_go(graph))
    removed = [branch for branch in branches if not branch.admissible]
    kept = [branch for branch in branches if branch.admissible]
    dropped = {(branch.edge, branch.failure) for branch in removed}

    filtered = graph.model_copy(deep=True)
    for edge in filtered.edges:
        edge.failures = [f for f in edge.failures if (edge.id, f.name) not in dropped]

    # An alternative (another arm's way along an entry edge) stands or falls with its entry edge.
    before_edges, before_nodes = recovery_reach(graph, with_alternatives(graph, (b.recovery_edge for b in branches)))
    after_edges, after_nodes = recovery_reach(filtered, with_alternatives(filtered, (b.recovery_edge for b in kept)))
    # Only what a removed branch made unreachable goes; nominal nodes always stay.
    gone_edges = {e.id for e in graph.recovery_edges() if e.id in before_edges - after_edges}
    gone_nodes = {n.id for n in graph.recovery_nodes() if n.id in before_nodes - after_nodes}
    gone_edges |= {e.id for e in graph.edges if e.source in gone_nodes or e.target in gone_nodes}
    filtered.edges = [e for e in filtered.edges if e.id not in gone_edges]
    filtered.nodes = [n for n in filtered.nodes if n.id not in gone_nodes]
    return FilterResult(
        graph=filtered,
        removed=removed,
        kept=kept,
        removed_edges=[e.id for e in graph.edges if e.id in gone_edges],
        removed_nodes=[n.id for n in graph.nodes if n.id in gone_nodes],
    )
