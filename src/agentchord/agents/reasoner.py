"""The reasoner interface shared by the three agents: their requests, the protocol, the record of each call.

The scene the requests carry is :mod:`agentchord.agents.scene`; the checks of a reply, :mod:`agentchord.agents.checks`.

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
pass :func:`~agentchord.agents.checks.check_reply`: the semantic checks of ``graph check``
(:func:`~agentchord.graph.validation.check_graph`) plus what each agent must
leave unchanged. Each call appends a :class:`ReasonerCall` to the reasoner's
``calls``: the request, every attempt's raw reply, tokens, latency and errors,
serialisable to the episode trace.
"""

from __future__ import annotations

import time
from collections.abc import Iterable
from typing import Any, ClassVar, Literal, Protocol, runtime_checkable

from pydantic import BaseModel, ConfigDict, Field, computed_field

from agentchord.agents.scene import Scene
from agentchord.graph.models import TaskGraph

#: The three agents of the paper, in pipeline order.
Agent = Literal["composer", "arranger", "conductor"]
AGENTS: tuple[Agent, ...] = ("composer", "arranger", "conductor")

class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid")


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
