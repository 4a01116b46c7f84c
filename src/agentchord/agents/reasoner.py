"""The reasoner interface shared by the three agents, and the record of each call.

A :class:`Reasoner` answers the three agents of the paper (Sec. III-B to III-E):

- ``compose`` (task structuring agent): instruction + first observation -> the
  nominal :class:`~agentchord.graph.models.TaskGraph` (sub-goal nodes, transition
  edges, sub-goal and path constraints; no failure modes).
- ``arrange`` (recovery orchestration agent): nominal graph + scene -> the
  recovery-augmented graph (failure modes with monitors and intents, recovery
  nodes and edges, merge targets), the nominal part unchanged.
- ``conduct`` (execution compilation agent): augmented graph + scene -> the same
  graph with its parameters grounded in the scene (action arguments such as
  offsets and yaws, constraint tolerances, monitor margins and windows); its
  structure (ids, endpoints, kinds, failure names and recovery map) unchanged.
  Keyframes, edge programs and compiled monitors are then built from it without
  a reasoner.

Every reasoner (the offline ``rules`` one and the LLM one) returns graphs that
pass :func:`check_reply`: the semantic checks of ``graph check``
(:func:`~agentchord.graph.validation.check_graph`) plus what each agent must
leave unchanged. Each call appends a :class:`ReasonerCall` to the reasoner's
``calls``: the request, every attempt's raw reply, tokens, latency and errors,
serialisable to the episode trace.
"""

from __future__ import annotations

import time
from collections.abc import Iterable, Mapping
from typing import Any, ClassVar, Literal, Protocol, runtime_checkable

from pydantic import BaseModel, ConfigDict, Field, computed_field

from agentchord.features.frame import UP, FeatureFrame
from agentchord.graph.models import TaskGraph
from agentchord.graph.validation import Problem, check_graph

#: The three agents of the paper, in pipeline order.
Agent = Literal["composer", "arranger", "conductor"]
AGENTS: tuple[Agent, ...] = ("composer", "arranger", "conductor")

Vec3 = tuple[float, float, float]
Vec4 = tuple[float, float, float, float]


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid")


# --- the first observation ---------------------------------------------------------------


class SceneObject(_Model):
    """One object of the scene as the reasoner sees it (world frame, metres).

    Attributes:
        name: The name graphs use for it (``bottle``).
        description: Category, colour, material, in words (optional).
        pos: Centre.
        quat: Orientation (w, x, y, z).
        axis: Unit principal axis (bottom to top for an upright object).
        extent: Full size along the object's principal axes.
    """

    name: str
    description: str = ""
    pos: Vec3
    quat: Vec4 = (1.0, 0.0, 0.0, 0.0)
    axis: Vec3 = (0.0, 0.0, 1.0)
    extent: Vec3


class ArmState(_Model):
    """The measurable state of one arm at the first observation.

    Attributes:
        name: ``left`` or ``right``.
        ee: Tool centre point.
        width: Gripper opening (m).
        closed: Whether the gripper is commanded closed.
        holding: Name of the object in the gripper, if any.
        home: Whether the arm is at its home pose (false in an observation taken mid-task
            with the arm elsewhere: a plan that ends at home sends it back).
    """

    name: str
    ee: Vec3
    width: float = 0.0
    closed: bool = False
    holding: str | None = None
    home: bool = True


class Region(_Model):
    """A named region of the table (a target area), a disc.

    Attributes:
        name: How instructions name it (``target``, ``forward``).
        description: More words that name it.
        center: Centre (x, y), metres.
        radius: Radius, metres.
    """

    name: str
    description: str = ""
    center: tuple[float, float]
    radius: float = Field(0.04, gt=0.0)


