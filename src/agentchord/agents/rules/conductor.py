"""The offline conductor: ground the free keyframes of a graph in the scene (Sec. III-D, Eq. 9).

Placeholder until the sub-goal solver lands: returns the graph unchanged.
"""

from __future__ import annotations

from agentchord.agents.reasoner import Scene
from agentchord.graph.models import TaskGraph


class Conductor:
    """Solves free keyframes (``move_to_target`` poses, ``place`` spots)."""

    def conduct(self, graph: TaskGraph, scene: Scene) -> TaskGraph:
        return graph.model_copy(deep=True)
