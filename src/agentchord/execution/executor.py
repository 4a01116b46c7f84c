"""The executor (paper Algorithm 1): run the augmented graph, tick by tick.

Every control tick: refresh the feature frame, let disturbances act, evaluate
the active edge's compiled monitors, and on a persistent violation switch at
once to what the recovery strategy says -- for AgentChord a pre-compiled
forward-moving recovery edge that starts from the robot's current state, for
the backtracking ablation a return to an earlier node's keyframe. Budgets end
an episode as a failure with a reason, never as a hang. A recovery that must wait for what fell
to come to rest keeps the interrupted edge suspended: if the lost hold comes back as it was, the
failure has cleared and the edge resumes (:mod:`agentchord.execution.binding`); a recovery with nothing
left to do stops short (:mod:`agentchord.execution.shortcuts`). With a repairer, an edge
that ends short of its target's constraints with no monitor fired (a failure
nobody anticipated) is repaired online: the graph gains one branch, the compiled
artefacts are rebuilt and the new recovery edge starts at once.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from agentchord.actions.base import ArmAction, Status
from agentchord.actions.catalog import ACTIONS
from agentchord.actions.controller import RobotController
from agentchord.agents.exceptions import ReasonerError
from agentchord.agents.reasoner import UnanticipatedFailure
from agentchord.execution.binding import Binding, HoldMemory
from agentchord.execution.edge_program import EdgeProgram
from agentchord.execution.feasibility import FeasibilityChecker, first_grasps, off_table
from agentchord.execution.harness import Disturbance, DisturbanceEvent, SuccessTracker
from agentchord.execution.repair import RepairRejectedError, Repairer, validate_repair
from agentchord.execution.result import UNRECOVERABLE, EpisodeResult
from agentchord.execution.shortcuts import Shortcuts
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
        tick_limit: Ticks before the episode ends as a failure (50 Hz).
        failure_budget: Times one failure mode may fire per episode.
        max_repairs: Online repairs attempted per episode (at most one per
            (edge, target) pair); past it, unanticipated failures go unrepaired.
    """

    tick_limit: int = 4000
    failure_budget: int = 3
    max_repairs: int = 2
    #: Ticks an object must stay off the table before the episode ends as unrecoverable.
    off_table_ticks: int = 5
    #: Ticks a recovery waits for the objects it grasps to come to rest before binding its arm.
    bind_wait_ticks: int = 100


