"""From a detection to the recovery program running: the executor's failure switching.

On a detection the strategy names its recovery programs; :meth:`_on_failure` switches to them at
once. A skill's reported failure (:meth:`_on_program_failed`) is the strategy's detection, or the
next candidate bound, and a recovery merged with a constraint still violated fires the next edge's
mode that watches it (:meth:`_watched_violation`). A recovery that grasps first waits (binds) until what fell is at rest, then starts the first
candidate its arms can make (:mod:`agentchord.execution.feasibility`); while it waits, a lost hold
that comes back as it was resumes the interrupted edge (:mod:`agentchord.execution.binding`), and a
recovery whose merge sub-goal already holds is skipped (:mod:`agentchord.execution.shortcuts`). An
edge that ends short of its target with no monitor fired is repaired online, within budgets
(:mod:`agentchord.execution.repair`).

:class:`RecoverySwitching` is a part of :class:`~agentchord.execution.executor.Executor` (a mixin):
it reads and sets the executor's episode state, declared in :class:`~agentchord.execution.state.ExecutorState`.
"""

from __future__ import annotations

import time
from dataclasses import replace

from agentchord.actions.base import Status
from agentchord.agents.exceptions import ReasonerError, ReasonerTransportError
from agentchord.agents.reasoner import UnanticipatedFailure
from agentchord.execution.arrivals import DERIVED_INTENT
from agentchord.execution.binding import Binding
from agentchord.execution.edge_program import EdgeProgram
from agentchord.execution.feasibility import first_grasps
from agentchord.execution.repair import RepairRejectedError, validate_repair
from agentchord.execution.result import UNRECOVERABLE
from agentchord.execution.shortcuts import Shortcuts
from agentchord.execution.state import ExecutorState
from agentchord.features.frame import FeatureFrame
from agentchord.monitor import Detection
from agentchord.worlds.protocol import CONTROL_HZ


