"""The recovery map of paper Eq. 13: (active edge, fired mode) -> recovery entry edge.

Built once before execution, so a switch at run time is a dictionary lookup:
no reasoner call, no re-planning.
"""

from __future__ import annotations

from agentchord.graph.models import Edge, TaskGraph
from agentchord.graph.progress import cost_to_go


class RecoveryMap:
    """Where to go when a failure mode fires, and how to merge back.

    Args:
        graph: The (filtered) recovery-augmented graph.
    """

    def __init__(self, graph: TaskGraph) -> None:
        self.graph = graph
        self.cost_to_go = cost_to_go(graph)
        self._entries = {(edge.id, f.name): f.recovery for edge in graph.edges for f in edge.failures}
        self._alternatives: dict[str, list[Edge]] = {}
        for edge in graph.edges:
            if edge.alternative_to is not None:
                self._alternatives.setdefault(edge.alternative_to, []).append(edge)

    def entry(self, edge_id: str, failure_name: str) -> Edge | None:
        """The recovery entry edge for a fired mode (None if none was compiled)."""
        edge_id = self._entries.get((edge_id, failure_name))
        return None if edge_id is None else self.graph.edge(edge_id)

    def candidates(self, edge_id: str, failure_name: str) -> list[Edge]:
        """The entry edge for a fired mode followed by its alternatives, in the order they are tried."""
        entry = self.entry(edge_id, failure_name)
        return [] if entry is None else [entry, *self._alternatives.get(entry.id, [])]

    def exit_edges(self, node_id: str) -> list[Edge]:
        """Recovery exit edges leaving a recovery node, best merge candidate first.

        The executor takes the admissible candidate with the least cost-to-go
        (DESIGN section 3): ties keep the file's order.
        """
        entries = set(self._entries.values()) | {e.id for alts in self._alternatives.values() for e in alts}
        # Entry edges (a failure's first response) and self-loops are not ways forward.
        exits = [e for e in self.graph.out_edges(node_id) if e.kind == "recovery" and e.id not in entries and e.target != node_id]
        return sorted(exits, key=lambda e: self.cost_to_go.get(e.target, float("inf")))
