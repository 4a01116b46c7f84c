"""Inner Monologue, DoReMi, ReKep and Code-as-Monitor as recovery strategies of one executor.

Each answers the executor's questions (:class:`~agentchord.execution.strategies.RecoveryStrategy`):
what it detects every tick and when an edge ends, and what it does on a detection. The
graph they run is the same as AgentChord's; they use its nominal chain (sub-goal nodes and
their constraints, edges and their path constraints) and, for Code-as-Monitor, its compiled
monitors, never its recovery branches. The reasoning each call stands for is charged by
:meth:`~agentchord.execution.executor.Executor.charge` (the latency model of
:mod:`agentchord.execution.reasoning`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from agentchord.agents.exceptions import ReasonerError
from agentchord.agents.rules.arm_switch import arm_switch_alternative
from agentchord.agents.rules.knowledge import is_cloth_corner
from agentchord.execution.baselines.progress import GoalEvents
from agentchord.execution.baselines.replies import composer_call, next_step_call, stages_call, subgoal_calls, vqa_call
from agentchord.execution.baselines.vqa import SimulatedVqa
from agentchord.execution.edge_program import EdgeProgram
from agentchord.execution.reasoning import ModelledCall, ReasoningConfig, charge_calls
from agentchord.execution.strategies import RecoveryStrategy
from agentchord.expr import Vocabulary, compile_expr
from agentchord.graph.models import FailureMode, TaskGraph
from agentchord.graph.progress import nominal_path
from agentchord.monitor import Detection

if TYPE_CHECKING:
    from agentchord.agents.pipeline import Replanner
    from agentchord.execution.context import ExecutionContext as Executor
    from agentchord.features.frame import FeatureFrame

#: ReKep's ``constraint_tolerance``: a path constraint's cost above it is a violation.
REKEP_TOLERANCE = 0.10


def _failure(name: str, intent: str) -> FailureMode:
    # model_validate, not FailureMode(...): mypy takes the positional Field defaults (margin, window) for required.
    return FailureMode.model_validate({"name": name, "monitor": "1", "intent": intent, "recovery": intent})


VQA_NO = _failure("vqa_failure", "replan")
SKILL_FAILED = _failure("skill_failed", "replan")
CONSTRAINT_VIOLATED = _failure("constraint_violated", "replan")
PATH_VIOLATED = _failure("path_constraint_violated", "backtrack")


def _same(expr: str) -> str:
    return " ".join(expr.split())


@dataclass
class BaselineContext:
    """What a baseline needs beyond the graph, per episode.

    Attributes:
        seed: The episode's seed (the VQA's errors).
        replanner: Plans the rest of the task from the current observation (None: no re-planning).
        events: The event goals achieved so far (ground truth), told to the re-planner.
        descriptions: Object descriptions, for the re-planner's observation.
    """

    seed: int = 0
    replanner: Replanner | None = None
    events: GoalEvents | None = None
    descriptions: dict[str, str] = field(default_factory=dict)


class BaselineStrategy(RecoveryStrategy):
    """Shared by the four: step constraints, VQA queries, re-planning, charges.

    Args:
        reasoning: Latencies, VQA error rates, DoReMi's period.
        context: Per-episode re-planner, progress and seed.
    """

    reasoning: ReasoningConfig  # never None here (the default config when none is given)

    def __init__(self, reasoning: ReasoningConfig | None = None, context: BaselineContext | None = None) -> None:
        self.reasoning = reasoning or ReasoningConfig()
        self.context = context or BaselineContext()
        self.vqa = SimulatedVqa(self.context.seed, self.reasoning.vqa_miss, self.reasoning.vqa_false_alarm)
        # Step constraints compiled for the graph run now, by edge id. The graph itself is kept: a
        # re-plan's graph reuses edge ids, and a cache keyed by id(graph) could find a collected
        # graph's entries under a new graph at the same address (an episode then depends on memory).
        self._compiled_graph: TaskGraph | None = None
        self._compiled: dict[str, list] = {}

    # -- charges ---------------------------------------------------------------------------
    def planning_calls(self, graph: TaskGraph) -> list[ModelledCall]:
        """The calls before the first tick: a whole plan (the composer's nominal graph)."""
        return [composer_call(graph)]

    def replan_calls(self, graph: TaskGraph) -> list[ModelledCall]:
        """The calls of one re-plan that wrote ``graph``: a whole plan again."""
        return [composer_call(graph)]

    def _charge(self, executor: Executor, calls: list[ModelledCall]) -> None:
        for call in calls:
            executor.charge(call.kind, call.agent, self.reasoning.latency.price(call), tokens=call.tokens)

    def ask_vqa(self, executor: Executor, constraints: list) -> bool:
        """One VQA query (charged): do ``constraints`` hold now?"""
        self._charge(executor, [vqa_call()])
        return self.vqa.holds(constraints, executor.frame)

    # -- the step's constraints ------------------------------------------------------------
    def step_constraints(self, executor: Executor, edge_id: str) -> list:
        """What must hold while an edge runs: its path constraints and the constraints its
        source and target share (what is held stays held: ReKep's "still grasping" path
        constraint, DoReMi's step constraints). Compiled, cached per graph."""
        if self._compiled_graph is not executor.graph:
            self._compiled_graph, self._compiled = executor.graph, {}
        key = edge_id
        if key not in self._compiled:
            graph = executor.graph
            edge = graph.edge(edge_id)
            source = {_same(c) for c in graph.node(edge.source).constraints}
            shared = [c for c in graph.node(edge.target).constraints if _same(c) in source]
            sources = list(dict.fromkeys([*edge.path_constraints, *shared]))
            vocabulary = Vocabulary(frozenset(graph.objects))
            self._compiled[key] = [compile_expr(c, vocabulary) for c in sources]
        return self._compiled[key]

    def _known_edge(self, executor: Executor, program: EdgeProgram) -> bool:
        return program.edge_id in {e.id for e in executor.graph.edges}

    # -- detection -------------------------------------------------------------------------
    def watch(self, executor: Executor, frame: FeatureFrame) -> Detection | None:
        if self.context.events is not None:
            self.context.events.observe(frame)
        return self.detect(executor, frame)

    def detect(self, executor: Executor, frame: FeatureFrame) -> Detection | None:
        """The strategy's own per-tick detection."""
        return None

    def on_program_failure(self, executor: Executor, program: EdgeProgram) -> Detection | None:
        # The skill says it failed: that is feedback the method reads (no query needed).
        tick = executor.world.tick
        return Detection(program.edge_id, SKILL_FAILED, tick, tick, 1.0)

    # -- re-planning -----------------------------------------------------------------------
    def recover(self, executor: Executor, detection: Detection) -> list[EdgeProgram]:
        return self.replan(executor, detection)

    def replan(self, executor: Executor, detection: Detection) -> list[EdgeProgram]:
        """Plan the rest from the current observation and run its first edge (empty: give up)."""
        replanner = self.context.replanner
        if replanner is None:
            executor.trace.add(executor.world.tick, "replan", ok=False, reason="no re-planner")
            return []
        if executor.replans >= self.reasoning.max_replans:
            executor.trace.add(executor.world.tick, "replan", ok=False, reason=f"re-plan budget {self.reasoning.max_replans} spent")
            return []
        achieved = set(self.context.events.achieved) if self.context.events is not None else set()
        started = time.perf_counter()
        try:
            planned = replanner(executor.frame, achieved, self.context.descriptions)
        except ReasonerError as error:
            wall = time.perf_counter() - started
            # A failed re-plan wrote about as much as a plan of what was there.
            charge_calls(executor, self.reasoning, self.replan_calls(executor.graph), getattr(error, "calls", []) or [], wall)
            executor.trace.add(executor.world.tick, "replan", ok=False, reason=str(error), problems=list(getattr(error, "problems", []) or []))
            return []
        wall = time.perf_counter() - started
        written = self.replan_calls(planned.graph) if planned is not None else [ModelledCall("composer", "plan", 8, part="nothing left")]
        charge_calls(executor, self.reasoning, written, planned.calls if planned else [], wall)
        goal = executor.graph.goal
        if planned is None:
            # Every goal is achieved: nothing to plan, the episode is judged now.
            executor.trace.add(executor.world.tick, "replan", ok=True, edges=[], achieved=sorted(achieved), failure=detection.failure.name)
            return [EdgeProgram("replan_nothing_left", goal, [], kind="nominal")]
        executor.adopt(planned.graph)
        first = executor.nominal_next.get(executor.graph.start)
        executor.trace.add(executor.world.tick, "replan", ok=True, edges=nominal_path(executor.graph), achieved=sorted(achieved),
                           failure=detection.failure.name)
        if first is None:
            return [EdgeProgram("replan_nothing_left", executor.graph.goal, [], kind="nominal")]
        entry = executor.graph.edge(first)
        # The planner's arm may not reach where the object lies now: the project's arm-switch rule
        # gives the other arm's way (it takes the object and sets it down within reach); the
        # executor binds the first the arms can make, as it does for AgentChord's recoveries.
        rigid = [name for name in executor.graph.objects if not is_cloth_corner(name)]
        alternative = arm_switch_alternative(entry, rigid)
        return [EdgeProgram.from_edge(edge) for edge in (entry, alternative) if edge is not None]


class _SubgoalVqa(BaselineStrategy):
    """A VQA success query when an edge ends; the planner is called again for the next step."""

    uses_monitors = False

    def at_subgoal(self, executor: Executor, program: EdgeProgram) -> Detection | None:
        if not self._known_edge(executor, program):
            return None
        tick = executor.world.tick
        if not self.ask_vqa(executor, executor.constraints[program.target]):
            return Detection(program.edge_id, VQA_NO, tick, tick, 1.0)
        if program.target != executor.graph.goal:
            # The next step is asked of the planner with this feedback in its context: from a
            # state where the sub-goal holds its answer is the plan's next edge (charged, not re-run).
            following = executor.nominal_next.get(program.target)
            if following is not None:
                self._charge(executor, [next_step_call(executor.graph, following)])
        return None


class InnerMonologueStrategy(_SubgoalVqa):
    """Inner Monologue (Huang et al., CoRL 2022): success detection after each skill, feedback into
    the planner's context, re-plan from the current state on a failure; nothing during motion."""

    name = "inner-monologue"


class DoReMiStrategy(_SubgoalVqa):
    """DoReMi (Guo et al., IROS 2024): the planner writes each step's constraints; a VQA model
    checks them every ``doremi_every`` ticks of motion (and at the step's end); a violation halts
    the skill at once and calls the planner to re-plan."""

    name = "doremi"

    def __init__(self, reasoning: ReasoningConfig | None = None, context: BaselineContext | None = None) -> None:
        super().__init__(reasoning, context)
        self._ticks = 0

    def detect(self, executor: Executor, frame: FeatureFrame) -> Detection | None:
        program = executor.program
        if program is None or not self._known_edge(executor, program):
            return None
        self._ticks += 1
        if self._ticks % self.reasoning.doremi_every:
            return None
        constraints = self.step_constraints(executor, program.edge_id)
        if not constraints:
            return None  # nothing to ask about this step
        if self.ask_vqa(executor, constraints):
            return None
        tick = executor.world.tick
        return Detection(program.edge_id, VQA_NO, tick, tick, 1.0)


class ReKepStrategy(BaselineStrategy):
    """ReKep (Huang et al., CoRL 2024; huangwl18/ReKep ``main.py``): each stage's path constraints
    every tick from the second stage on; on a cost above 0.10, back to the latest earlier stage
    whose path constraints all hold or that has none (stage 1 if none does), re-run from there
    from the current state. One planning call at the start; no reasoner afterwards."""

    name = "rekep"
    uses_monitors = False

    def planning_calls(self, graph: TaskGraph) -> list[ModelledCall]:
        """ReKep's one call: every stage's constraints."""
        return [stages_call(graph)]

    def _stage(self, executor: Executor, edge_id: str) -> tuple[list[str], int]:
        path = nominal_path(executor.graph)
        return path, path.index(edge_id) if edge_id in path else -1

    def detect(self, executor: Executor, frame: FeatureFrame) -> Detection | None:
        program = executor.program
        if program is None:
            return None
        _, stage = self._stage(executor, program.edge_id)
        if stage < 1:  # the first stage (and anything off the chain) is not checked
            return None
        costs = [c.scalar(frame) for c in self.step_constraints(executor, program.edge_id)]
        worst = max(costs, default=0.0)
        if worst <= REKEP_TOLERANCE:
            return None
        tick = executor.world.tick
        return Detection(program.edge_id, PATH_VIOLATED, tick, tick, worst)

    def recover(self, executor: Executor, detection: Detection) -> list[EdgeProgram]:
        path, stage = self._stage(executor, detection.edge_id)
        if stage < 0:
            return []
        target = 0
        if detection.failure is SKILL_FAILED:
            target = stage  # the stage's own skill failed: solve it again from here
        else:
            for earlier in range(stage - 1, -1, -1):
                constraints = self.step_constraints(executor, path[earlier])
                if all(c.scalar(executor.frame) <= REKEP_TOLERANCE for c in constraints):
                    target = earlier
                    break
        edge = executor.graph.edge(path[target])
        executor.node = edge.source
        executor.trace.add(executor.world.tick, "backtrack", from_stage=stage + 1, to_stage=target + 1, edge=edge.id)
        return [EdgeProgram.from_edge(edge)]


class CodeAsMonitorStrategy(BaselineStrategy):
    """Code-as-Monitor (Zhou et al., CVPR 2025): at each sub-goal's start the VLM writes the
    sub-goal's constraints and the monitor code (two calls); the compiled monitors run every tick
    and the completion constraints are checked when the sub-goal ends; a violation halts the policy
    and the reason goes back to the generator, which re-plans from the current state."""

    name = "code-as-monitor"
    uses_monitors = True

    def planning_calls(self, graph: TaskGraph) -> list[ModelledCall]:
        """The first sub-goal's constraints and monitor code."""
        path = nominal_path(graph)
        return subgoal_calls(graph, path[0] if path else None)

    def replan_calls(self, graph: TaskGraph) -> list[ModelledCall]:
        """A re-plan is the next sub-goal written again: its constraints and monitor code."""
        return self.planning_calls(graph)

    def at_subgoal(self, executor: Executor, program: EdgeProgram) -> Detection | None:
        if not self._known_edge(executor, program):
            return None
        tick = executor.world.tick
        if not executor.constraints_hold(program.target):
            return Detection(program.edge_id, CONSTRAINT_VIOLATED, tick, tick, 1.0)
        if program.target != executor.graph.goal:
            # The next sub-goal: the generator and the monitor writer are called again.
            self._charge(executor, subgoal_calls(executor.graph, executor.nominal_next.get(program.target)))
        return None


BASELINES: dict[str, type[BaselineStrategy]] = {
    s.name: s for s in (InnerMonologueStrategy, DoReMiStrategy, ReKepStrategy, CodeAsMonitorStrategy)
}
