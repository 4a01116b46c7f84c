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
    UnanticipatedFailure,
)
from agentchord.agents.scene import Region, Scene
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
        from agentchord.agents.rules import RulesReasoner

        return RulesReasoner(goal, watch_visibility=watch_visibility)
    if kind == "llm":
        from agentchord.agents.llm import LlmConfig, LlmReasoner

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
    start = time.perf_counter()
    nominal = reasoner.compose(ComposeRequest(instruction=instruction, scene=scene, task=task))
    composed = time.perf_counter() - start
    result = _augment(nominal, scene, reasoner, first)
    result.seconds = {"composer": composed, **result.seconds}
    return result


def compose_task(instruction: str, scene: Scene, reasoner: Reasoner, task: str = "") -> TaskGraph:
    """The composer alone: the nominal graph a pipelined plan starts the robot on.

    Raises:
        ReasonerError: No valid nominal graph (the refused replies travel with the error).
    """
    first = len(reasoner.calls)
    try:
        return reasoner.compose(ComposeRequest(instruction=instruction, scene=scene, task=task))
    except ReasonerError as error:
        error.calls = list(reasoner.calls[first:])
        raise


def augment_task(nominal: TaskGraph, scene: Scene, reasoner: Reasoner) -> PlanResult:
    """The arranger (then the forward-moving filter) and the conductor on a composed graph: the rest of
    a pipelined plan, asked while the robot moves.

    Raises:
        ReasonerError: An agent could not produce a valid graph.
    """
    first = len(reasoner.calls)
    try:
        return _augment(nominal, scene, reasoner, first)
    except ReasonerError as error:
        error.calls = list(reasoner.calls[first:])
        raise


def _augment(nominal: TaskGraph, scene: Scene, reasoner: Reasoner, first: int) -> PlanResult:
    seconds: dict[str, float] = {}
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


#: Distance (m) of a tool from its first-observation (home) position within which the arm is home.
HOME_TOLERANCE = 0.03


def _distance(a, b) -> float:
    return sum((float(x) - float(y)) ** 2 for x, y in zip(a, b, strict=True)) ** 0.5


@dataclass
class Replanner:
    """Plan the rest of a task from a mid-task observation: the re-planning baselines' planner.

    The same composer, arranger and conductor as the first plan, asked again with the
    current observation (something held, something fallen) and the goal predicates not yet
    achieved. What is achieved is told, not guessed: event predicates (a pour, a handover)
    that happened are dropped, as a re-planning LLM would read them from its history; a
    "put it down" with no place becomes "put it down where it was first seen". Destinations
    already reached are read from the observation by the planner itself.

    Attributes:
        reasoner_kind: ``rules`` or ``llm``.
        instruction: The task's instruction.
        goal: The goal spec the instruction states (grounded on the first observation).
        first: The first observation.
        regions: The task's named regions.
        task: The task's name.
        llm_options: Options for an LLM reasoner.
    """

    reasoner_kind: str
    instruction: str
    goal: GoalSpec
    first: Scene
    regions: list[Region] = field(default_factory=list)
    task: str = ""
    llm_options: dict = field(default_factory=dict)

    def remaining(self, achieved: set[int]) -> GoalSpec | None:
        """The goal spec left once the goals at indices ``achieved`` happened (None: nothing left)."""
        from agentchord.agents.rules.goals import Placed

        seen = {o.name: o for o in self.first.objects}
        goals = []
        for index, goal in enumerate(self.goal.goals):
            if index in achieved:
                continue
            if isinstance(goal, Placed) and goal.region is None and goal.at is None and goal.relative_to is None and goal.obj in seen:
                x, y = seen[goal.obj].pos[:2]
                goal = goal.model_copy(update={"at": (round(float(x), 4), round(float(y), 4))})
            goals.append(goal)
        if not goals:
            return None
        return GoalSpec(goals=goals, home=self.goal.home)

    def __call__(self, frame: FeatureFrame, achieved: set[int], descriptions: dict[str, str] | None = None) -> PlanResult | None:
        """The plan from ``frame`` for what is left (None when nothing is left).

        Raises:
            ReasonerError: No plan reaches what is left from here (the message says why).
        """
        remaining = self.remaining(achieved)
        if remaining is None:
            return None
        done = [g.model_dump(mode="json") for i, g in enumerate(self.goal.goals) if i in achieved]
        notes = ("Re-plan from this observation, taken in the middle of the task. Already achieved: "
                 f"{done}. Still to achieve, in order: {remaining.model_dump(mode='json')['goals']}.")
        scene = Scene.from_frame(frame, descriptions=descriptions, regions=self.regions, notes=notes)
        # Both arms were home at the first observation: an arm more than 3 cm from there is not.
        homes = {arm.name: arm.ee for arm in self.first.arms}
        scene = scene.model_copy(update={"arms": [
            arm.model_copy(update={"home": arm.name not in homes or _distance(arm.ee, homes[arm.name]) < HOME_TOLERANCE})
            for arm in scene.arms]})
        if self.reasoner_kind == "rules":
            from agentchord.agents.rules import facts

            state = facts.initial_state(scene, remaining)
            if facts.goal_facts(remaining, scene)[-1] <= state:
                return None  # what is left already holds in this observation
            reasoner = make_reasoner("rules", goal=remaining)
        else:
            reasoner = make_reasoner(self.reasoner_kind, **self.llm_options)
        return plan_task(self.instruction, scene, reasoner, task=self.task)