class Scene(_Model):
    """The first observation given to the agents: objects with poses and sizes, and the arms.

    Attributes:
        objects: Scene objects.
        arms: Arm states (may be empty when unknown).
        regions: Named regions of the table.
        notes: Anything else worth saying (table height, workspace bounds, in words).
    """

    objects: list[SceneObject]
    arms: list[ArmState] = Field(default_factory=list)
    regions: list[Region] = Field(default_factory=list)
    notes: str = ""

    @property
    def object_names(self) -> list[str]:
        """Names of the scene's objects, in order."""
        return [obj.name for obj in self.objects]

    @classmethod
    def from_frame(
        cls,
        frame: FeatureFrame,
        descriptions: Mapping[str, str] | None = None,
        notes: str = "",
        decimals: int = 4,
        regions: Iterable[Region] = (),
    ) -> Scene:
        """The scene seen in a feature frame (oracle or RGB-D), rounded for a prompt.

        Args:
            frame: The first frame of the episode.
            descriptions: Optional words per object name.
            notes: Free text passed on to the agents.
            regions: Named regions of the table.
            decimals: Rounding of every coordinate (4: 0.1 mm).
        """

        def r(values: Iterable[float]) -> Any:
            return tuple(round(float(v), decimals) for v in values)

        descriptions = descriptions or {}
        objects = [
            SceneObject(
                name=name,
                description=descriptions.get(name, ""),
                pos=r(feats.pos),
                quat=r(feats.quat),
                axis=r(feats.axis if feats.axis is not None else UP),
                extent=r(feats.extent),
            )
            for name, feats in frame.objects.items()
        ]
        arms = []
        for name, arm in frame.arms.items():
            held = [obj for (a, obj) in sorted(frame.holding) if a == name]
            arms.append(
                ArmState(
                    name=name,
                    ee=r(arm.ee),
                    width=round(float(arm.width), decimals),
                    closed=bool(arm.closed),
                    holding=held[0] if held else None,
                )
            )
        return cls(objects=objects, arms=arms, regions=list(regions), notes=notes)


# --- requests ----------------------------------------------------------------------------


class ComposeRequest(_Model):
    """Input of the task structuring agent (paper Eq. 2).

    Attributes:
        instruction: The manipulation instruction.
        scene: The first observation.
        task: A name for the task (becomes ``TaskGraph.task``); empty lets the reasoner name it.
    """

    agent: ClassVar[Agent] = "composer"

    instruction: str
    scene: Scene
    task: str = ""


class UnanticipatedFailure(_Model):
    """An online-repair request: a failure that no monitor anticipated (DESIGN section 4).

    Attributes:
        edge: Id of the edge that ended with its target's constraints violated.
        context: The failure context, the last completed sub-goal (node id).
        observation: What is wrong, in words (e.g. the violated constraints and their values).
    """

    edge: str
    context: str
    observation: str = ""


class ArrangeRequest(_Model):
    """Input of the recovery orchestration agent (paper Eq. 4-8).

    Attributes:
        graph: The nominal graph (or, for an online repair, the current augmented graph).
        scene: The first (or, for an online repair, the current) observation.
        failure: Set for an online repair: add one branch for this failure, keep the rest.
    """

    agent: ClassVar[Agent] = "arranger"

    graph: TaskGraph
    scene: Scene
    failure: UnanticipatedFailure | None = None


class ConductRequest(_Model):
    """Input of the execution compilation agent (paper Sec. III-D).

    Attributes:
        graph: The recovery-augmented graph, after the forward-moving filter.
        scene: The first observation, to ground offsets and tolerances in the geometry.
    """

    agent: ClassVar[Agent] = "conductor"

    graph: TaskGraph
    scene: Scene


AgentRequest = ComposeRequest | ArrangeRequest | ConductRequest


# --- the record of a call ----------------------------------------------------------------


class ReasonerAttempt(_Model):
    """One reply within a call: the first answer or a repair.

    Attributes:
        reply: The raw text of the reply (``None`` if none came).
        finish_reason: Why the model stopped (``stop``, ``length``, ...), if reported.
        tokens_in: Prompt tokens, ``None`` when the endpoint did not report usage.
        tokens_out: Completion tokens, ``None`` when the endpoint did not report usage.
        latency_s: Wall time of the attempt, transport retries and back-off included.
        retries: Transport retries before the reply came.
        response_format: Structured-output mode of the request that answered
            (``json_schema``, ``json_object``, ``text``), or ``None`` for a local reasoner.
        transport_errors: What went wrong on the way (one line per failed request).
        problems: Why the reply was rejected; empty when it was accepted.
    """

    reply: str | None = None
    finish_reason: str | None = None
    tokens_in: int | None = None
    tokens_out: int | None = None
    latency_s: float = 0.0
    retries: int = 0
    response_format: str | None = None
    transport_errors: list[str] = Field(default_factory=list)
    problems: list[str] = Field(default_factory=list)


