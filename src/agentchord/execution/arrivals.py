"""A pipelined plan's parts arriving while the robot moves: the executor's side of it.

The robot starts once the first edge is grounded (:mod:`agentchord.execution.planning`); the rest
of the plan arrives at ticks of the episode. Until the arranger's list of an edge's failure modes
has arrived, the edge runs with what needs no reasoner: **monitors derived from its own
constraints** -- each constraint its source and target nodes share (what is held stays held; what
stands stays standing), each of its path constraints, and the hold of what its own grasps take
once the gripper has closed, each as a monitor with the default persistence window. From the
list's arrival the edge's own monitors are armed (their persistence history starts then).

A failure before its recovery branch has arrived **waits for the branch**: the arms hold still
(the world keeps stepping, disturbances keep acting) and the recovery starts when the branch is
there, from where things are then. A mode that fires waits for its own branch. A derived monitor
that fires waits for the list, then is the mode that watches the same constraint (it would have
fired, had it been there) and waits for that mode's branch; if no mode watches it, it waits for
all the edge's branches and asks their monitors what the scene is: one that reads it violated
recovers, else the edge goes on. A skill that reports failure waits for the list, then goes to
the strategy as usual. A nominal edge whose grounding has not arrived when the robot reaches its
source waits the same way. A nominal edge that ends at a node whose constraints do not hold before
its modes have all arrived (their monitors never watched it) waits for them at the node, then asks
them what the scene is, as a derived monitor's failure does. Each case is in the trace (``failure_before_branch``,
``modes_listed``, ``branch_arrived`` with what came of it) and in the episode's result
(:attr:`EpisodeResult.early_failures`).

A background plan that **fails** (the endpoint down, a reply refused) brings no mode and no branch:
from then on every nominal edge keeps its derived monitors for the rest of the episode (the robot is
never blind), a derived monitor that fires ends the episode with the failure and the plan's error as
its reason (``unrecovered`` in the trace; a failure waiting for its branch when the plan fails ends
the same way), and so does an edge that ends at a node whose constraints do not hold. After an
outage the online repairer is not asked either: it would call the same endpoint.

:class:`PlanArrivals` is a part of :class:`~agentchord.execution.executor.Executor` (a mixin), as
:class:`~agentchord.execution.switching.RecoverySwitching` is.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal

from agentchord.execution.planning import PlanSchedule
from agentchord.execution.state import ExecutorState
from agentchord.expr import Vocabulary
from agentchord.graph.models import FailureMode, TaskGraph
from agentchord.graph.progress import forward_filter, nominal_path
from agentchord.monitor import Detection, EdgeMonitors
from agentchord.worlds.protocol import CONTROL_HZ

if TYPE_CHECKING:
    from agentchord.execution.background import Arrival
    from agentchord.execution.edge_program import EdgeProgram

#: The intent of a derived monitor's failure: there is no recovery before the arranger's arrives.
DERIVED_INTENT = "wait for the arranger's branch"
#: A node's hold constraint, spaces normalised: ``0.5 - holding(arm, obj)``.
_HOLD = re.compile(r"0\.5 - holding\((?P<arm>left|right), (?P<obj>[A-Za-z_][A-Za-z0-9_]*)\)")
#: Seconds standing for "not known yet": the parts of a background plan before its reply is in.
UNKNOWN_S = 1e9


def derived_monitors(graph: TaskGraph, vocabulary: Vocabulary) -> dict[str, EdgeMonitors]:
    """Per nominal edge, monitors of the constraints it must keep, known before any arranger reply.

    A constraint both ends of the edge share (the same text, spaces aside) must hold all along it; a
    path constraint must too; what one of the edge's grasps takes stays in that hand once its
    gripper has closed (``arm.closed * (0.5 - holding(arm, obj))``, the grasp-done signal gating
    the hold); and what the source node holds (``0.5 - holding(arm, obj)``) and its target does not
    stays in the hand while the gripper is closed (the same gate: opening it to put the object down
    ends the watch). Each is a failure mode named ``keeps: <constraint>``.
    """
    out = {}
    for edge in graph.nominal_edges():
        source = {" ".join(c.split()): c for c in graph.node(edge.source).constraints}
        target = {" ".join(c.split()) for c in graph.node(edge.target).constraints}
        shared = [source[key] for key in target if key in source]
        # What the edge's own grasps take stays in the hand once the gripper has closed on it.
        grasped = [f"{arm}.closed * (0.5 - holding({arm}, {call.args['obj']}))" for arm, call in edge.calls
                   if call.fn == "grasp" and isinstance(call.args.get("obj"), str)]
        # What the source holds stays in the hand while its gripper stays closed: until the edge opens it
        # to put the object down (a tray carried to its place, a bottle pulled out as it is set down).
        held = [f"{m['arm']}.closed * (0.5 - holding({m['arm']}, {m['obj']}))" for key in source
                if key not in target and (m := _HOLD.fullmatch(key)) is not None]
        kept = list(dict.fromkeys([*shared, *edge.path_constraints, *grasped, *held]))
        # model_validate, not FailureMode(...): mypy takes the positional Field defaults (margin, window) for required.
        failures = [FailureMode.model_validate({"name": f"keeps: {c}", "monitor": c, "intent": DERIVED_INTENT, "recovery": edge.id})
                    for c in kept]
        out[edge.id] = EdgeMonitors.compile(edge.model_copy(update={"failures": failures}), vocabulary)
    return out


@dataclass
class Waiting:
    """The robot holding still for a part of the plan that has not arrived.

    Attributes:
        until: The tick it arrives.
        since: The tick the wait began.
        edge_id: The nominal edge whose part is awaited.
        failure: What fired before the branch (None when waiting for a grounding).
        then: Called when it arrives: the episode's outcome, or None to go on.
        began: The tick this leg of the wait began (a failure may wait for the modes' list, then a branch).
    """

    until: int
    since: int
    edge_id: str
    failure: str | None
    then: Callable[[], tuple[bool, str] | None]
    began: int = -1

    def __post_init__(self) -> None:
        if self.began < 0:
            self.began = self.since


class PlanArrivals(ExecutorState):
    """The executor's pipelined plan: parts armed at their ticks, failures that come first wait.

    The executor's state it reads and sets is declared in :class:`ExecutorState`, but for its own waits.
    """

    # The wait under way (None: nothing waits), and the one whose part has just arrived (its ``then`` runs).
    waiting: Waiting | None
    _arriving: Waiting | None

    def follow_schedule(self, schedule: PlanSchedule) -> None:
        """Plan with ``schedule``: the robot waits for its first motion, the rest arrives at its ticks."""
        self.schedule = schedule
        self.reasoning_s += schedule.first_motion_s
        for scheduled in schedule.calls:
            call = scheduled.call
            self.reasoning_calls[call.kind] = self.reasoning_calls.get(call.kind, 0) + 1
            self.trace.add(self.world.tick, "reasoning", kind=call.kind, agent=call.agent, part=call.part, tokens=call.tokens,
                           start_s=round(scheduled.start_s, 4), end_s=round(scheduled.end_s, 4),
                           latency_s=round(scheduled.end_s - scheduled.start_s, 4), measured=False,
                           arrives_tick=schedule.tick_of(scheduled.end_s), critical=call.part in schedule.critical)

    def follow_background(self) -> None:
        """Start the robot on the composed graph and ask the rest of the plan in the background
        (:mod:`agentchord.execution.background`): every mode arrives with its reply, whenever that is."""
        first = self.reasoning_s + self.compute_s
        path = nominal_path(self.graph)
        self.schedule = PlanSchedule((), first, {e: first for e in path}, {}, {e: first + UNKNOWN_S for e in path})
        # Called by a strategy only when there is a background plan (``executor.background is not None``).
        assert self.background is not None
        self.background.start()
        self.trace.add(self.world.tick, "plan_asked", agents=["arranger", "conductor"], first_motion_s=round(first, 4))

    def _poll_background(self) -> None:
        """Take the background plan's reply when it is in, and adopt its graph at the tick it arrives."""
        if self.background is not None:
            arrival = self.background.poll(self.world.tick / CONTROL_HZ)
            if arrival is not None:
                self.background = None
                self._received(arrival)
        if self._incoming is not None and self.world.tick >= self._incoming[0]:
            arrival, self._incoming = self._incoming[1], None
            if arrival.graph is None:
                self._plan_failed(arrival.error or "no reply", arrival.outage)
                return
            graph = forward_filter(arrival.graph).graph
            self._compile(graph)
            if arrival.fallback is not None and arrival.outage and self.repairer is not None:
                self.repairer = None  # it would ask the endpoint that is down
            self.trace.add(self.world.tick, "plan_arrived", failures=len(graph.failures()), recovery_edges=len(graph.recovery_edges()),
                           **({"written_by": arrival.fallback, "llm_error": arrival.error} if arrival.fallback else {}))

    def _received(self, arrival: Arrival) -> None:
        schedule = self.schedule
        assert schedule is not None  # follow_background set it before the background plan was asked
        at = schedule.first_motion_s + arrival.latency_s
        tick = schedule.tick_of(at)
        self.trace.add(self.world.tick, "plan_replied", latency_s=round(arrival.latency_s, 4), arrives_tick=tick,
                       error=arrival.error, outage=arrival.outage, fallback=arrival.fallback,
                       calls=[c.to_trace_event(messages=False) for c in arrival.calls])
        listed = {edge_id: at for edge_id in schedule.modes_listed_s}
        modes: dict[tuple[str, str], float] = {}
        if arrival.graph is not None:
            modes = {(edge.id, failure.name): at for edge, failure in forward_filter(arrival.graph).graph.failures()}
        self._incoming = (tick, arrival)  # adopted (or its failure taken) at the tick it arrives
        self.schedule = PlanSchedule(schedule.calls, schedule.first_motion_s, schedule.edge_ready_s, modes, listed)
        if self.waiting is not None:
            self.waiting.until = min(self.waiting.until, tick)
        if self._early_armed is not None:
            self._rearm_tick = min(self._rearm_tick, tick)

    def _plan_failed(self, error: str, outage: bool) -> None:
        """The background plan failed: no mode or branch will come; the derived monitors stay armed."""
        self.plan_error = error
        repair = None
        if outage and self.repairer is not None:
            self.repairer, repair = None, "not asked: the endpoint is down"
        self.trace.add(self.world.tick, "plan_failed", reason=error, outage=outage, repair=repair,
                       then="each edge keeps the monitors derived from its constraints; a failure that needs a branch ends the episode")

    def _unrecovered(self, detection: Detection) -> tuple[bool, str]:
        """End the episode on a failure no branch will come for (the background plan failed)."""
        reason = (f"{detection.failure.name} on {detection.edge_id}: no recovery branch, "
                  f"the arranger's plan failed ({_headline(self.plan_error)})")
        self.trace.add(self.world.tick, "unrecovered", edge=detection.edge_id, failure=detection.failure.name, reason=reason)
        return False, reason

    # ------------------------------------------------------------ queries
    def _tick_at(self, seconds: float | None) -> int | None:
        """The tick a part arriving at ``seconds`` is armed, if that is still to come (None: it is here)."""
        if seconds is None:
            return None
        assert self.schedule is not None  # ``seconds`` were read from the schedule
        tick = self.schedule.tick_of(seconds)
        return tick if self.world.tick < tick else None

    def _mode_tick(self, edge_id: str, failure: str) -> int | None:
        """The tick a failure mode can be recovered from (what its recovery runs has arrived), if still to come."""
        if self.schedule is None:
            return None
        return self._tick_at(self.schedule.mode_ready_s.get((edge_id, failure)))

    def _pending_modes(self, edge_id: str) -> list[int]:
        """The ticks still to come at which ``edge_id``'s failure modes (or their list) can be recovered from."""
        if self.schedule is None:
            return []
        ticks = [self._mode_tick(edge_id, f.name) for f in self.graph.edge(edge_id).failures] if edge_id in self.monitors else []
        ticks.append(self._tick_at(self.schedule.modes_listed_s.get(edge_id)))
        return sorted(t for t in ticks if t is not None)

    def _listed_tick(self, edge_id: str) -> int | None:
        """The tick the arranger's list of ``edge_id``'s failure modes arrives, if still to come."""
        return self._tick_at(self.schedule.modes_listed_s.get(edge_id)) if self.schedule is not None else None

    def modes_unknown(self, edge_id: str) -> bool:
        """Whether the arranger's list of ``edge_id``'s failure modes (their monitors) is still to come."""
        return self._listed_tick(edge_id) is not None

    # ------------------------------------------------------------ arming
    def _arm_early(self, program: EdgeProgram) -> bool:
        """Arm the monitors derived from a nominal edge's own constraints while its modes are not known yet
        (True when so); once they are, the edge's own monitors are armed as usual. After the background
        plan failed, a nominal edge keeps its derived monitors (no mode of it will come)."""
        if program.kind == "nominal" and self.plan_error is not None:
            derived = self._derived.get(program.edge_id)
            self.armed = derived if derived is not None and derived.monitors else None
            if self.armed is not None:
                self.armed.reset()
            self._early_armed = None
            return True
        listed = self._listed_tick(program.edge_id) if program.kind == "nominal" else None
        if listed is None:
            self._early_armed = None
            return False
        derived = self._derived.get(program.edge_id)
        self.armed = derived if derived is not None and derived.monitors else None
        if self.armed is not None:
            self.armed.reset()
        self._early_armed = program.edge_id
        self._rearm_tick = listed
        return True

    def _arm_arrived(self) -> None:
        """The running edge's modes arrived: their monitors are armed from now on (their persistence history starts)."""
        edge_id, self._early_armed = self._early_armed, None
        if self.program is None or self.program.edge_id != edge_id:
            return
        self._arm_monitors(self.program)
        # Drift is measured from where things are now: what moved before, the running program has aimed at.
        self.frame.capture_refs()
        self.trace.add(self.world.tick, "monitors_armed", edge=edge_id,
                       monitors=[m.failure.name for m in self.armed.monitors] if self.armed is not None else [])

    def _arrivals_due(self) -> bool:
        """Whether the running edge's modes arrive at this tick."""
        return self._early_armed is not None and self.world.tick >= self._rearm_tick

    # ------------------------------------------------------------ waiting
    def _wait_for(self, edge_id: str, until: int, failure: str | None, then: Callable[[], tuple[bool, str] | None]) -> None:
        """Hold the arms still until tick ``until`` (a part of the plan for ``edge_id`` arrives), then call ``then``."""
        self.program, self.armed = None, None
        self.waiting = Waiting(until, self.world.tick, edge_id, failure, then)
        if failure is not None:
            self.trace.add(self.world.tick, "failure_before_branch", edge=edge_id, failure=failure, arrives_tick=until)

    def _early_failure(self, detection: Detection, suspended: EdgeProgram | None = None, since: int | None = None,
                       resume: Callable[[], tuple[bool, str] | None] | None = None) -> bool:
        """Wait for the branch of a failure that fired before it arrived (True when it waits).

        A mode that fires before its branch (a strategy's detection) waits for its own branch. A derived
        monitor (``keeps: ...``) first waits for the arranger's list of the edge's modes, if it has not
        come; then it is the mode that watches the same constraint, if there is one: it waits for that
        mode's branch and switches to its recovery then, as if the mode had fired (it would have, had it
        been there). Otherwise it waits for every mode of the edge and asks them what the scene is: one
        that reads it violated switches to its recovery, else the edge goes on (``resume``, when given:
        what going on is for an edge that has ended).
        """
        derived = detection.failure.intent == DERIVED_INTENT
        if derived and self.plan_error is not None:
            return False  # no branch will come: :meth:`_on_failure` ends the episode with the reason
        listed = self._listed_tick(detection.edge_id) if derived else None
        if listed is not None:
            self._hurry(detection.edge_id, None)  # which modes the edge has is not known yet
            until = self._listed_tick(detection.edge_id) or self.world.tick
        elif derived:
            watching = self.as_arranged(detection)
            if watching is not detection:
                return self._early_failure(watching, suspended, since, resume)
            if self._pending_modes(detection.edge_id):
                self._hurry(detection.edge_id, None)
            pending = self._pending_modes(detection.edge_id)
            until = pending[-1] if pending else self.world.tick
        else:
            if self._mode_tick(detection.edge_id, detection.failure.name) is None:
                return False
            self._hurry(detection.edge_id, detection.failure.name)
            until = self._mode_tick(detection.edge_id, detection.failure.name) or self.world.tick
        suspended = self.program if suspended is None else suspended
        since = self.world.tick if since is None else since

        def arrived() -> tuple[bool, str] | None:
            self.program = suspended
            if derived and self.plan_error is not None:  # the plan failed while the robot waited for it
                self._arrived(f"no branch will come: the arranger's plan failed ({_headline(self.plan_error)})", since)
                return self._on_failure(detection)
            if listed is not None:  # the edge's modes are known now: the one watching this constraint, or all
                watching = self.as_arranged(detection)
                self.trace.add(self.world.tick, "modes_listed", edge=detection.edge_id, failure=detection.failure.name,
                               taken_as=watching.failure.name if watching is not detection else None)
                if self._early_failure(detection, suspended, since, resume):
                    return None
                self._arrived(f"recovery for {watching.failure.name}", since)
                return self._recover_after_wait(detection, since)
            if not derived:
                self._arrived(f"recovery for {detection.failure.name}", since)
                return self._recover_after_wait(detection, since)
            monitors = self.monitors.get(detection.edge_id)
            now = monitors.violated_now(self.frame) if monitors is not None else None
            if now is not None:
                self._arrived(f"recovery for {now.failure.name}", since)
                return self._recover_after_wait(Detection(now.edge_id, now.failure, self.world.tick, detection.onset_tick, now.value), since)
            self._arrived("no failure mode of the edge is violated: the edge goes on", since)
            if suspended is not None:
                self._arm_monitors(suspended)
            return resume() if resume is not None else None

        if since == self.world.tick:
            self.trace.add(self.world.tick, "failure_before_branch", edge=detection.edge_id, failure=detection.failure.name,
                           arrives_tick=until)
        self.program, self.armed = None, None
        self.waiting = Waiting(until, since, detection.edge_id, detection.failure.name, arrived, self.world.tick)
        return True

    def _hurry(self, edge_id: str, failure: str | None, recovery_edge: str | None = None) -> None:
        """Tell the planner what the robot now waits for: the branch of ``failure`` on ``edge_id`` (None: every
        mode of the edge), or the grounding of ``recovery_edge``, goes first from this tick
        (:meth:`PlanSchedule.hurried`; a modelled schedule only)."""
        schedule = self.schedule
        if schedule is None or schedule.inputs is None:
            return
        self.schedule = schedule.hurried(schedule.first_motion_s + self.world.tick / CONTROL_HZ, edge_id, failure, recovery_edge)
        if self._early_armed is not None:  # the running edge's modes may come at another tick now
            listed = self._listed_tick(self._early_armed)
            self._rearm_tick = self.world.tick if listed is None else listed
        before = {(c.call.part, c.start_s) for c in schedule.calls}
        moved = [c.call.part for c in self.schedule.calls if (c.call.part, c.start_s) not in before]
        self.trace.add(self.world.tick, "plan_hurried", edge=recovery_edge or edge_id, failure=failure, moved=moved)

    def _early_arrival(self, program: EdgeProgram,
                       arrive: Callable[[], tuple[bool, str] | None]) -> tuple[bool, str] | Literal[False] | None:
        """A nominal edge that ended at a node whose constraints do not hold, before its failure modes had
        all arrived: their monitors never watched the edge (a cup knocked over while the bottle was
        carried to it), so the robot waits for them as for a failure before its branch, then asks them
        what the scene is; one that reads it violated recovers, else the robot arrives (``arrive``).

        Returns:
            False when the edge's modes were all here (arrive as usual); otherwise what came of it now
            (None: it waits, or recovers).
        """
        failed_plan = program.kind == "nominal" and self.plan_error is not None
        if not failed_plan and (program.kind != "nominal" or self.schedule is None or not self._pending_modes(program.edge_id)):
            return False
        values = [(c.source, c.scalar(self.frame)) for c in self.constraints[program.target]]
        violated = [(source, value) for source, value in values if value > 0.0]
        if not violated:
            return False
        source, value = violated[0]
        failure = FailureMode.model_validate({"name": f"reached {program.target}: {source}", "monitor": source,
                                              "intent": DERIVED_INTENT, "recovery": program.edge_id})
        detection = Detection(program.edge_id, failure, self.world.tick, self.world.tick, float(value))
        if failed_plan:
            return self._on_failure(detection)  # detected, counted, and unrecovered for want of a branch
        if self._early_failure(detection, resume=arrive):
            return None
        return self._on_failure(self.as_arranged(detection))  # the mode watching it is here already

    def _recover_after_wait(self, detection: Detection, since: int) -> tuple[bool, str] | None:
        """Recover from a failure that waited for its branch since tick ``since``.

        The arms held still all that while, as a recovery's binding holds them while what was dropped
        or taken comes to rest: the binding counts its wait from ``since``, not from now, so that a
        pipelined recovery does not hold still twice over what the sequential plan waits once.
        """
        self.still_since = since
        try:
            return self._on_failure(detection)
        finally:
            self.still_since = None

    def as_arranged(self, detection: Detection) -> Detection:
        """A derived monitor's detection as the arranger's mode of its edge that reads the same constraint, if
        there is one (the mode would have fired, had it been there); any other detection as it is."""
        if detection.failure.intent != DERIVED_INTENT or self._listed_tick(detection.edge_id) is not None:
            return detection
        constraint = " ".join(detection.failure.monitor.split())
        for failure in self.graph.edge(detection.edge_id).failures:
            if constraint in " ".join(failure.monitor.split()):
                return Detection(detection.edge_id, failure, detection.tick, detection.onset_tick, detection.value)
        return detection

    def _early_program_failure(self) -> bool:
        """Wait for the list of modes of an edge whose skill failed before it arrived (True when it waits).

        Once the list is here, its monitors are asked what the scene is first, as they would have been
        asked every tick had they been armed (a corner dropped as it was carried to its place: the
        sequential plan's monitor fires before the place finds nothing to place). One that reads it
        violated recovers; otherwise the skill's failure goes to the strategy as usual.
        """
        program = self.program
        if program is None or program.kind != "nominal":
            return False
        listed = self._listed_tick(program.edge_id)
        if listed is None:
            return False  # the strategy reads the edge's monitors; a mode it names waits for its own branch
        since = self.world.tick

        def arrived() -> tuple[bool, str] | None:
            self.program = program
            monitors = self.monitors.get(program.edge_id)
            now = monitors.violated_now(self.frame) if monitors is not None else None
            if now is not None:
                self._arrived(f"recovery for {now.failure.name} (the skill failed: {program.failure_reason})", since)
                return self._recover_after_wait(Detection(now.edge_id, now.failure, self.world.tick, self.world.tick, now.value), since)
            self._arrived(f"the skill's failure taken as the strategy takes it ({program.failure_reason})", since)
            return self._on_program_failed()

        reason = f"skill failed: {program.failure_reason}"
        self._wait_for(program.edge_id, listed, reason, arrived)
        return True

    def _wait_for_grounding(self, program: EdgeProgram) -> bool:
        """Wait for an edge's grounding (nominal, further on in a branch, or an alternative a recovery bound)
        if the robot needs it first (True when it waits). A recovery edge's is hurried."""
        if self.schedule is None:
            return False
        until = self._tick_at(self.schedule.edge_ready_s.get(program.edge_id))
        if until is None:
            return False
        if program.kind == "recovery":
            self._hurry(program.edge_id, None, recovery_edge=program.edge_id)
            assert self.schedule is not None  # _hurry replaces the schedule, never drops it
            until = self._tick_at(self.schedule.edge_ready_s.get(program.edge_id))
            if until is None:
                return False
        since = self.world.tick

        def arrived() -> tuple[bool, str] | None:
            self.trace.add(self.world.tick, "edge_grounded", edge=program.edge_id, waited_ticks=self.world.tick - since)
            self._start(program)
            return None

        self._wait_for(program.edge_id, until, None, arrived)
        return True

    def _arrived(self, outcome: str, since: int) -> None:
        """Record what came of a failure that waited for its branch since tick ``since``."""
        waiting = self._arriving
        assert waiting is not None  # called from a wait's ``then``, which _tick_waiting calls once it set _arriving
        waited = self.world.tick - since
        self.early_failures.append({"edge": waiting.edge_id, "failure": waiting.failure, "tick": since,
                                    "waited_ticks": waited, "then": outcome})
        self.trace.add(self.world.tick, "branch_arrived", edge=waiting.edge_id, failure=waiting.failure,
                       waited_ticks=waited, then=outcome)

    def _tick_waiting(self) -> tuple[bool, str] | Literal[False] | None:
        """One tick of a wait: the arms hold still until the part arrives (the world stepped, None), or what
        came of it once it has (an outcome, or False: the tick goes on as usual, as when nothing waits)."""
        waiting = self.waiting
        if waiting is None:
            return False
        if self.world.tick < waiting.until:
            self._step()
            return None
        self.plan_wait_ticks += self.world.tick - waiting.began
        self.waiting, self._arriving = None, waiting
        outcome = waiting.then()
        return False if outcome is None else outcome

    @property
    def plan_wait_s(self) -> float:
        """Seconds the robot held still for parts of the plan, the wait under way included."""
        return self.held_for_plan_ticks / CONTROL_HZ

    @property
    def held_for_plan_ticks(self) -> int:
        """Ticks the robot held still for parts of the plan, the wait under way included."""
        return self.plan_wait_ticks + (self.world.tick - self.waiting.began if self.waiting is not None else 0)


def _headline(error: str | None) -> str:
    """The first line of an error, shortened for a one-line reason."""
    lines = (error or "").strip().splitlines()
    line = lines[0] if lines else "no reply"
    return line if len(line) <= 200 else line[:197] + "..."
