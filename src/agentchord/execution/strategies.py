"""Recovery strategies compared on one executor (DESIGN section 6).

A strategy answers two questions: which edge follows a node, and what to run
when a monitor fires. AgentChord answers the second with a dictionary lookup
into the pre-compiled recovery map; the backtracking ablation returns to an
earlier node's keyframe and re-runs the nominal edges from there.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from agentchord.actions.library import Grasp
from agentchord.execution.edge_program import EdgeProgram, ReturnToKeyframe
from agentchord.execution.feasibility import first_grasps
from agentchord.execution.planning import composer_call, pipelined_schedule, sequential_calls
from agentchord.execution.reasoning import ModelledCall, ReasoningConfig, charge_calls
from agentchord.monitor import Detection

if TYPE_CHECKING:
    from agentchord.actions.base import ArmAction
    from agentchord.execution.context import ExecutionContext as Executor  # the executor as a strategy sees it
    from agentchord.features.frame import FeatureFrame
    from agentchord.graph.models import TaskGraph


class RecoveryStrategy:
    """Base: follow the nominal path; subclasses decide how to recover.

    Detection is the compiled monitors of the active edge when ``uses_monitors``; a strategy
    may add its own (``watch`` every tick of motion, ``at_subgoal`` when an edge ends) and
    take a skill's reported failure as a detection (``on_program_failure``).
    """

    name = "base"
    #: Whether the active edge's compiled monitors are armed (the baselines that ask a VQA model do not).
    uses_monitors = True
    #: Whether a lost hold that comes back as it was, while the recovery waits for what fell, lets the
    #: interrupted edge go on (``execution.binding``). Only where the recovery is a branch of the same
    #: graph: a re-plan has replaced the graph already, a backtrack does not wait.
    resumes_cleared_failures = False
    #: Whether a recovery whose merge node's constraints already hold once what fell is at rest is
    #: skipped (the executor goes on from the merge node). Only where the recovery is a branch of the
    #: same graph: a re-plan checks what is achieved itself, a backtrack returns regardless.
    merges_met_subgoals = False
    #: The latency model; None charges no reasoning (``run``, ``demo``: robot time only).
    reasoning: ReasoningConfig | None = None
    #: The reasoner calls that planned this episode's graph (none: a library graph, modelled).
    planned_calls: tuple = ()

    def planning_calls(self, graph: TaskGraph) -> list[ModelledCall]:
        """The calls that make ``graph`` before the first tick, each with what it writes: AgentChord's
        three agents one after the other (composer, arranger, conductor: the paper's order)."""
        return sequential_calls(graph)

    def begin(self, executor: Executor) -> None:
        """Called once before the first tick: charge the reasoning that made the plan (the robot waits for it)."""
        if self.reasoning is not None:
            charge_calls(executor, self.reasoning, self.planning_calls(executor.graph), self.planned_calls)

    def watch(self, executor: Executor, frame: FeatureFrame) -> Detection | None:
        """A failure this strategy detects at this tick of an edge program (None: nothing)."""
        return None

    def at_subgoal(self, executor: Executor, program: EdgeProgram) -> Detection | None:
        """A failure this strategy detects when ``program`` has just ended (None: go on)."""
        return None

    def on_program_failure(self, executor: Executor, program: EdgeProgram) -> Detection | None:
        """A skill reported failure: a detection to recover from, or None to end the episode.

        With compiled monitors, a nominal edge's grasp that failed (its object pushed or pulled away
        during the approach, now out of that arm's reach) is the failure the edge's monitor of that
        arm's hold anticipates: the object is not in the hand. That mode's detection switches to its
        pre-compiled recovery, whose alternatives include the other arm's; the monitor itself could
        not fire, since it reads the hold only once the hand has closed. A recovery's own failure is
        not taken so: it was bound where its arms could make it, and the same recovery would only
        run again.
        """
        action = program.failed_action
        monitors = executor.monitors.get(program.edge_id)
        if not self.uses_monitors or program.kind != "nominal" or monitors is None:
            return None
        if action is None or not isinstance(action, Grasp):
            return None
        obj = action.args.obj
        if executor.frame.is_holding(action.arm, obj):
            return None
        for monitor in monitors.watching(action.arm, obj):
            candidates = executor.recovery_map.candidates(program.edge_id, monitor.failure.name)
            if any(g.args.obj == obj for c in candidates for g in first_grasps(EdgeProgram.from_edge(c))):
                tick = executor.world.tick
                return Detection(program.edge_id, monitor.failure, tick, tick, monitor.expr.scalar(executor.frame))
        return None

    def next_edge(self, executor: Executor, node_id: str) -> str | None:
        """The nominal edge to run from a nominal node."""
        return executor.nominal_next.get(node_id)

    def recover(self, executor: Executor, detection: Detection) -> list[EdgeProgram]:
        """The programs to switch to when ``detection`` fired, in order of preference (empty: give up).

        The executor runs the first whose grasps are feasible once the objects are at rest.
        """
        raise NotImplementedError


class AgentChordStrategy(RecoveryStrategy):
    """Switch to the pre-compiled forward-moving recovery edge (Eq. 13): no re-planning.

    The entry edge and its alternatives (another arm's way there) are all candidates;
    the executor binds the first the arms can make. The plan is pipelined: the robot moves once
    the first edge is grounded, and the rest of the plan arrives while it moves
    (:mod:`agentchord.execution.planning`, :mod:`agentchord.execution.arrivals`).
    """

    name = "agentchord"
    resumes_cleared_failures = True
    merges_met_subgoals = True

    def begin(self, executor: Executor) -> None:
        if executor.background is not None:
            # An LLM composed the graph; its arranger and conductor answer while the robot moves.
            if self.reasoning is not None:
                charge_calls(executor, self.reasoning, [composer_call(executor.graph)], self.planned_calls)
            executor.follow_background()
            return
        if self.reasoning is None:
            return
        if any(call.reasoner != "rules" for call in self.planned_calls):
            # An LLM planned this graph, its calls one after the other: charged what they measured.
            super().begin(executor)
            return
        executor.compute_s += sum(call.latency_s for call in self.planned_calls)  # the offline agents' own work
        executor.follow_schedule(pipelined_schedule(executor.graph, self.reasoning.latency))

    def recover(self, executor: Executor, detection: Detection) -> list[EdgeProgram]:
        candidates = executor.recovery_map.candidates(detection.edge_id, detection.failure.name)
        return [EdgeProgram.from_edge(edge) for edge in candidates]


class SequentialAgentChordStrategy(AgentChordStrategy):
    """AgentChord with the paper's sequential plan: the robot waits for all three agents before it moves."""

    name = "agentchord-sequential"
    begin = RecoveryStrategy.begin


class BacktrackStrategy(RecoveryStrategy):
    """AgentChord-BT (paper Appendix E-C): back to the latest earlier nominal node that holds.

    The robot returns to that node's keyframe (joint-space), then the nominal
    edges run again from there.
    """

    name = "agentchord-bt"
    # The same three agents answer before the first tick, one after the other: the paper's
    # ablation keeps "the same task graph, feature extractors and compiled monitors", and the
    # monitors are the arranger's (its failure modes); only the recovery edges are not followed.

    def recover(self, executor: Executor, detection: Detection) -> list[EdgeProgram]:
        for node_id in reversed(executor.visited_nominal):
            if executor.constraints_hold(node_id):
                keyframe = executor.keyframes[node_id]
                actions: list[ArmAction] = [ReturnToKeyframe(arm, q, grip) for arm, (q, grip) in keyframe.items()]
                return [EdgeProgram(f"backtrack_to_{node_id}", node_id, [actions], kind="backtrack")]
        return []


STRATEGIES: dict[str, type[RecoveryStrategy]] = {
    s.name: s for s in (AgentChordStrategy, SequentialAgentChordStrategy, BacktrackStrategy)
}


def make_strategy(name: str) -> RecoveryStrategy:
    """A strategy by name.

    Raises:
        ValueError: Unknown strategy name.
    """
    try:
        return STRATEGIES[name]()
    except KeyError:
        raise ValueError(f"unknown strategy {name!r} (choose from: {', '.join(STRATEGIES)})") from None