class ReasonerCall(_Model):
    """The record of one agent call: what was asked, every reply, what it cost.

    Attributes:
        agent: Which agent asked.
        reasoner: Which reasoner answered (``llm``, ``rules``).
        model: Model name, for an LLM.
        endpoint: Base URL, for an LLM.
        started_at: Unix time the call started.
        request: The request, as JSON (:meth:`pydantic.BaseModel.model_dump`).
        settings: The reasoner's settings that shaped the call (structured-output
            mode, temperature, token limit, repairs allowed, ...).
        messages: The chat conversation (system, user, assistant and repair
            messages), for an LLM; empty for a local reasoner.
        attempts: Every reply: the first answer, then the repairs.
        reply: The accepted graph as JSON; ``None`` when the call failed.
        error: Why the call failed; ``None`` when it succeeded.
        tokens_in: Prompt tokens over all attempts (unreported usage counts 0).
        tokens_out: Completion tokens over all attempts.
        latency_s: Wall time of the call; for an offline reasoner it may be a
            stated per-call latency instead, then ``latency_modelled`` is set.
        latency_modelled: Whether ``latency_s`` is modelled rather than measured.
    """

    # The dump carries the computed ok, repairs and errors: ignore them when a trace is read back.
    model_config = ConfigDict(extra="ignore")

    agent: Agent
    reasoner: str
    model: str | None = None
    endpoint: str | None = None
    started_at: float = Field(default_factory=time.time)
    request: dict[str, Any] = Field(default_factory=dict)
    settings: dict[str, Any] = Field(default_factory=dict)
    messages: list[dict[str, Any]] = Field(default_factory=list)
    attempts: list[ReasonerAttempt] = Field(default_factory=list)
    reply: dict[str, Any] | None = None
    error: str | None = None
    tokens_in: int = 0
    tokens_out: int = 0
    latency_s: float = 0.0
    latency_modelled: bool = False

    @computed_field  # type: ignore[prop-decorator]
    @property
    def ok(self) -> bool:
        """Whether the call produced an accepted graph."""
        return self.reply is not None and self.error is None

    @computed_field  # type: ignore[prop-decorator]
    @property
    def repairs(self) -> int:
        """Repair turns taken (attempts after the first)."""
        return max(0, len(self.attempts) - 1)

    @computed_field  # type: ignore[prop-decorator]
    @property
    def errors(self) -> list[str]:
        """Every transport error and rejected reply, in order, then the final error."""
        lines = []
        for index, attempt in enumerate(self.attempts, start=1):
            lines += [f"attempt {index}: {line}" for line in attempt.transport_errors]
            lines += [f"attempt {index}: {line}" for line in attempt.problems]
        if self.error:
            lines.append(self.error)
        return lines

    def add_usage(self) -> None:
        """Set ``tokens_in`` and ``tokens_out`` to the sums over the attempts."""
        self.tokens_in = sum(a.tokens_in or 0 for a in self.attempts)
        self.tokens_out = sum(a.tokens_out or 0 for a in self.attempts)

    def to_trace_event(self, *, messages: bool = True) -> dict[str, Any]:
        """The call as a JSON-ready mapping for ``Trace.add(tick, "reasoner_call", **event)``.

        Args:
            messages: Include the chat conversation (the system prompt is long).
        """
        return self.model_dump(mode="json", exclude=None if messages else {"messages"})


def total_usage(calls: Iterable[ReasonerCall]) -> dict[str, float]:
    """Totals over calls: ``calls``, ``failed``, ``attempts``, ``tokens_in``, ``tokens_out``, ``latency_s``."""
    calls = list(calls)
    return {
        "calls": len(calls),
        "failed": sum(not c.ok for c in calls),
        "attempts": sum(len(c.attempts) for c in calls),
        "tokens_in": sum(c.tokens_in for c in calls),
        "tokens_out": sum(c.tokens_out for c in calls),
        "latency_s": sum(c.latency_s for c in calls),
    }


