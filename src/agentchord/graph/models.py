"""Pydantic models of the recovery-augmented task graph (DESIGN section 3).

The field names are the on-disk contract: extend, don't rename. Every model
forbids unknown fields so that a typo in a graph file is an error, not a
silently ignored key. The models check types and local ranges only; relations
between fields (ids, reachability, action arguments, expressions) are checked
by :func:`agentchord.graph.validation.check_graph`.
"""

from __future__ import annotations

import unicodedata

from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field, SerializerFunctionWrapHandler, field_serializer, field_validator

from agentchord.expr.names import ObjectName
from agentchord.graph.exceptions import UnknownEdgeError, UnknownNodeError
from agentchord.guard.numbers import MAX_MAGNITUDE, check_finite

Kind = Literal["nominal", "recovery"]


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid")


class ActionCall(_Model):
    """One atomic action call of one arm.

    Attributes:
        fn: Name of an action in :data:`agentchord.actions.catalog.ACTIONS`.
        args: Keyword arguments, validated against that action's argument model.
    """

    fn: str
    args: dict[str, Any] = Field(default_factory=dict)

    @field_validator("args")
    @classmethod
    def _finite_args(cls, args: dict[str, Any]) -> dict[str, Any]:
        # NaN passes every range check; it must not reach a solver (guard.numbers says why).
        return check_finite(args, MAX_MAGNITUDE)


#: One step of an edge: arm name -> call, ``None`` for an idle arm. Both arms
#: present means they run synchronously; the step ends when both are done.
Step = dict[str, ActionCall | None]


class FailureMode(_Model):
    """An anticipated failure of an edge, its monitor and its recovery (Eq. 11-13).

    Attributes:
        name: Unique among the failure modes of its edge.
        monitor: Expression; > 0 means the failure is present.
        margin: Threshold delta of the persistence trigger (Eq. 12).
        window: Ticks tau the monitor must exceed the margin before firing.
        intent: What the recovery should achieve (e.g. ``regrasp``).
        recovery: Id of the recovery entry edge; it starts at the failure
            context, the source of the edge this mode belongs to.
    """

    name: str
    monitor: str
    margin: float = Field(0.0, allow_inf_nan=False)
    window: int = Field(3, ge=1)
    intent: str
    recovery: str


#: The longest id a graph may give a node or an edge (a figure's label, a trace's field, a log line).
MAX_ID_CHARS = 128


def _printable_id(value: str) -> str:
    """An id is a short line of text: no control character (newline, NUL), no lone surrogate."""
    if len(value) > MAX_ID_CHARS:
        raise ValueError(f"an id of {len(value):,} characters, more than {MAX_ID_CHARS}")
    bad = next((c for c in value if unicodedata.category(c) in ("Cc", "Cs")), None)
    if bad is not None:
        raise ValueError(f"the id holds {'a lone surrogate' if unicodedata.category(bad) == 'Cs' else 'a control character'} "
                         f"(U+{ord(bad):04X}); an id is one line of text")
    return value


def _plain_text(value: str) -> str:
    """Free text (a semantic): any line breaks, but no NUL or other control character and no lone surrogate."""
    bad = next((c for c in value if unicodedata.category(c) in ("Cc", "Cs") and c not in "\n\t"), None)
    if bad is not None:
        raise ValueError(f"the text holds {'a lone surrogate' if unicodedata.category(bad) == 'Cs' else 'a control character'} "
                         f"(U+{ord(bad):04X})")
    return value


class Node(_Model):
    """A sub-goal (nominal) or a recovery state.

    Attributes:
        id: Unique node id.
        semantic: What holds at this node, in words.
        kind: ``nominal`` sub-goal or ``recovery`` node added by the arranger.
        constraints: Expressions that are all <= 0 when the sub-goal holds (Eq. 3).
    """

    id: str
    semantic: str
    kind: Kind = "nominal"
    constraints: list[str] = Field(default_factory=list)

    @field_validator("id")
    @classmethod
    def _check_id(cls, value: str) -> str:
        return _printable_id(value)

    @field_validator("semantic")
    @classmethod
    def _check_semantic(cls, value: str) -> str:
        return _plain_text(value)

    @property
    def is_recovery(self) -> bool:
        """Whether this is a recovery node."""
        return self.kind == "recovery"


