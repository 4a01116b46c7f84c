"""Composer -> arranger -> conductor: an instruction and a scene become an executable graph.

Also the bridge from a reasoner to the executor's online repair (:class:`ReasonerRepairer`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

from agentchord.agents.exceptions import ReasonerConfigError, ReasonerError
from agentchord.agents.reasoner import (
    ArrangeRequest,
    ComposeRequest,
    ConductRequest,
    Reasoner,
    ReasonerCall,
    Region,
    Scene,
    UnanticipatedFailure,
)
from agentchord.agents.rules.goals import GoalSpec
from agentchord.features.frame import FeatureFrame
from agentchord.graph.models import TaskGraph
from agentchord.graph.progress import FilterResult, forward_filter

REASONERS = ("rules", "llm")


def make_reasoner(kind: str = "rules", *, goal: GoalSpec | None = None, watch_visibility: bool = False, **llm_options) -> Reasoner:
    """A reasoner by name: ``rules`` (offline) or ``llm`` (configured from flags or the environment).

    Raises:
        ReasonerConfigError: Unknown kind, or the LLM is not configured.
    """
    if kind == "rules":
        from agentchord.agents.rules import RulesReasoner  # noqa: PLC0415

        return RulesReasoner(goal, watch_visibility=watch_visibility)
    if kind == "llm":
        from agentchord.agents.llm import LlmConfig, LlmReasoner  # noqa: PLC0415

        return LlmReasoner(LlmConfig.from_env(**{k: v for k, v in llm_options.items() if v is not None}))
    raise ReasonerConfigError(f"unknown reasoner {kind!r} (choose from: {', '.join(REASONERS)})")


@dataclass
class PlanResult:
    """The output of the three agents.

    Attributes:
        graph: The executable augmented graph (conducted).
        nominal: The composer's nominal graph.
        filtered: What the forward-moving filter removed from the arranger's graph.
        calls: The reasoner calls made, in order.
        seconds: Wall time per agent.
    """

    graph: TaskGraph
    nominal: TaskGraph
    filtered: FilterResult
    calls: list[ReasonerCall] = field(default_factory=list)
    seconds: dict[str, float] = field(default_factory=dict)


def plan_task(instruction: str, scene: Scene, reasoner: Reasoner, task: str = "") -> PlanResult:
    """Run the composer, the arranger (then the forward-moving filter) and the conductor.

    Raises:
        ReasonerError: An agent could not produce a valid graph (the message says why).
    """
    first = len(reasoner.calls)
    try:
        return _plan(instruction, scene, reasoner, task, first)
    except ReasonerError as error:
        error.calls = list(reasoner.calls[first:])  # the refused replies travel with the error
        raise


def _plan(instruction: str, scene: Scene, reasoner: Reasoner, task: str, first: int) -> PlanResult:
    seconds: dict[str, float] = {}
    start = time.perf_counter()
    nominal = reasoner.compose(ComposeRequest(instruction=instruction, scene=scene, task=task))
    seconds["composer"] = time.perf_counter() - start
    start = time.perf_counter()
    arranged = reasoner.arrange(ArrangeRequest(graph=nominal, scene=scene))
    filtered = forward_filter(arranged)
    seconds["arranger"] = time.perf_counter() - start
    start = time.perf_counter()
    graph = reasoner.conduct(ConductRequest(graph=filtered.graph, scene=scene))
    seconds["conductor"] = time.perf_counter() - start
    return PlanResult(graph, nominal, filtered, list(reasoner.calls[first:]), seconds)


@dataclass
class ReasonerRepairer:
    """Online repair through a reasoner's arranger (the executor's :class:`~agentchord.execution.repair.Repairer`).

    Attributes:
        reasoner: Answers the arranger's repair request.
        regions: The task's named regions, for the current observation.
    """

    reasoner: Reasoner
    regions: list[Region] = field(default_factory=list)

    def __call__(self, graph: TaskGraph, failure: UnanticipatedFailure, frame: FeatureFrame) -> TaskGraph | None:
        """The graph with one new branch for ``failure``, or ``None`` when the reasoner has none."""
        scene = Scene.from_frame(frame, regions=self.regions)
        try:
            return self.reasoner.arrange(ArrangeRequest(graph=graph, scene=scene, failure=failure))
        except ReasonerError:
            return None