# --- the protocol ------------------------------------------------------------------------


@runtime_checkable
class Reasoner(Protocol):
    """What the composer, arranger and conductor ask of a reasoner.

    Attributes:
        name: Short name recorded in each :class:`ReasonerCall` (``rules``, ``llm``).
        calls: Every call made so far, failed ones included, in order.
    """

    name: str
    calls: list[ReasonerCall]

    def compose(self, request: ComposeRequest) -> TaskGraph:
        """The nominal task graph for an instruction and a first observation.

        Raises:
            ReasonerError: No valid graph could be produced.
        """
        ...

    def arrange(self, request: ArrangeRequest) -> TaskGraph:
        """The graph augmented with failure modes, monitors and recovery branches.

        Raises:
            ReasonerError: No valid graph could be produced.
        """
        ...

    def conduct(self, request: ConductRequest) -> TaskGraph:
        """The graph with its parameters grounded in the scene, its structure unchanged.

        Raises:
            ReasonerError: No valid graph could be produced.
        """
        ...


# --- checks of a reply -------------------------------------------------------------------


def check_reply(request: AgentRequest, graph: TaskGraph) -> list[Problem]:
    """Every problem of ``graph`` as an answer to ``request``; empty means accepted.

    The checks of ``graph check`` (:func:`check_graph`), then the agent's own:

    - composer: a nominal graph only (no failure modes, no recovery nodes or
      edges); every graph object is a scene object.
    - arranger: start, goal and every nominal node and edge of the input kept
      (edge endpoints and actions unchanged); everything added is ``kind:
      recovery``; every graph object is a scene object.
    - conductor: the input's structure kept: the same node ids and kinds, the
      same edges with the same endpoints and kinds, the same failure modes per
      edge with the same recovery entry edges.

    Args:
        request: What the agent was asked.
        graph: The graph it answered (schema-valid).
    """
    problems = check_graph(graph)
    if isinstance(request, ComposeRequest):
        problems += _check_nominal_only(graph)
        problems += _check_scene_objects(graph, request.scene)
    elif isinstance(request, ArrangeRequest):
        problems += _check_keeps_nominal(request.graph, graph)
        problems += _check_scene_objects(graph, request.scene)
    elif isinstance(request, ConductRequest):
        problems += _check_keeps_structure(request.graph, graph)
    else:  # pragma: no cover - guarded by the type
        raise TypeError(f"expected a ComposeRequest, ArrangeRequest or ConductRequest, got {type(request).__name__}")
    return problems


def _check_nominal_only(graph: TaskGraph) -> list[Problem]:
    why = "the composer writes the nominal graph only; failure modes and recovery branches are the arranger's"
    problems = [Problem(f"nodes[{i}].kind", why) for i, n in enumerate(graph.nodes) if n.is_recovery]
    for i, edge in enumerate(graph.edges):
        if edge.is_recovery:
            problems.append(Problem(f"edges[{i}].kind", why))
        if edge.failures:
            problems.append(Problem(f"edges[{i}].failures", why))
    return problems


def _check_scene_objects(graph: TaskGraph, scene: Scene) -> list[Problem]:
    names = scene.object_names
    if not names:
        return []
    return [
        Problem(f"objects[{i}]", f"{name!r} is not a scene object; the scene has {', '.join(names)}")
        for i, name in enumerate(graph.objects)
        if name not in names
    ]