class RecoverySwitching(ExecutorState):
    """The executor's failure handling (detection -> recovery switch -> binding -> start or resume)."""

    def _beyond_every_arm(self, obj: str, confirm_ik: bool) -> tuple[bool, str] | None:
        """The unrecoverable outcome when no arm can take ``obj`` where it is (else None)."""
        beyond = self.feasibility.unreachable(obj, confirm_ik=confirm_ik)
        if not beyond:
            return None
        reasons = "; ".join(c.reason for c in beyond)
        self.trace.add(self.world.tick, "unrecoverable", obj=obj, reason=reasons)
        return False, f"{UNRECOVERABLE}: no arm can take {obj} at {self.feasibility.where(obj)} ({reasons})"

    def _begin_recovery(self, candidates: list[EdgeProgram]) -> tuple[bool, str] | None:
        """Start a recovery: at once when it grasps nothing, else after binding its arm."""
        objects = sorted({g.args.obj for c in candidates for g in first_grasps(c)})
        if not objects:
            self._start(candidates[0])
            return None
        # The arms hold still while what was dropped or taken comes to rest; then the arm is bound.
        self.program, self.armed = None, None
        since = self.world.tick if self.still_since is None else self.still_since  # a pipelined plan's wait counts
        self.binding = Binding(candidates, objects, since)
        return None

    def _bind(self, frame: FeatureFrame) -> tuple[bool, str] | None:
        """One tick of a binding recovery: wait for rest, then start the first feasible candidate."""
        binding = self.binding
        assert binding is not None  # the tick loop calls this only while a recovery binds
        waited = self.world.tick - binding.since
        if binding.holds_back(frame):
            self._resume(binding)
            return None
        # Longer for a rigid object (a person may still be carrying it, low over the table or held
        # up) than for a cloth's corners, which jitter on the table or hang from the other hand.
        limit = self.config.bind_rigid_wait_ticks if binding.rigid(frame) else self.config.bind_wait_ticks
        if not binding.at_rest(frame, CONTROL_HZ) and waited < limit:
            return None
        self.binding = None
        if binding.suspended is not None:
            binding.suspended.terminate(Status.INVALID)
        met = None
        if self.strategy.merges_met_subgoals:
            met = Shortcuts.met_merge(self.graph, binding.candidates[0], binding.objects, self.frame.holding, self._node_holds)
        skip = (binding.candidates[0].edge_id, met)
        if met is not None and self._leaving_fails_at_once(met):
            met = None  # the merge node holds, but not what the recovery was for: it runs
        if met is not None and self._skipped == skip:
            # Skipped to this node already, and the edge out of it failed before it ended (later than
            # its first frame, or by a monitor that reads an arm): the node's constraints do not read
            # what that edge watches. Skipping again would go round node, edge, failure until the
            # budget ended the episode; the recovery runs instead.
            met = None
        if met is not None:
            self._skipped = (skip[0], met)  # ``skip`` itself: ``met`` is the node it was made with
            # What the recovery was for already holds (a bottle pulled out of the hand as it was being
            # put down, set down upright by the person): nothing to redo, go on from the merge node.
            self.trace.add(self.world.tick, "subgoal_met", edge=binding.candidates[0].edge_id, node=met,
                           waited_ticks=waited)
            return self._arrive(met)
        refused: list[dict[str, str]] = []
        for k, candidate in enumerate(binding.candidates):
            problems = self.feasibility.check_program(candidate)
            if not problems:
                self.trace.add(self.world.tick, "recovery_bound", edge=candidate.edge_id, waited_ticks=waited,
                               refused=refused, arms=sorted({a.arm for step in candidate.steps for a in step}))
                # A pipelined plan's alternative (the other arm's way) may not have arrived: the arms hold still for it.
                if not self._wait_for_grounding(candidate):
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

    def _leaving_fails_at_once(self, node_id: str) -> bool:
        """Whether the nominal edge out of ``node_id`` would detect a failure on its first frame.

        A merge node's constraints need not read what its recovery was for: "bottle held beside the
        cup" says nothing of the cup standing. Skipping there while the cup lies on its side only
        fires the next edge's monitor again, counted against the failure budget for nothing until it
        ran out and ended the episode. Only monitors of the scene alone count: one that reads an arm
        (a closed-gripper monitor of an object the edge is about to grasp) reads as violated until the
        edge opens the hand, and the binding judges holds. Drift is measured from where the objects
        are now, as that edge would measure it from its start.
        """
        edge_id = self.nominal_next.get(node_id)
        monitors = self.monitors.get(edge_id) if edge_id is not None else None
        if edge_id is None or monitors is None or self.modes_unknown(edge_id):
            return False
        frame = self.frame
        as_started = replace(frame, refs={name: feats.pos.copy() for name, feats in frame.objects.items()})
        return monitors.violated_now(as_started, scene_only=True) is not None

    def _resume(self, binding: Binding) -> None:
        """The lost holds came back as they were: the failure cleared, the interrupted edge goes on."""
        self.binding = None
        program = binding.suspended
        assert program is not None  # a binding's holds come back only where it kept the interrupted edge
        self.program = program
        self._arm_monitors(program)
        self.recovering_from = binding.recovering_from
        # A cleared failure cost nothing: it does not count against the mode's failure budget.
        self.fire_counts[(program.edge_id, binding.failure)] -= 1
        if self.recovering_from is None:  # nothing else is being recovered: this disturbance is over
            self.disturbances.merged()
        self.trace.add(self.world.tick, "failure_cleared", edge=program.edge_id, failure=binding.failure,
                       waited_ticks=self.world.tick - binding.since,
                       objects=[h.obj for h in binding.lost])

    def _on_failure(self, detection: Detection) -> tuple[bool, str] | None:
        if self._early_failure(detection):
            return None  # its branch has not arrived: the arms hold still until it does
        detection = self.as_arranged(detection)
        key = (detection.edge_id, detection.failure.name)
        self.fire_counts[key] = self.fire_counts.get(key, 0) + 1
        self.trace.add(detection.tick, "failure_detected", edge=detection.edge_id, failure=detection.failure.name,
                       onset_tick=detection.onset_tick, value=detection.value, count=self.fire_counts[key])
        disturbance = self.disturbances.detection(detection.tick)
        if detection.failure.intent == DERIVED_INTENT:  # a derived monitor past its wait: the background plan failed
            return self._unrecovered(detection)
        if self.fire_counts[key] > self.config.failure_budget:
            return False, f"failure budget exhausted: {detection.failure.name} on {detection.edge_id} fired {self.fire_counts[key]} times"
        interrupted, self.program = self.program, None  # None after an online repair: the failed edge had ended
        resumable = interrupted is not None and self.strategy.resumes_cleared_failures
        if interrupted is not None and not resumable:
            interrupted.terminate(Status.INVALID)
        failed_nominal = self.recovering_from or detection.edge_id
        candidates = self.strategy.recover(self, detection)
        lost = None
        if interrupted is not None and resumable:
            # A hold lost by the interrupted edge's arms may come back while the recovery waits.
            objects = sorted({g.args.obj for c in candidates for g in first_grasps(c)})
            lost = self.holds.lost(self.frame, {a.arm for a in interrupted.running}, objects) if objects else None
            if lost is None:
                interrupted.terminate(Status.INVALID)
        if not candidates:
            return False, f"no recovery for {detection.failure.name} on {detection.edge_id}"
        previous_context, self.recovering_from = self.recovering_from, failed_nominal
        if disturbance is not None:
            self.disturbances.switched(disturbance, self.world.tick, self.reasoning_s)
        self.trace.add(self.world.tick, "recovery_switch", failure=detection.failure.name, edge=detection.edge_id,
                       to=candidates[0].edge_id, alternatives=[c.edge_id for c in candidates[1:]],
                       strategy=self.strategy.name, latency_ticks=self.world.tick - detection.onset_tick)
        outcome = self._begin_recovery(candidates)
        if lost is not None:
            # The recovery waits for what fell; if it was never really let go, the edge goes on.
            # A hold is looked for only when the candidates grasp: _begin_recovery then bound them.
            assert self.binding is not None
            self.binding.suspended, self.binding.lost = interrupted, lost
            self.binding.failure, self.binding.recovering_from = detection.failure.name, previous_context
            self.binding.window = detection.failure.window
        return outcome

    def _on_program_failed(self) -> tuple[bool, str] | None:
        """The running program reported a skill's failure: bind it once more (what it found done was
        undone under it), take it as the strategy's detection, bind the next candidate, or end."""
        if self._early_program_failure():
            return None  # its branch has not arrived: the arms hold still until it does
        assert self.program is not None  # a skill's failure is reported by the running program
        program = self.program
        if program.kind == "recovery" and program.attempt == 1 and program.scene_changed:
            # What it had found done was undone under it (a cup found placed, then knocked over
            # before its place step): bound once more from where things are, then the rest.
            again = EdgeProgram.from_edge(program.edge or self.graph.edge(program.edge_id))
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

    def _watched_violation(self, node_id: str, edge_id: str) -> Detection | None:
        """A recovery merged at ``node_id`` with one of its constraints violated (a second disturbance
        cut the first recovery short before it restored what it was for): the failure mode of the
        next edge whose monitor watches that constraint, fired now, so its recovery runs rather than
        an edge that cannot start (its monitor may be gated by a signal the cut-short recovery reset).
        """
        if self.modes_unknown(edge_id):
            return None  # its failure modes have not arrived
        values = [(c, c.scalar(self.frame)) for c in self.constraints[node_id]]
        broken = [(c, value) for c, value in values if value > 0.0]
        violated = {" ".join(c.source.split()): value for c, value in broken}
        read = frozenset().union(*(c.objects for c, _ in broken))
        compiled = {m.failure.name: m for m in self.monitors[edge_id].monitors} if edge_id in self.monitors else {}
        # In the arranger's order, the first mode that watches what broke: its monitor names a violated
        # constraint, or reads the scene alone (no hand), reads an object a violated constraint reads and
        # is violated now. The second takes a mode listed first for a worse state (both towel corners
        # off, before either one) whose monitor spells the constraints differently.
        for failure in self.graph.edge(edge_id).failures:
            monitor = " ".join(failure.monitor.split())
            watched = [value for source, value in violated.items() if source in monitor]
            scene = compiled.get(failure.name)
            if not watched and scene is not None and not scene.expr.arms and scene.expr.objects & read:
                value = scene.expr.scalar(self.frame)
                watched = [value] if value > failure.margin else []
            if watched:
                self.trace.add(self.world.tick, "violation_at_merge", node=node_id, edge=edge_id, failure=failure.name)
                return Detection(edge_id, failure, self.world.tick, self.world.tick, float(watched[0]))
        return None

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
        edge = program.edge or self.graph.edge(program.edge_id)
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
            if isinstance(error, ReasonerTransportError):
                # The endpoint is down: the next repair would wait out every retry again for nothing.
                self.repairer = None
                reason += " (the endpoint is down: no more repairs are asked in this episode)"
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