class Executor:
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
    """

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
    ) -> None:
        filtered = forward_filter(graph)
        self.world = world
        self.strategy = strategy
        self.tracker = tracker
        self.disturbance = disturbance
        self.config = config or ExecutorConfig()
        self.on_tick = on_tick
        self.repairer = repairer
        self.trace = Trace()
        for removed in filtered.removed:
            self.trace.add(0, "branch_removed", failure=removed.failure, edge=removed.edge, reason=removed.reason)
        self.robot = RobotController(world)
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
        self._open_disturbance: DisturbanceEvent | None = None
        self._latencies: list[int] = []
        self._detected: list[DisturbanceEvent] = []
        self._recovered: list[DisturbanceEvent] = []
        # Detected disturbances whose recovery has not merged back yet (a second one can interrupt the first's).
        self._unmerged: list[DisturbanceEvent] = []
        # (edge, target) pairs a repair was attempted for: one attempt each.
        self._repair_attempts: set[tuple[str, str]] = set()
        # Reasoning charged so far (see charge()), and at the last disturbance (for reaction seconds).
        self.reasoning_s = 0.0
        self.compute_s = 0.0
        self.reasoning_calls: dict[str, int] = {}
        self.replans = 0
        self._reasoning_at_disturbance = 0.0
        self._reaction_s: list[float] = []

    def _compile(self, graph: TaskGraph) -> None:
        """Adopt a (filtered) graph: compile what the tick loop evaluates.

        Called before execution and again after an online repair; the world,
        the trace and the episode's bookkeeping are left as they are.
        """
        self.graph = graph
        vocabulary = Vocabulary(frozenset(graph.objects))
        # Compile once, before execution: the tick loop only evaluates closures.
        self.monitors = {edge.id: EdgeMonitors.compile(edge, vocabulary) for edge in graph.edges}
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

    def charge(self, kind: str, agent: str, latency_s: float, measured: bool = False, compute_s: float = 0.0) -> None:
        """Charge one reasoning call: its latency (modelled or measured) and any compute it measured here."""
        self.reasoning_s += latency_s
        self.compute_s += compute_s
        self.reasoning_calls[kind] = self.reasoning_calls.get(kind, 0) + 1
        self.trace.add(self.world.tick, "reasoning", kind=kind, agent=agent, latency_s=round(latency_s, 4),
                       measured=measured, compute_s=round(compute_s, 4))

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
        self.trace.add(self.world.tick, "episode_start", task=self.graph.task, strategy=self.strategy.name, start=self.graph.start)
        self.strategy.begin(self)
        outcome = self._arrive(self.graph.start)
        while outcome is None:
            outcome = self._tick()
        success, reason = outcome
        injected = self.disturbance.events if self.disturbance is not None else []
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
            drops_injected=sum(e.kind == "drop" for e in injected),
            drops_detected=sum(e.kind == "drop" for e in self._detected),
            drops_recovered=sum(e.kind == "drop" for e in self._recovered),
            disturbances={kind: [sum(e.kind == kind for e in group) for group in (injected, self._detected, self._recovered)]
                          for kind in sorted({e.kind for e in injected})},
            reaction_latency_ticks=self._latencies,
            trace=self.trace,
            compute_s=self.compute_s,
            reasoning_s=self.reasoning_s,
            reasoning_calls=dict(sorted(self.reasoning_calls.items())),
            reaction_latency_s=self._reaction_s,
            replans=self.replans,
        )
        self.trace.add(self.world.tick, "episode_end", success=success, reason=reason, steps=result.steps)
        close = getattr(self.extractor, "close", None)
        if close is not None:
            close()
        return result

    def _tick(self) -> tuple[bool, str] | None:
        frame = self.extractor.update()
        self.tracker.observe(frame)
        if self.strategy.resumes_cleared_failures:
            self.holds.observe(frame)
        if self.disturbance is not None:
            event = self.disturbance.apply(self.world, frame)
            if event is not None:
                self._open_disturbance = event
                self._reasoning_at_disturbance = self.reasoning_s
                self.trace.add(event.tick, "disturbance", kind=event.kind, arm=event.arm, obj=event.obj, action=event.action)
        if self.world.tick >= self.config.tick_limit:
            return False, f"tick limit {self.config.tick_limit} reached at {self._where()}"
        lost = self._lost_objects(frame)
        if lost is not None:
            return False, lost
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
                program = self.program
                if program.kind == "recovery" and program.attempt == 1 and program.scene_changed:
                    # What it had found done was undone under it (a cup found placed, then knocked over
                    # before its place step): bound once more from where things are, then the rest.
                    again = EdgeProgram.from_edge(self.graph.edge(program.edge_id))
                    again.attempt = 2
                    self._fallbacks.insert(0, again)
                detection = None if self._fallbacks else self.strategy.on_program_failure(self, self.program)
                if detection is not None:
                    # The skill reported failure: a strategy that re-plans takes it as a detected failure.
                    self.trace.add(self.world.tick, "action_failed", edge=self.program.edge_id, reason=self.program.failure_reason)
                    self.program = None
                    return self._on_failure(detection)
                if self._fallbacks:
                    # The bound recovery could not be carried out (a grasp out of reach after all):
                    # the next candidate is bound from where the robot is now.
                    self.trace.add(self.world.tick, "recovery_failed", edge=self.program.edge_id, reason=self.program.failure_reason)
                    fallbacks, self._fallbacks = self._fallbacks, []
                    self.program = None
                    return self._begin_recovery(fallbacks)
                return False, f"{self._where()}: {self.program.failure_reason}"
            if status == Status.SUCCESS:
                outcome = self._on_program_done()
                if outcome is not None:
                    return outcome
        self.robot.step()
        if self.on_tick is not None:
            self.on_tick(self)
        return None

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

    def _beyond_every_arm(self, obj: str, confirm_ik: bool) -> tuple[bool, str] | None:
        """The unrecoverable outcome when no arm can take ``obj`` where it is (else None)."""
        beyond = self.feasibility.unreachable(obj, confirm_ik=confirm_ik)
        if not beyond:
            return None
        reasons = "; ".join(c.reason for c in beyond)
        self.trace.add(self.world.tick, "unrecoverable", obj=obj, reason=reasons)
        return False, f"{UNRECOVERABLE}: no arm can take {obj} at {self.feasibility.where(obj)} ({reasons})"

    # ------------------------------------------------------- binding
    def _begin_recovery(self, candidates: list[EdgeProgram]) -> tuple[bool, str] | None:
        """Start a recovery: at once when it grasps nothing, else after binding its arm."""
        objects = sorted({g.args.obj for c in candidates for g in first_grasps(c)})
        if not objects:
            self._start(candidates[0])
            return None
        # The arms hold still while what was dropped or taken comes to rest; then the arm is bound.
        self.program, self.armed = None, None
        self.binding = Binding(candidates, objects, self.world.tick)
        return None

    def _bind(self, frame: FeatureFrame) -> tuple[bool, str] | None:
        """One tick of a binding recovery: wait for rest, then start the first feasible candidate."""
        binding = self.binding
        waited = self.world.tick - binding.since
        if binding.holds_back(frame):
            self._resume(binding)
            return None
        if not binding.at_rest(frame, CONTROL_HZ) and waited < self.config.bind_wait_ticks:
            return None
        self.binding = None
        if binding.suspended is not None:
            binding.suspended.terminate(Status.INVALID)
        met = None
        if self.strategy.merges_met_subgoals:
            met = Shortcuts.met_merge(self.graph, binding.candidates[0], binding.objects, self.frame.holding, self._node_holds)
        if met is not None:
            # What the recovery was for already holds (a bottle pulled out of the hand as it was being
            # put down, set down upright by the person): nothing to redo, go on from the merge node.
            self.trace.add(self.world.tick, "subgoal_met", edge=binding.candidates[0].edge_id, node=met,
                           waited_ticks=waited)
            return self._arrive(met)
        refused = []
        for k, candidate in enumerate(binding.candidates):
            problems = self.feasibility.check_program(candidate)
            if not problems:
                self.trace.add(self.world.tick, "recovery_bound", edge=candidate.edge_id, waited_ticks=waited,
                               refused=refused, arms=sorted({a.arm for step in candidate.steps for a in step}))
                self._start(candidate)
                self._fallbacks = binding.candidates[k + 1:]  # not started yet: still fresh programs
                return None
            refused.append({"edge": candidate.edge_id, "reason": "; ".join(p.reason for p in problems)})
        summary = "; ".join(f"{r['edge']}: {r['reason']}" for r in refused)
        for obj in binding.objects:
            outcome = self._beyond_every_arm(obj, confirm_ik=True)
            if outcome is not None:
                return outcome
        return False, f"no feasible recovery for {', '.join(binding.objects)} at {self.feasibility.where(binding.objects[0])}: {summary}"

    def _node_holds(self, node_id: str) -> bool:
        """Whether the node has constraints and all of them hold now."""
        return bool(self.constraints[node_id]) and self.constraints_hold(node_id)

    def _resume(self, binding: Binding) -> None:
        """The lost holds came back as they were: the failure cleared, the interrupted edge goes on."""
        self.binding = None
        program = binding.suspended
        self.program = program
        self._arm_monitors(program)
        self.recovering_from = binding.recovering_from
        # A cleared failure cost nothing: it does not count against the mode's failure budget.
        self.fire_counts[(program.edge_id, binding.failure)] -= 1
        if self.recovering_from is None:  # nothing else is being recovered: this disturbance is over
            self._recovered.extend(self._unmerged)
            self._unmerged = []
        self.trace.add(self.world.tick, "failure_cleared", edge=program.edge_id, failure=binding.failure,
                       waited_ticks=self.world.tick - binding.since,
                       objects=[h.obj for h in binding.lost])

    # ------------------------------------------------------- transitions
    def _arrive(self, node_id: str) -> tuple[bool, str] | None:
        """Reach a node: record it, then start the next edge (or finish at the goal)."""
        node = self.graph.node(node_id)
        held = self.constraints_hold(node_id)
        self.node = node_id
        self.path.append(node_id)
        self.trace.add(self.world.tick, "node_reached", node=node_id, kind=node.kind, constraints_hold=held,
                       violated=[] if held else self.violated_constraints(node_id))
        merging = node.kind == "nominal" and self.recovering_from is not None
        if node.kind == "nominal":
            self.visited_nominal.append(node_id)
            self.keyframes[node_id] = {arm: (self.robot.ik.arm_q(arm), t.grip) for arm, t in self.robot.targets.items()}
            if self.recovering_from is not None:
                self.recovering_from = None
                self.trace.add(self.world.tick, "recovery_merged", node=node_id)
                self._recovered.extend(self._unmerged)
                self._unmerged = []
                ahead = None
                if self.strategy.merges_met_subgoals:
                    ahead = self.shortcuts.ahead(self.graph, self.nominal_next, node_id, self._node_holds)
                if ahead is not None:
                    self.trace.add(self.world.tick, "merged_ahead", node=node_id, to=ahead.node, passed=ahead.passed, skipped=ahead.skipped)
                    return self._arrive(ahead.node)
        if node_id == self.graph.goal:
            verdict = self.tracker.verdict(self.frame, self.world)
            return verdict.success, verdict.reason
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
        self._start(program)
        return None

    def _watched_violation(self, node_id: str, edge_id: str) -> Detection | None:
        """A recovery merged at ``node_id`` with one of its constraints violated (a second disturbance
        cut the first recovery short before it restored what it was for): the failure mode of the
        next edge whose monitor watches that constraint, fired now, so its recovery runs rather than
        an edge that cannot start (its monitor may be gated by a signal the cut-short recovery reset).
        """
        violated = {" ".join(c.source.split()): c.scalar(self.frame) for c in self.constraints[node_id]
                     if c.scalar(self.frame) > 0.0}
        for failure in self.graph.edge(edge_id).failures:
            monitor = " ".join(failure.monitor.split())
            watched = [value for source, value in violated.items() if source in monitor]
            if watched:
                self.trace.add(self.world.tick, "violation_at_merge", node=node_id, edge=edge_id, failure=failure.name)
                return Detection(edge_id, failure, self.world.tick, self.world.tick, float(watched[0]))
        return None

    def _start(self, program: EdgeProgram) -> None:
        """Start an edge program from the robot's current state."""
        self._fallbacks = []
        self.program = program
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
        edge_monitors = self.monitors.get(program.edge_id) if self.strategy.uses_monitors else None
        self.armed = edge_monitors if edge_monitors is not None and edge_monitors.monitors else None
        if self.armed is not None:
            self.armed.reset()

    def _on_program_done(self) -> tuple[bool, str] | None:
        program = self.program
        self.trace.add(self.world.tick, "edge_end", edge=program.edge_id)
        self.program = None
        # The strategy's check at a sub-goal's completion (a VQA success query), if it has one.
        detection = self.strategy.at_subgoal(self, program)
        if detection is not None:
            return self._on_failure(detection)
        detection = self._repair(program)
        if detection is not None:
            return self._on_failure(detection)
        target = self.graph.node(program.target) if program.kind != "backtrack" else None
        if target is not None and target.kind == "recovery":
            self.path.append(target.id)
            self.trace.add(self.world.tick, "node_reached", node=target.id, kind="recovery", constraints_hold=self.constraints_hold(target.id))
            exits = self.recovery_map.exit_edges(target.id)
            if not exits:
                return False, f"recovery node {target.id} has no exit edge"
            self._start(EdgeProgram.from_edge(exits[0]))
            return None
        return self._arrive(program.target)

    def _on_failure(self, detection: Detection) -> tuple[bool, str] | None:
        key = (detection.edge_id, detection.failure.name)
        self.fire_counts[key] = self.fire_counts.get(key, 0) + 1
        self.trace.add(detection.tick, "failure_detected", edge=detection.edge_id, failure=detection.failure.name,
                       onset_tick=detection.onset_tick, value=detection.value, count=self.fire_counts[key])
        disturbance = self._open_disturbance
        if disturbance is not None:
            # The first detection after a disturbance is its detection.
            self._detected.append(self._open_disturbance)
            self._latencies.append(detection.tick - self._open_disturbance.tick)
            self._unmerged.append(self._open_disturbance)
            self._open_disturbance = None
        if self.fire_counts[key] > self.config.failure_budget:
            return False, f"failure budget exhausted: {detection.failure.name} on {detection.edge_id} fired {self.fire_counts[key]} times"
        interrupted, self.program = self.program, None  # None after an online repair: the failed edge had ended
        resumable = interrupted is not None and self.strategy.resumes_cleared_failures
        if interrupted is not None and not resumable:
            interrupted.terminate(Status.INVALID)
        failed_nominal = self.recovering_from or detection.edge_id
        candidates = self.strategy.recover(self, detection)
        lost = None
        if resumable:
            # A hold lost by the interrupted edge's arms may come back while the recovery waits.
            objects = sorted({g.args.obj for c in candidates for g in first_grasps(c)})
            lost = self.holds.lost(self.frame, {a.arm for a in interrupted.running}, objects) if objects else None
            if lost is None:
                interrupted.terminate(Status.INVALID)
        if not candidates:
            return False, f"no recovery for {detection.failure.name} on {detection.edge_id}"
        previous_context, self.recovering_from = self.recovering_from, failed_nominal
        if disturbance is not None:
            # Seconds from the disturbance to this switch: robot time plus the reasoning charged since.
            self._reaction_s.append((self.world.tick - disturbance.tick) / CONTROL_HZ + self.reasoning_s - self._reasoning_at_disturbance)
        self.trace.add(self.world.tick, "recovery_switch", failure=detection.failure.name, edge=detection.edge_id,
                       to=candidates[0].edge_id, alternatives=[c.edge_id for c in candidates[1:]],
                       strategy=self.strategy.name, latency_ticks=self.world.tick - detection.onset_tick)
        outcome = self._begin_recovery(candidates)
        if lost is not None:
            # The recovery waits for what fell; if it was never really let go, the edge goes on.
            self.binding.suspended, self.binding.lost = interrupted, lost
            self.binding.failure, self.binding.recovering_from = detection.failure.name, previous_context
            self.binding.window = detection.failure.window
        return outcome

    def _repair(self, program: EdgeProgram) -> Detection | None:
        """Online repair of an unanticipated failure at the end of ``program``.

        The program ended (so no monitor of its edge fired) but its target's
        constraints do not hold. Within the budgets, ask the repairer for one new
        failure mode on the edge, validate it, rebuild the compiled graph and
        return the detection "as if" the new mode's monitor had fired now, so the
        usual switch (the strategy's ``recover``: for AgentChord the new entry
        edge) starts from where the robot is. The failed target is not "reached".

        Returns:
            The synthetic detection, or None to carry on as without a repairer.
        """
        if self.repairer is None or program.kind == "backtrack" or self.constraints_hold(program.target):
            return None
        key = (program.edge_id, program.target)
        if len(self._repair_attempts) >= self.config.max_repairs or key in self._repair_attempts:
            return None
        self._repair_attempts.add(key)
        edge = self.graph.edge(program.edge_id)
        failure = UnanticipatedFailure(edge=edge.id, context=edge.source, observation=self.describe_violation(program.target))
        record = {"edge": edge.id, "target": program.target, "context": edge.source, "observation": failure.observation}
        started = time.perf_counter()
        try:
            proposal = self.repairer(self.graph, failure, self.frame)
            if proposal is None:
                raise RepairRejectedError(edge.id, "the repairer proposed no branch")
            repair = validate_repair(self.graph, proposal, failure)
        except (RepairRejectedError, ReasonerError) as error:
            reason = error.reason if isinstance(error, RepairRejectedError) else error.headline
            self.trace.add(self.world.tick, "repair", **record, failure=None, recovery=None, accepted=False,
                           reason=reason, latency_s=time.perf_counter() - started)
            return None
        self._compile(repair.filtered.graph)
        latency = time.perf_counter() - started
        for removed in repair.filtered.removed:
            self.trace.add(self.world.tick, "branch_removed", failure=removed.failure, edge=removed.edge, reason=removed.reason)
        self.trace.add(self.world.tick, "repair", **record, failure=repair.failure.name, recovery=repair.recovery.id,
                       accepted=True, latency_s=latency)
        monitor = next(m for m in self.monitors[edge.id].monitors if m.failure.name == repair.failure.name)
        return Detection(edge.id, repair.failure, self.world.tick, self.world.tick, monitor.expr.scalar(self.frame))

    # --------------------------------------------------------- hooks
    def _action_started(self, arm: str, action: ArmAction) -> None:
        self.trace.add(self.world.tick, "action_start", arm=arm, action=action.describe())
        if self.disturbance is not None:
            spec = ACTIONS.get(action.name)
            self.disturbance.action_started(arm, action, spec.expected_ticks if spec else 100, self.world.tick)

    def _action_ended(self, arm: str, action: ArmAction) -> None:
        if self.disturbance is not None:
            self.disturbance.action_ended(arm)