def _check_keeps_nominal(before: TaskGraph, after: TaskGraph) -> list[Problem]:
    problems = _check_ends(before, after)
    nodes = {n.id: n for n in after.nodes}
    for node in before.nodes:
        if node.is_recovery:
            continue
        if node.id not in nodes:
            message = f"nominal node {node.id!r} of the input is missing; keep every nominal node"
            problems.append(Problem("nodes", message))
        elif nodes[node.id].is_recovery:
            problems.append(Problem("nodes", f"nominal node {node.id!r} of the input became kind: recovery"))
    edges = {e.id: e for e in after.edges}
    for edge in before.nominal_edges():
        new = edges.get(edge.id)
        if new is None:
            message = f"nominal edge {edge.id!r} of the input is missing; keep every nominal edge"
            problems.append(Problem("edges", message))
            continue
        i = after.edges.index(new)
        if new.is_recovery:
            problems.append(Problem(f"edges[{i}].kind", f"nominal edge {edge.id!r} of the input became kind: recovery"))
        if (new.source, new.target) != (edge.source, edge.target):
            problems.append(
                Problem(
                    f"edges[{i}]",
                    f"nominal edge {edge.id!r} must keep {edge.source!r} -> {edge.target!r}, "
                    f"got {new.source!r} -> {new.target!r}",
                )
            )
        if new.actions != edge.actions:
            problems.append(Problem(f"edges[{i}].actions", f"nominal edge {edge.id!r} must keep its actions"))
    old_nodes = {n.id for n in before.nodes}
    old_edges = {e.id for e in before.edges}
    problems += [
        Problem(f"nodes[{i}].kind", f"node {n.id!r} is new: nodes the arranger adds are kind: recovery")
        for i, n in enumerate(after.nodes)
        if n.id not in old_nodes and not n.is_recovery
    ]
    problems += [
        Problem(f"edges[{i}].kind", f"edge {e.id!r} is new: edges the arranger adds are kind: recovery")
        for i, e in enumerate(after.edges)
        if e.id not in old_edges and not e.is_recovery
    ]
    return problems


def _check_keeps_structure(before: TaskGraph, after: TaskGraph) -> list[Problem]:
    problems = _check_ends(before, after)
    old_nodes = {n.id: n.kind for n in before.nodes}
    new_nodes = {n.id: n.kind for n in after.nodes}
    if old_nodes != new_nodes:
        missing = sorted(old_nodes.keys() - new_nodes.keys())
        added = sorted(new_nodes.keys() - old_nodes.keys())
        changed = sorted(k for k in old_nodes.keys() & new_nodes.keys() if old_nodes[k] != new_nodes[k])
        groups = (("missing", missing), ("added", added), ("kind changed", changed))
        detail = "; ".join(f"{what}: {', '.join(ids)}" for what, ids in groups if ids)
        problems.append(Problem("nodes", f"the conductor must keep the nodes of its input ({detail})"))
    old_edges = {e.id: e for e in before.edges}
    new_ids = {e.id for e in after.edges}
    missing_edges = [e for e in before.edges if e.id not in new_ids]
    if missing_edges:
        ids = ", ".join(e.id for e in missing_edges)
        problems.append(Problem("edges", f"the conductor must keep every edge of its input (missing: {ids})"))
    for i, edge in enumerate(after.edges):
        old = old_edges.get(edge.id)
        if old is None:
            problems.append(Problem(f"edges[{i}].id", f"edge {edge.id!r} is new; the conductor must not add edges"))
            continue
        if (edge.source, edge.target, edge.kind) != (old.source, old.target, old.kind):
            problems.append(
                Problem(
                    f"edges[{i}]",
                    f"edge {edge.id!r} must keep {old.source!r} -> {old.target!r} ({old.kind}), "
                    f"got {edge.source!r} -> {edge.target!r} ({edge.kind})",
                )
            )
        old_map = {f.name: f.recovery for f in old.failures}
        new_map = {f.name: f.recovery for f in edge.failures}
        if old_map != new_map:
            problems.append(
                Problem(
                    f"edges[{i}].failures",
                    f"edge {edge.id!r} must keep its failure modes and their recovery edges "
                    f"({_mapping(old_map)}), got ({_mapping(new_map)})",
                )
            )
    return problems


def _check_ends(before: TaskGraph, after: TaskGraph) -> list[Problem]:
    return [
        Problem(field, f"must stay {getattr(before, field)!r}, got {getattr(after, field)!r}")
        for field in ("start", "goal")
        if getattr(before, field) != getattr(after, field)
    ]


def _mapping(mapping: Mapping[str, str]) -> str:
    return ", ".join(f"{name} -> {entry}" for name, entry in mapping.items()) or "none"
