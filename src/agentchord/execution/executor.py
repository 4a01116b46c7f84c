"""The executor (paper Algorithm 1): run the augmented graph, tick by tick.

Every control tick: refresh the feature frame, let disturbances act, evaluate
the active edge's compiled monitors, and on a persistent violation switch at
once to what the recovery strategy says -- for AgentChord a pre-compiled
forward-moving recovery edge that starts from the robot's current state, for
the backtracking ablation a return to an earlier node's keyframe. Budgets end
an episode as a failure with a reason, never as a hang.

This module holds the loop, the transitions between edges and nodes, and the queries the
strategies ask; what happens from a detection to the recovery program running (binding, a
cleared failure, online repair) is :mod:`agentchord.execution.switching`, and the disturbance
metrics are :mod:`agentchord.execution.ledger`.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from agentchord.actions.base import ArmAction, Status
from agentchord.actions.catalog import ACTIONS
from agentchord.actions.controller import RobotController
from agentchord.execution.arrivals import PlanArrivals, Waiting, derived_monitors
from agentchord.execution.background import Arrival, ScriptedPlan, ThreadedPlan
from agentchord.execution.binding import Binding, HoldMemory
from agentchord.execution.edge_program import EdgeProgram
from agentchord.execution.feasibility import FeasibilityChecker, first_grasps, off_table
from agentchord.harness import Disturbance, DisturbanceSetting, SuccessTracker
from agentchord.execution.ledger import DisturbanceLedger
from agentchord.execution.motion_watch import MotionWatch
from agentchord.execution.planning import PlanSchedule
from agentchord.execution.repair import Repairer
from agentchord.execution.result import UNRECOVERABLE, EpisodeResult
from agentchord.execution.shortcuts import Shortcuts, attach_subgoal_checks
from agentchord.execution.switching import RecoverySwitching
from agentchord.execution.strategies import RecoveryStrategy
from agentchord.execution.trace import Trace
from agentchord.expr import Vocabulary, compile_expr
from agentchord.features.frame import FeatureFrame
from agentchord.features.extractors import make_extractor
from agentchord.graph.models import TaskGraph
from agentchord.graph.progress import forward_filter, nominal_path
from agentchord.monitor import Detection, EdgeMonitors, RecoveryMap
from agentchord.worlds.protocol import CONTROL_HZ, World


@dataclass
class ExecutorConfig:
    """Budgets of one episode.

    Attributes:
        tick_limit: Ticks of the robot's work before the episode ends as a failure (50 Hz); the ticks it
            holds still waiting for a part of a pipelined plan (reasoning, not work) are not counted.
        failure_budget: Times one failure mode may fire per episode.
        max_repairs: Online repairs attempted per episode (at most one per
            (edge, target) pair); past it, unanticipated failures go unrepaired.
    """

    tick_limit: int = 4000
    failure_budget: int = 3
    max_repairs: int = 2
    #: Ticks an object must stay off the table before the episode ends as unrecoverable.
    off_table_ticks: int = 5
    #: Ticks a recovery waits for the objects it grasps to come to rest before binding its arm: a
    #: cloth's corners (they jitter on the table, or hang from the other hand) ...
    bind_wait_ticks: int = 100
    #: ... and a rigid object: a person's pull takes up to 3.3 s to set it down (out of the
    #: fingers, held clear of a moving gripper for up to 1.5 s, carried, lowered, held still:
    #: ``sim/hand.py``).
    bind_rigid_wait_ticks: int = 200
    #: Ticks a failing goal verdict waits, arms still, for a scene that still moves (a cloth's vertices
    #: jittering in contact, a tray rocking after release, a bottle knocked over as the arm got home)
    #: to come to rest; the last edge's monitors keep watching meanwhile.
    settle_ticks: int = 25
    #: How fast the actions move, as a multiple of their speeds (a task with a time budget, as
    #: gym-aloha's 8 s, runs them faster: ``RobotController.pace``).
    pace: float = 1.0


class Executor(RecoverySwitching, PlanArrivals):
    """Runs one episode of a graph on a world with a recovery strategy.

    Args:
        graph: The recovery-augmented graph (the forward-moving filter is applied here).
        world: The world to act in.
        strategy: What to do when a monitor fires.
        tracker: Judges task success from the frames.
        disturbance: Seeded disturbance schedule (None: undisturbed).
        config: Budgets.
        on_tick: Called after every tick (video recording).
        perception: ``oracle`` (simulator state) or ``rgbd`` (rendered depth and
            segmentation of two cameras at 10 Hz, fused and shape-fitted).
        repairer: Proposes a branch for an unanticipated failure (None: no online
            repair; the episode goes on from the unmet sub-goal as before).
        background: The rest of a pipelined plan asked while the robot moves (an LLM's arranger and
            conductor); ``graph`` is then the composed graph it starts on.
        disturbance_setting: The setting ``disturbance`` was drawn from (None: a scripted schedule, or none).
        seed: The trial's seed (its scene and its schedule). Both go into the trace's ``episode_start``.
    """

    # All of it (the mixins declare only the budgets they read: :class:`~agentchord.execution.state.RecoveryBudgets`).
    config: ExecutorConfig

    def __init__(
        self,
        graph: TaskGraph,
        world: World,
        strategy: RecoveryStrategy,
        tracker: SuccessTracker,
        disturbance: Disturbance | None = None,
        config: ExecutorConfig | None = None,
        on_tick: Callable[[Executor], None] | None = None,
        perception: str = "oracle",
        repairer: Repairer | None = None,
        background: ThreadedPlan | ScriptedPlan | None = None,
        disturbance_setting: DisturbanceSetting | None = None,
        seed: int | None = None,
    ) -> None:
        filtered = forward_filter(graph)
        self.world = world
        self.strategy = strategy
        self.tracker = tracker
        self.disturbance = disturbance
        self.disturbance_setting = disturbance_setting
        self.seed = seed
        self.config = config or ExecutorConfig()
        self.on_tick = on_tick
        self.repairer = repairer
        self.trace = Trace()
        for removed in filtered.removed:
            self.trace.add(0, "branch_removed", failure=removed.failure, edge=removed.edge, reason=removed.reason)
        self.robot = RobotController(world)
        self.robot.pace = self.config.pace
        self.extractor = make_extractor(perception, world, lambda arm: self.robot.targets[arm].grip_closed_settled)
        self.robot.frame = self.extractor.frame
        self.feasibility = FeasibilityChecker(self.robot)
        self._compile(filtered.graph)
        # Per reached nominal node: the robot's keyframe (arm joints and grips), for backtracking.
        self.keyframes: dict[str, dict[str, tuple[np.ndarray, float]]] = {}
        self.visited_nominal: list[str] = []
        # Nodes passed before a failure cut their edge short; sub-goals a recovery finds met already.
        self.shortcuts = Shortcuts()
        self.path: list[str] = []
        self.program: EdgeProgram | None = None
        self.binding: Binding | None = None
        # Where each held object sits in its hand: a hold that comes back the same clears a drop.
        self.holds = HoldMemory()
        # Candidates after the bound recovery, tried if it fails outright; cleared when another edge starts.
        self._fallbacks: list[EdgeProgram] = []
        self._off_table_since: dict[str, int] = {}
        self.armed: EdgeMonitors | None = None
        self.recovering_from: str | None = None
        self.fire_counts: dict[tuple[str, str], int] = {}
        self.node = self.graph.start
        self.disturbances = DisturbanceLedger()
        # (edge, target) pairs a repair was attempted for: one attempt each.
        self._repair_attempts: set[tuple[str, str]] = set()
        # The last recovery skipped because its merge node held, until an edge next runs to its end.
        self._skipped: tuple[str, str] | None = None
        # Tick the goal was reached with a scene still moving (its verdict waits for rest), else None.
        self.settling_since: int | None = None
        self.motion = MotionWatch(self.graph.objects)
        # Reasoning charged so far (see charge()).
        self.reasoning_s = 0.0
        self.compute_s = 0.0
        self.reasoning_calls: dict[str, int] = {}
        self.replans = 0
        # A pipelined plan's arrivals (None: the whole graph was there before the first tick).
        self.schedule: PlanSchedule | None = None
        self.waiting: Waiting | None = None
        self.early_failures: list[dict] = []
        self.plan_wait_ticks = 0
        self._early_armed: str | None = None
        self._rearm_tick = 0
        self._arriving: Waiting | None = None
        # While a recovery that waited for its branch begins: the tick the arms have held still since.
        self.still_since: int | None = None
        self.background = background
        # Why the background plan failed, once it has (None: it has not, or there is none).
        self.plan_error: str | None = None
        self._incoming: tuple[int, Arrival] | None = None

    def _compile(self, graph: TaskGraph) -> None:
        """Adopt a (filtered) graph: compile what the tick loop evaluates.

        Called before execution and again after an online repair; the world,
        the trace and the episode's bookkeeping are left as they are.
        """
        self.graph = graph
        vocabulary = Vocabulary(frozenset(graph.objects))
        # Compile once, before execution: the tick loop only evaluates closures.
        self.monitors = {edge.id: EdgeMonitors.compile(edge, vocabulary) for edge in graph.edges}
        self._derived = derived_monitors(graph, vocabulary)
        self.constraints = {node.id: [compile_expr(c, vocabulary) for c in node.constraints] for node in graph.nodes}
        self.recovery_map = RecoveryMap(graph)
        self.nominal_next = {graph.edge(e).source: e for e in nominal_path(graph)}

    def adopt(self, graph: TaskGraph) -> None:
        """Run a re-planned graph from now on (the re-planning baselines): compiled like the first.

        The episode's bookkeeping (trace, path, counts) carries on; the new graph starts at
        its start node, which is where the robot is now.
        """
        filtered = forward_filter(graph)
        for removed in filtered.removed:
            self.trace.add(self.world.tick, "branch_removed", failure=removed.failure, edge=removed.edge, reason=removed.reason)
        self._compile(filtered.graph)
        self.node = self.graph.start
        self.replans += 1

    def charge(self, kind: str, agent: str, latency_s: float, measured: bool = False, compute_s: float = 0.0,
               tokens: int | None = None) -> None:
        """Charge one blocking reasoning call: its latency (modelled or measured) and any compute it measured here."""
        self.reasoning_s += latency_s
        self.compute_s += compute_s
        self.reasoning_calls[kind] = self.reasoning_calls.get(kind, 0) + 1
        self.trace.add(self.world.tick, "reasoning", kind=kind, agent=agent, latency_s=round(latency_s, 4),
                       measured=measured, compute_s=round(compute_s, 4), tokens=tokens)

    # ------------------------------------------------------------- queries
    @property
    def frame(self) -> FeatureFrame:
        """The current feature frame."""
        return self.extractor.frame

    def constraints_hold(self, node_id: str) -> bool:
        """Whether a node's sub-goal constraints all hold on the current frame (Eq. 3)."""
        return all(c.scalar(self.frame) <= 0.0 for c in self.constraints[node_id])

    def violated_constraints(self, node_id: str) -> list[str]:
        """The source text of a node's constraints that do not hold now."""
        return [c.source for c in self.constraints[node_id] if c.scalar(self.frame) > 0.0]

    def describe_violation(self, node_id: str) -> str:
        """One line: each violated constraint of a node with its value now (the repair's observation)."""
        values = ((c.source, c.scalar(self.frame)) for c in self.constraints[node_id])
        violated = "; ".join(f"{source} = {value:.3g}" for source, value in values if value > 0.0)
        return f"at {node_id}: {violated or 'no constraint violated'} (each should be <= 0)"

    # ------------------------------------------------------------ episode
    def run(self) -> EpisodeResult:
        """Execute until the goal, a failure or a budget ends the episode."""
        wall0 = time.perf_counter()
        setting = self.disturbance_setting
        self.trace.add(self.world.tick, "episode_start", task=self.graph.task, strategy=self.strategy.name, start=self.graph.start,
                       seed=self.seed, p=setting.p if setting is not None else 0.0,
                       disturbances=setting.to_dict() if setting is not None else None)
        self.strategy.begin(self)
        first_motion_s = self.reasoning_s + self.compute_s
        outcome = self._arrive(self.graph.start)
        while outcome is None:
            outcome = self._tick()
        success, reason = outcome
        injected = self.disturbance.events if self.disturbance is not None else []
        drops = self.disturbances.drops(injected)
        result = EpisodeResult(
            success=success,
            reason=reason,
            steps=self.world.tick,
            time_s=self.world.tick / CONTROL_HZ,
            wall_s=time.perf_counter() - wall0,
            path=self.path,
            failures_detected=len(self.trace.of("failure_detected")),
            recoveries=len(self.trace.of("recovery_switch")) - len(self.trace.of("failure_cleared")),
            repairs=sum(e["accepted"] for e in self.trace.of("repair")),
            drops_injected=drops[0],
            drops_detected=drops[1],
            drops_recovered=drops[2],
            disturbances=self.disturbances.by_kind(injected),
            reaction_latency_ticks=self.disturbances.latency_ticks,
            trace=self.trace,
            compute_s=self.compute_s,
            reasoning_s=self.reasoning_s,
            reasoning_calls=dict(sorted(self.reasoning_calls.items())),
            reaction_latency_s=self.disturbances.latency_s,
            replans=self.replans,
            first_motion_s=first_motion_s,
            plan_wait_s=self.plan_wait_s,
            early_failures=self.early_failures,
        )
        self.trace.add(self.world.tick, "episode_end", success=success, reason=reason, steps=result.steps)
        if self.background is not None:
            self.background.close()
        close = getattr(self.extractor, "close", None)
        if close is not None:
            close()
        return result

    def _tick(self) -> tuple[bool, str] | None:
        frame = self.extractor.update()
        self.tracker.observe(frame)
        # An environment whose episode ends the moment its task is done (gym-aloha: reward 4 terminates).
        terminated = getattr(self.tracker, "terminated", None)
        verdict = terminated(self.world) if terminated is not None else None
        if verdict is not None:
            # Its judge ends the episode; the graph's own goal is judged beside it, and the record
            # says where the two disagree (a left finger touching the cube is its success, while the
            # graph's goal asks for the left hand alone to hold it).
            goal_holds = self.constraints_hold(self.graph.goal)
            self.trace.add(self.world.tick, "terminated", node=self.node, reason=verdict.reason, graph_goal_holds=goal_holds,
                           graph_goal=self.graph.goal, violated=[] if goal_holds else self.violated_constraints(self.graph.goal))
            return verdict.success, verdict.reason
        self.motion.observe(frame)
        if self.settling_since is not None:
            # The last edge's failure modes hold until the scene is at rest: a bottle knocked over
            # as the arm reached home is still falling when the goal is first judged.
            detection = self.armed.evaluate(frame) if self.armed is not None else None
            if detection is not None:
                self.settling_since = None
                return self._on_failure(detection)
            return self._settle()
        if self.strategy.resumes_cleared_failures:
            self.holds.observe(frame)
        if self.disturbance is not None:
            event = self.disturbance.apply(self.world, frame)
            if event is not None:
                self.disturbances.injected(event, self.reasoning_s)
                self.trace.add(event.tick, "disturbance", kind=event.kind, arm=event.arm, obj=event.obj, action=event.action)
        waited = self.held_for_plan_ticks
        if self.world.tick - waited >= self.config.tick_limit:
            besides = f" ({waited} more ticks held still for the plan, not counted)" if waited else ""
            return False, f"tick limit {self.config.tick_limit} reached at {self._where()}{besides}"
        lost = self._lost_objects(frame)
        if lost is not None:
            return False, lost
        # A part of a pipelined plan the robot waits for; then a failure mode arriving as the edge runs.
        self._poll_background()
        held = self._tick_waiting()
        if held is not False:
            return held
        if self._arrivals_due():
            self._arm_arrived()
        if self.binding is not None:
            outcome = self._bind(frame)
            if outcome is not None:
                return outcome
        if self.strategy.merges_met_subgoals:
            self.shortcuts.observe(self.program, self._node_holds)
        # While a recovery is still binding, nothing is armed or running: the arms hold their poses.
        if self.armed is not None:
            detection = self.armed.evaluate(frame)
            if detection is not None:
                outcome = self._on_failure(detection)
                if outcome is not None:
                    return outcome
        if self.program is not None:
            # The strategy's own detection (VQA queries, path-constraint checks), if it has one.
            detection = self.strategy.watch(self, frame)
            if detection is not None:
                outcome = self._on_failure(detection)
                if outcome is not None:
                    return outcome
        if self.program is not None:
            status = self.program.update(self.robot)
            if status == Status.FAILURE:
                return self._on_program_failed()
            if status == Status.SUCCESS:
                outcome = self._on_program_done()
                if outcome is not None:
                    return outcome
        self._step()
        return None

    def _step(self) -> None:
        """Advance the world a tick (the arms follow their targets), then call the tick watcher."""
        self.robot.step()
        if self.on_tick is not None:
            self.on_tick(self)

    def _settle(self) -> tuple[bool, str] | None:
        """One tick at the goal waiting for the scene to come to rest: nothing runs, nothing is injected."""
        outcome = self._judge_goal()
        if outcome is None:
            self._step()
        return outcome

    def _judge_goal(self) -> tuple[bool, str] | None:
        """The verdict on the goal; None while it fails with the scene still moving, which may yet come to rest.

        A verdict taken on the tick the last edge ends can catch a single cloth vertex jittering at
        16 cm/s in a towel that is otherwise at rest, or a bottle knocked over a few ticks before
        the arm got home, still falling (24 deg and on its way down). The judge waits, the arms
        holding still, up to ``settle_ticks``; those ticks count as the episode's.
        """
        verdict = self.tracker.verdict(self.frame, self.world)
        if verdict.settling or (not verdict.success and self.motion.moving()):
            if self.settling_since is None:
                self.settling_since = self.world.tick
                self.trace.add(self.world.tick, "goal_settling", node=self.node, reason=verdict.reason)
            if self.world.tick - self.settling_since < self.config.settle_ticks:
                return None
        if not verdict.success:
            detection = self._explained_at_goal()
            if detection is not None:
                self.settling_since = None
                self.trace.add(self.world.tick, "violation_at_goal", node=self.node, edge=detection.edge_id,
                               failure=detection.failure.name, reason=verdict.reason)
                return self._on_failure(detection)
        return verdict.success, verdict.reason

    def _explained_at_goal(self) -> Detection | None:
        """A failure mode of the nominal edge into the goal that the scene violates now, if any.

        The goal fails for something that edge watches for (a bottle knocked over again while a
        recovery took the arm home, where nothing watched it): its recovery runs, as if the edge's
        monitor had fired; the failure budget bounds the repeats.
        """
        if not self.strategy.uses_monitors:
            return None
        into_goal = [e for e in nominal_path(self.graph) if self.graph.edge(e).target == self.graph.goal]
        if not into_goal or self.modes_unknown(into_goal[-1]):
            return None
        monitors = self.monitors.get(into_goal[-1])
        return monitors.violated_now(self.frame) if monitors is not None else None

    def _where(self) -> str:
        if self.binding is not None:
            return f"recovery {self.binding.candidates[0].edge_id} (binding its arm)"
        return f"edge {self.program.edge_id}" if self.program else f"node {self.node}"

    def _lost_objects(self, frame: FeatureFrame) -> str | None:
        """The unrecoverable reason once a graph object has been off the table for a few ticks."""
        lost = off_table(frame, self.graph.objects)
        self._off_table_since = {name: self._off_table_since.get(name, self.world.tick) for name in lost}
        for name, since in self._off_table_since.items():
            if self.world.tick - since >= self.config.off_table_ticks:
                z = frame.objects[name].pos[2]
                self.trace.add(self.world.tick, "unrecoverable", obj=name, reason="off the table")
                return f"{UNRECOVERABLE}: {name} fell off the table (z = {z:.2f} m, table top at 0) at {self._where()}"
        return None

    def _node_holds(self, node_id: str) -> bool:
        """Whether the node has constraints and all of them hold now."""
        return bool(self.constraints[node_id]) and self.constraints_hold(node_id)

    # ------------------------------------------------------- transitions
    def _arrive(self, node_id: str) -> tuple[bool, str] | None:
        """Reach a node: record it, then start the next edge (or finish at the goal)."""
        node = self.graph.node(node_id)
        held = self.constraints_hold(node_id)
        self.node = node_id
        self.path.append(node_id)
        self.trace.add(self.world.tick, "node_reached", node=node_id, kind=node.kind, constraints_hold=held,
                       violated=[] if held else self.violated_constraints(node_id), semantic=node.semantic)
        merging = node.kind == "nominal" and self.recovering_from is not None
        if node.kind == "nominal":
            self.visited_nominal.append(node_id)
            self.keyframes[node_id] = {arm: (self.robot.ik.arm_q(arm), t.grip) for arm, t in self.robot.targets.items()}
            if self.recovering_from is not None:
                self.recovering_from = None
                self.trace.add(self.world.tick, "recovery_merged", node=node_id)
                self.disturbances.merged()
                ahead = None
                if self.strategy.merges_met_subgoals:
                    ahead = self.shortcuts.ahead(self.graph, self.nominal_next, node_id, self._node_holds)
                if ahead is not None:
                    self.trace.add(self.world.tick, "merged_ahead", node=node_id, to=ahead.node, passed=ahead.passed, skipped=ahead.skipped)
                    return self._arrive(ahead.node)
        if node_id == self.graph.goal:
            return self._judge_goal()
        next_edge = self.strategy.next_edge(self, node_id)
        if next_edge is None:
            return False, f"no edge leaves node {node_id} toward the goal"
        if merging and not held and self.strategy.uses_monitors:
            detection = self._watched_violation(node_id, next_edge)
            if detection is not None:
                return self._on_failure(detection)
        program = EdgeProgram.from_edge(self.graph.edge(next_edge))
        for grasp in first_grasps(program):
            # Before the arm moves: an object beyond every arm ends the episode now, not after budgets.
            outcome = self._beyond_every_arm(grasp.args.obj, confirm_ik=False)
            if outcome is not None:
                return outcome
        if not self._wait_for_grounding(program):
            self._start(program)
        return None

    def _start(self, program: EdgeProgram) -> None:
        """Start an edge program from the robot's current state."""
        self._fallbacks = []
        self.program = program
        if program.kind == "recovery" and self.strategy.merges_met_subgoals and self.graph.node(program.target).kind == "nominal":
            attach_subgoal_checks(program, self.constraints[program.target])
        program.on_action_start = self._action_started
        program.on_action_end = self._action_ended
        self._arm_monitors(program)
        self.frame.capture_refs()
        self.path.append(program.edge_id)
        self.trace.add(self.world.tick, "edge_start", edge=program.edge_id, kind=program.kind, target=program.target)
        program.initialise(self.robot)

    def _arm_monitors(self, program: EdgeProgram) -> None:
        """Arm ``program``'s edge's monitors, their persistence history cleared.

        Only the active edge's own monitors are armed. A failure during a recovery edge
        without monitors shows at its merge node: the next edge's monitors catch it.
        """
        if self.strategy.uses_monitors and self._arm_early(program):
            return  # its branches are still to come: the monitors derived from its own constraints
        edge_monitors = self.monitors.get(program.edge_id) if self.strategy.uses_monitors else None
        self.armed = edge_monitors if edge_monitors is not None and edge_monitors.monitors else None
        if self.armed is not None:
            self.armed.reset()

    def _on_program_done(self) -> tuple[bool, str] | None:
        program = self.program
        assert program is not None  # called when the running program has just succeeded
        self._skipped = None
        self.trace.add(self.world.tick, "edge_end", edge=program.edge_id)
        self.program = None
        # The strategy's check at a sub-goal's completion (a VQA success query), if it has one.
        detection = self.strategy.at_subgoal(self, program)
        if detection is not None:
            return self._on_failure(detection)
        detection = self._repair(program)
        if detection is not None:
            return self._on_failure(detection)
        early = self._early_arrival(program, lambda: self._arrive(program.target))
        if early is not False:
            return early
        target = self.graph.node(program.target) if program.kind != "backtrack" else None
        if target is not None and target.kind == "recovery":
            self.path.append(target.id)
            self.trace.add(self.world.tick, "node_reached", node=target.id, kind="recovery", constraints_hold=self.constraints_hold(target.id))
            exits = self.recovery_map.exit_edges(target.id)
            if not exits:
                return False, f"recovery node {target.id} has no exit edge"
            following = EdgeProgram.from_edge(exits[0])
            if not self._wait_for_grounding(following):  # a pipelined plan's rest of a branch may not be here yet
                self._start(following)
            return None
        return self._arrive(program.target)

    # --------------------------------------------------------- hooks
    def _action_started(self, arm: str, action: ArmAction) -> None:
        self.trace.add(self.world.tick, "action_start", arm=arm, action=action.describe())
        if self.disturbance is not None:
            spec = ACTIONS.get(action.name)
            self.disturbance.action_started(arm, action, spec.expected_ticks if spec else 100, self.world.tick)

    def _action_ended(self, arm: str, action: ArmAction) -> None:
        if self.disturbance is not None:
            self.disturbance.action_ended(arm)
