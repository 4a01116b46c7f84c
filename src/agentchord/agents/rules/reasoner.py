"""The ``rules`` reasoner: offline, deterministic, no per-task code.

Composer: instruction (or a goal spec) -> goal predicates -> STRIPS plan over the scene's
skills -> nominal graph. Arranger: failure modes and forward-moving recovery branches
from the edges' atomic actions (and, for an online repair, one branch read from the
current observation). Conductor: grounds free keyframes in the scene with the sub-goal
solver. Every call is recorded as a :class:`ReasonerCall` and checked by
:func:`check_reply`, like an LLM's reply.
"""

from __future__ import annotations

import time
from collections.abc import Callable

from pydantic import ValidationError

from agentchord.agents.exceptions import InfeasibleGoalError, InvalidReplyError, ReasonerError
from agentchord.agents.checks import check_reply
from agentchord.agents.reasoner import (
    AgentRequest,
    ArrangeRequest,
    ComposeRequest,
    ConductRequest,
    ReasonerAttempt,
    ReasonerCall,
)
from agentchord.agents.rules.arranger import Arranger
from agentchord.agents.rules.composer import compose
from agentchord.agents.rules.conductor import Conductor
from agentchord.agents.rules.feasibility import goal_problems
from agentchord.agents.rules.goals import GoalSpec
from agentchord.agents.rules.instructions import ground_instruction
from agentchord.graph.models import Success, TaskGraph


class RulesReasoner:
    """The offline knowledge-based reasoner.

    Attributes:
        name: ``rules``.
        calls: Every call so far.
        goal: A goal spec that replaces reading the instruction (``--goal``).
        watch_visibility: The arranger adds lost-from-view monitors (RGB-D perception).
        conductor: Grounds keyframes (a :class:`Conductor`).
    """

    name = "rules"

    def __init__(self, goal: GoalSpec | None = None, *, watch_visibility: bool = False, conductor: Conductor | None = None) -> None:
        self.calls: list[ReasonerCall] = []
        self.goal = goal
        self.watch_visibility = watch_visibility
        self.conductor = conductor or Conductor()
        #: The goal spec of the last compose call (read from the instruction or given).
        self.last_goal: GoalSpec | None = None

    def compose(self, request: ComposeRequest) -> TaskGraph:
        """The nominal graph (raises :class:`InstructionNotGroundedError` or :class:`PlanningError`)."""

        def answer() -> TaskGraph:
            try:
                goal = self.goal or ground_instruction(request.instruction, request.scene)
            except ValidationError as error:  # the words make a contradictory goal (a stack cycle)
                raise InfeasibleGoalError([d["msg"].removeprefix("Value error, ") for d in error.errors()]) from None
            if problems := goal_problems(goal, request.scene):
                raise InfeasibleGoalError(problems)
            self.last_goal = goal
            graph = compose(goal, request.scene, request.task, request.instruction).graph
            # The composer states the goal it planned for, as the LLM's does: the episode is judged by it.
            return graph.model_copy(update={"success": Success(judge="goal", goal_spec=goal.model_dump(mode="json"))})

        return self._call(request, answer)

    def arrange(self, request: ArrangeRequest) -> TaskGraph:
        """The augmented graph; for an online repair, the graph plus one branch (or unchanged when none fits)."""
        arranger = Arranger(request.scene, watch_visibility=self.watch_visibility)

        def answer() -> TaskGraph:
            if request.failure is None:
                return arranger.arrange(request.graph)
            repaired = arranger.repair(request.graph, request.failure, request.scene)
            if repaired is None:
                raise ReasonerError(f"no rule explains the failure after edge {request.failure.edge!r}: {request.failure.observation}", agent="arranger")
            return repaired

        return self._call(request, answer)

    def conduct(self, request: ConductRequest) -> TaskGraph:
        """The graph with its free keyframes solved in the scene."""
        return self._call(request, lambda: self.conductor.conduct(request.graph, request.scene))

    def _call(self, request: AgentRequest, answer: Callable[[], TaskGraph]) -> TaskGraph:
        call = ReasonerCall(agent=request.agent, reasoner=self.name, request=request.model_dump(mode="json"))
        self.calls.append(call)
        start = time.perf_counter()
        try:
            graph = answer()
        except ReasonerError as exc:
            call.error = str(exc)
            call.latency_s = time.perf_counter() - start
            exc.call = call
            raise
        problems = [str(p) for p in check_reply(request, graph)]
        call.latency_s = time.perf_counter() - start
        call.attempts.append(ReasonerAttempt(latency_s=call.latency_s, problems=problems))
        if problems:
            call.error = "the rules produced an invalid graph (a bug: please report it with this trace)"
            raise InvalidReplyError(call.error, agent=request.agent, problems=problems, call=call)
        call.reply = graph.model_dump(mode="json")
        return graph
