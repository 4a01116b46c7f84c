"""Online repair of unanticipated failures (paper Limitations; DESIGN section 4).

When an edge program ends, its target's sub-goal constraints do not hold and no
monitor fired, the failure was not anticipated. A :class:`Repairer` -- the
arranger re-invoked on the current state -- proposes the current graph plus ONE
new failure mode on that edge: a monitor and a recovery entry edge that starts
at the failure context and merges forward. :func:`validate_repair` decides
whether the executor may adopt the proposal; :class:`ScriptedRepairer` is the
test double that adds a fixed branch.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, Protocol

from agentchord.agents.reasoner import UnanticipatedFailure
from agentchord.features.frame import FeatureFrame
from agentchord.graph.exceptions import UnknownEdgeError
from agentchord.graph.models import Edge, FailureMode, TaskGraph
from agentchord.graph.progress import FilterResult, forward_filter
from agentchord.graph.validation import check_graph

__all__ = [
    "RepairRejectedError",
    "Repairer",
    "ScriptedRepairer",
    "UnanticipatedFailure",
    "ValidRepair",
    "validate_repair",
]


class Repairer(Protocol):
    """Synthesises one recovery branch for a failure no monitor anticipated."""

    def __call__(self, graph: TaskGraph, failure: UnanticipatedFailure, frame: FeatureFrame) -> TaskGraph | None:
        """Propose a repaired graph.

        Args:
            graph: The graph the executor runs now (already forward-filtered).
            failure: The failed edge, the failure context (its source node) and
                the violated constraints with their values, in words.
            frame: The current feature frame (the robot is where the edge left it).

        Returns:
            ``graph`` plus one new failure mode on ``failure.edge`` whose recovery
            entry edge leaves ``failure.context``, or None when no repair is found.
        """
        ...


class RepairRejectedError(Exception):
    """A proposed repair cannot be adopted.

    Attributes:
        edge: The failed edge the repair was for.
        reason: What was expected and what came.
    """

    def __init__(self, edge: str, reason: str) -> None:
        self.edge = edge
        self.reason = reason
        super().__init__(f"repair of edge {edge!r} rejected: {reason}")


@dataclass(frozen=True)
class ValidRepair:
    """An accepted repair.

    Attributes:
        filtered: The forward filter's result on the proposal (the graph to run).
        failure: The new failure mode on the failed edge.
        recovery: The new mode's recovery entry edge.
    """

    filtered: FilterResult
    failure: FailureMode
    recovery: Edge


def validate_repair(current: TaskGraph, proposal: TaskGraph, failure: UnanticipatedFailure) -> ValidRepair:
    """Check a repairer's proposal the way the executor checks a graph at start, and more.

    The proposal must keep every node and edge of ``current``, add exactly one
    failure mode to the failed edge, pass ``graph check`` and keep the new
    branch through the forward-moving filter (Eq. 8).

    Args:
        current: The graph the executor runs now.
        proposal: What the repairer returned.
        failure: The failure the repair is for.

    Returns:
        The filtered proposal, the new failure mode and its recovery entry edge.

    Raises:
        RepairRejectedError: The proposal breaks one of the rules above.
    """
    edge_id = failure.edge
    lost = [n.id for n in current.nodes if n.id not in {m.id for m in proposal.nodes}]
    lost += [e.id for e in current.edges if e.id not in {d.id for d in proposal.edges}]
    if lost:
        raise RepairRejectedError(edge_id, f"a repair adds a branch and keeps the rest, but it dropped {', '.join(lost)}")
    try:
        failed_edge = proposal.edge(edge_id)
    except UnknownEdgeError as error:
        raise RepairRejectedError(edge_id, str(error)) from None
    known = {f.name for f in current.edge(edge_id).failures}
    added = [f for f in failed_edge.failures if f.name not in known]
    if len(added) != 1:
        names = ", ".join(f.name for f in added) or "none"
        raise RepairRejectedError(edge_id, f"expected one new failure mode on {edge_id!r}, got {len(added)} ({names})")
    problems = check_graph(proposal)
    if problems:
        shown = "; ".join(str(p) for p in problems[:3])
        more = f" (and {len(problems) - 3} more)" if len(problems) > 3 else ""
        raise RepairRejectedError(edge_id, f"graph check failed: {shown}{more}")
    mode = added[0]
    filtered = forward_filter(proposal)
    for branch in filtered.removed:
        if (branch.edge, branch.failure) == (edge_id, mode.name):
            raise RepairRejectedError(edge_id, f"regressive recovery branch {mode.name!r}: {branch.reason}")
    return ValidRepair(filtered=filtered, failure=mode, recovery=filtered.graph.edge(mode.recovery))


@dataclass
class ScriptedRepairer:
    """Test double of the online arranger: adds one fixed failure mode wherever asked.

    For the failed edge named in the failure it adds a failure mode ``name``
    (``monitor``, ``intent``, ``margin``, ``window``) and its recovery entry edge
    ``<edge>_r_<name>``: from the failure context to the failed edge's target,
    running ``steps``. It does not look at the frame. The real repairer (the
    rules arranger) replaces it outside tests.

    Attributes:
        name: Name of the new failure mode.
        monitor: Its monitor expression (> 0: failure present).
        intent: What its recovery achieves (``regrasp``).
        steps: The recovery edge's steps, each a mapping arm -> ``{fn, args}``.
        margin: Threshold of the persistence trigger.
        window: Persistence window in ticks.
        calls: Every failure it was asked to repair, in order.
    """

    name: str
    monitor: str
    intent: str
    steps: Sequence[Mapping[str, Any]]
    margin: float = 0.0
    window: int = 3
    calls: list[UnanticipatedFailure] = field(default_factory=list)

    def __call__(self, graph: TaskGraph, failure: UnanticipatedFailure, frame: FeatureFrame) -> TaskGraph | None:
        """The graph plus the scripted branch on ``failure.edge``; None if the names are taken."""
        self.calls.append(failure)
        entry_id = f"{failure.edge}_r_{self.name}"
        try:
            failed = graph.edge(failure.edge)
        except UnknownEdgeError:
            return None
        if entry_id in {e.id for e in graph.edges} or self.name in {f.name for f in failed.failures}:
            return None
        repaired = graph.model_copy(deep=True)
        repaired.edge(failure.edge).failures.append(
            FailureMode(
                name=self.name,
                monitor=self.monitor,
                margin=self.margin,
                window=self.window,
                intent=self.intent,
                recovery=entry_id,
            )
        )
        repaired.edges.append(
            Edge.model_validate(
                {
                    "id": entry_id,
                    "source": failure.context,
                    "target": failed.target,
                    "kind": "recovery",
                    "actions": [dict(step) for step in self.steps],
                }
            )
        )
        return repaired