class Edge(_Model):
    """A transition: the atomic actions that move the robot from ``source`` to ``target``.

    ``actions`` is either one step (a mapping arm -> call) or a list of steps
    run in sequence (e.g. a recovery "grasp bottle, then move to the cup").
    It is stored as a list of steps; a single step is written back as a
    mapping, so load -> dump -> load is the identity.

    Attributes:
        id: Unique edge id.
        source: Id of the node the edge leaves.
        target: Id of the node the edge reaches.
        kind: ``nominal`` or ``recovery``.
        actions: The steps, each a mapping arm -> call.
        path_constraints: Expressions that should stay <= 0 during the edge.
        failures: Anticipated failure modes, each mapped to a recovery entry edge.
        cost: Expected execution cost in control ticks; ``None`` means the sum
            over steps of the catalogue's ``expected_ticks`` (slowest arm per step).
        alternative_to: For a recovery entry edge's alternative: the id of that
            entry edge. Same source and target, another way there (typically the
            other arm). When a failure fires, the executor waits for the objects to
            come to rest, then binds the first of ``[entry, *alternatives]`` (file
            order) whose grasps the arms can make (reach model, confirmed by the IK).
    """

    id: str
    source: str
    target: str
    kind: Kind = "nominal"
    actions: list[Step] = Field(description="One step (arm -> call) or a list of steps run in sequence.")
    path_constraints: list[str] = Field(default_factory=list)
    failures: list[FailureMode] = Field(default_factory=list)
    cost: float | None = Field(None, ge=0.0, allow_inf_nan=False)
    alternative_to: str | None = None

    @field_validator("id", "source", "target")
    @classmethod
    def _check_ids(cls, value: str) -> str:
        return _printable_id(value)

    @field_validator("actions", mode="before", json_schema_input_type=Step | list[Step])
    @classmethod
    def _steps_from_compact(cls, value: Any) -> Any:
        # The compact single-step form is a mapping; store every edge as a list of steps.
        if isinstance(value, dict):
            return [value]
        if isinstance(value, (list, tuple)):
            return value
        raise ValueError(f"expected a mapping arm -> {{fn, args}} or a list of such steps, got {type(value).__name__}")

    @field_serializer("actions", mode="wrap")
    def _steps_to_compact(self, steps: list[Step], handler: SerializerFunctionWrapHandler) -> Any:
        dumped = handler(steps)
        return dumped[0] if len(dumped) == 1 else dumped

    @property
    def steps(self) -> list[Step]:
        """The steps run in sequence, each a mapping arm -> call (``None`` = idle)."""
        return self.actions

    @property
    def calls(self) -> list[tuple[str, ActionCall]]:
        """Every ``(arm, call)`` of the edge, in step order, idle arms left out."""
        return [(arm, call) for step in self.actions for arm, call in step.items() if call is not None]

    @property
    def is_recovery(self) -> bool:
        """Whether this is a recovery edge."""
        return self.kind == "recovery"


class Success(_Model):
    """What success means for a graph: what an episode that runs it is judged by.

    Attributes:
        judge: ``task``: the scene's built-in check of its task (the paper's tasks: the pour, the
            handover to its region ...); ``goal``: this graph's own goal, the goal spec below and
            the goal node's constraints (a planned graph whose instruction is not the task's own).
        goal_spec: The goal predicates the graph was planned for (a goal spec, as ``agentchord
            schema goal`` describes), judged on the end state; empty: the goal node's constraints only.
    """

    judge: Literal["task", "goal"] = "task"
    goal_spec: dict[str, Any] | None = None


class TaskGraph(_Model):
    """A recovery-augmented task graph.

    Attributes:
        task: Task name.
        instruction: The natural-language instruction the graph realises.
        start: Id of the start node.
        goal: Id of the goal node.
        objects: Names of the scene objects that actions and expressions may name.
        nodes: Sub-goal and recovery nodes.
        edges: Nominal and recovery edges.
        success: What an episode running it is judged by (default: the task's own check).
    """

    task: str
    instruction: str = ""
    start: str
    goal: str
    objects: list[ObjectName] = Field(default_factory=list)
    nodes: list[Node]
    edges: list[Edge]
    success: Success = Field(default_factory=Success)

    def node(self, node_id: str) -> Node:
        """The node with id ``node_id``.

        Raises:
            UnknownNodeError: No node has that id.
        """
        for node in self.nodes:
            if node.id == node_id:
                return node
        raise UnknownNodeError(node_id, [n.id for n in self.nodes])

    def edge(self, edge_id: str) -> Edge:
        """The edge with id ``edge_id``.

        Raises:
            UnknownEdgeError: No edge has that id.
        """
        for edge in self.edges:
            if edge.id == edge_id:
                return edge
        raise UnknownEdgeError(edge_id, [e.id for e in self.edges])

    def nominal_edges(self) -> list[Edge]:
        """Edges of kind ``nominal``, in file order."""
        return [e for e in self.edges if not e.is_recovery]

    def recovery_edges(self) -> list[Edge]:
        """Edges of kind ``recovery``, in file order."""
        return [e for e in self.edges if e.is_recovery]

    def recovery_nodes(self) -> list[Node]:
        """Nodes of kind ``recovery``, in file order."""
        return [n for n in self.nodes if n.is_recovery]

    def out_edges(self, node_id: str) -> list[Edge]:
        """Edges leaving ``node_id``, in file order."""
        return [e for e in self.edges if e.source == node_id]

    def failures(self) -> list[tuple[Edge, FailureMode]]:
        """Every ``(edge, failure mode)`` pair, in file order."""
        return [(edge, failure) for edge in self.edges for failure in edge.failures]

    def alternatives(self, entry_id: str) -> list[Edge]:
        """The alternatives of a recovery entry edge, in file order."""
        return [e for e in self.edges if e.alternative_to == entry_id]

    def failure_entries(self) -> dict[tuple[str, str], str]:
        """The recovery map (Eq. 13): ``(edge id, failure name) -> recovery entry edge id``."""
        return {(edge.id, failure.name): failure.recovery for edge, failure in self.failures()}
