"""The recovery-augmented task graph: models, files, checks, cost-to-go (Eq. 8), rendering."""

from agentchord.graph.exceptions import (
    GraphError,
    GraphFileError,
    NoPathError,
    RenderError,
    UnknownActionError,
    UnknownEdgeError,
    UnknownNodeError,
)
from agentchord.graph.loader import dump_graph, load_graph
from agentchord.graph.models import ActionCall, Edge, FailureMode, Node, Step, TaskGraph
from agentchord.graph.progress import (
    FilterResult,
    RecoveryBranch,
    RemovedBranch,
    augmented_digraph,
    cost_to_go,
    edge_cost,
    forward_filter,
    nominal_path,
    recovery_branches,
    recovery_reach,
)
from agentchord.graph.render import render, to_dot, to_mermaid
from agentchord.graph.validation import Problem, check_file, check_graph

__all__ = [
    "ActionCall",
    "Edge",
    "FailureMode",
    "FilterResult",
    "GraphError",
    "GraphFileError",
    "NoPathError",
    "Node",
    "Problem",
    "RecoveryBranch",
    "RemovedBranch",
    "RenderError",
    "Step",
    "TaskGraph",
    "UnknownActionError",
    "UnknownEdgeError",
    "UnknownNodeError",
    "augmented_digraph",
    "check_file",
    "check_graph",
    "cost_to_go",
    "dump_graph",
    "edge_cost",
    "forward_filter",
    "load_graph",
    "nominal_path",
    "recovery_branches",
    "recovery_reach",
    "render",
    "to_dot",
    "to_mermaid",
]
